// The ray marcher of method "propagation" (seed 003 sec. 4.4, eq. 8-10).
#include <haze/core/error.h>
#include <haze/grids/optical_depth.h>
#include <haze/grids/propagation.h>

#include "trilinear.h"

#include <algorithm>
#include <cmath>

namespace haze::grids {

namespace {

struct Marcher {
  const Scene& scene;
  const ExtinctionVolume& volume;
  const std::vector<DenseGrid>& depths;
  Rgb sigma_t;
  double step;
  // The lights' depths interleaved (all lights of a cell together): one stencil reads 8 short runs.
  std::vector<float> packed;

  Marcher(const Scene& s, const ExtinctionVolume& v, const std::vector<DenseGrid>& d, double step_length)
      : scene(s), volume(v), depths(d), sigma_t(v.sigma_t_scale), step(step_length) {
    const size_t lights = depths.size(), cells = volume.density.cell_count();
    packed.resize(cells * lights);
    for (size_t c = 0; c < cells; ++c)
      for (size_t l = 0; l < lights; ++l) packed[c * lights + l] = depths[l].values()[c];
  }

  // Density integral from x to the light: the volume's value inside it, a DDA walk outside.
  double depth_to_light(size_t l, const Vec3& x, const LightArrival& a) const {
    if (volume.density.bounds().contains(x)) return static_cast<double>(sample_trilinear(depths[l], x));
    const double reach = std::isfinite(a.distance) ? a.distance : 1e30;  // directional: past any grid
    return density_integral_dda(volume.density, x, x + a.to_light * reach);
  }

  Rgb pixel(const Ray& ray) const {
    double t_hit = kInfinity;
    Vec3 normal(0.0);
    const Surface* hit = nearest_surface(scene.surfaces, ray, kInfinity, t_hit, normal);
    Rgb radiance(0.0), transmittance(1.0);
    double t0 = 0.0, t1 = t_hit;
    LightArrival a;
    if (volume.density.bounds().clip(ray, t0, t1) && t1 > t0) {
      const int steps = static_cast<int>(std::ceil((t1 - t0) / step));
      const double dt = (t1 - t0) / steps;
      const size_t lights = scene.lights.size();
      std::vector<double> depth(lights);
      for (int s = 0; s < steps; ++s) {
        const Vec3 x = ray.at(t0 + (s + 0.5) * dt);
        const TrilinearStencil stencil(volume.density, x);
        double rho = 0.0;
        for (int m = 0; m < 8; ++m) rho += stencil.weight[m] * static_cast<double>(volume.density.values()[stencil.offset[m]]);
        if (rho <= 0.0) continue;
        std::fill(depth.begin(), depth.end(), 0.0);
        for (int m = 0; m < 8; ++m) {
          const float* run = packed.data() + stencil.offset[m] * lights;
          for (size_t l = 0; l < lights; ++l) depth[l] += stencil.weight[m] * static_cast<double>(run[l]);
        }
        Rgb in(0.0);
        for (size_t l = 0; l < lights; ++l) {
          if (!arrival(scene.lights[l], x, a) || a.irradiance == Rgb(0.0)) continue;
          in += volume.phase.eval(-a.to_light, -ray.direction) * a.irradiance * glm::exp(-sigma_t * depth[l]);
        }
        const Rgb step_transmittance = glm::exp(-sigma_t * rho * dt);
        radiance += transmittance * volume.albedo * (Rgb(1.0) - step_transmittance) * in;
        transmittance *= step_transmittance;
      }
    }
    if (!hit) return radiance + transmittance * scene.background;
    // Eq. 10: the surface's shading, each light attenuated by its depth to the surface point.
    const Vec3 p = ray.at(t_hit);
    Rgb surface(0.0);
    for (size_t l = 0; l < scene.lights.size(); ++l) {
      if (!arrival(scene.lights[l], p, a)) continue;
      const double cos_i = glm::dot(normal, a.to_light);
      if (cos_i <= 0.0) continue;
      surface += hit->brdf(a.to_light, -ray.direction, normal) * a.irradiance * cos_i * glm::exp(-sigma_t * depth_to_light(l, p, a));
    }
    return radiance + transmittance * surface;
  }
};

}  // namespace

Image march_image(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths,
                  const MarchSettings& settings, const RenderOptions& options) {
  if (depths.size() != scene.lights.size())
    throw Error("depths", to_text(depths.size()) + " volumes", "one per light (" + to_text(scene.lights.size()) + ")");
  if (!(settings.step_cells > 0.0)) throw Error("step", to_text(settings.step_cells), "a step > 0 cells");
  const Vec3 h = volume.density.cell_size();
  const Marcher marcher(scene, volume, depths, settings.step_cells * std::min({h.x, h.y, h.z}));
  const Camera& camera = scene.camera;
  Image image(camera.width_px, camera.height_px);
  ProgressTracker progress(options.progress, camera.height_px);
  parallel_for(camera.height_px, options.threads, 4, [&](long long y0, long long y1) {
    for (auto y = static_cast<int>(y0); y < y1 && !progress.cancelled(); ++y) {
      for (int x = 0; x < camera.width_px; ++x) image.set(x, y, marcher.pixel(camera.pixel_ray(x, y)));
      progress.advance();
    }
  });
  progress.throw_if_cancelled();
  return image;
}

}  // namespace haze::grids
