#include "dom_gather.h"

#include "dom_internal.h"
#include "dom_surfaces.h"

#include <haze/core/grid_walk.h>

namespace haze::grids::dom {

namespace {
constexpr int kSurfaceDirections = 64;  // over the sphere: the hemisphere above a surface point gets about half
}

Gather::Gather(const Scene& delta, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths, const DomSolution& solution,
               double step_cells, int threads, const SurfaceLight* surfaces)
    : delta_(delta),
      volume_(volume),
      depths_(depths),
      solution_(solution),
      surfaces_(surfaces),
      visibility_(surface_visibility(volume.density, delta.lights, delta.surfaces, threads)),
      around_(DirectionSet::fibonacci(kSurfaceDirections)) {
  const Vec3 h = volume.density.cell_size();
  step_ = step_cells * std::min({h.x, h.y, h.z});
  const double f = solution.delta_m_fraction;
  sigma_t_ = delta_m_sigma_t(volume.sigma_t_scale, volume.albedo, f);
  albedo_ = delta_m_albedo(volume.albedo, f);
  single_albedo_ = volume.albedo / (Rgb(1.0) - volume.albedo * f);
  cone_ = cone_tangent(kSurfaceDirections);
  if (!delta.surfaces.empty())
    for (int j = 0; j < around_.size(); ++j) around_weights_.push_back(inscatter_weights(solution, -around_[j]));
}

Rgb Gather::along(const Ray& ray, double t_end, const Eigen::VectorXd& c, Rgb& transmittance, double cone) const {
  const DenseGrid& density = volume_.density;
  Rgb radiance(0.0);
  transmittance = Rgb(1.0);
  double t0 = 0.0, t1 = t_end;
  if (!density.bounds().clip(ray, t0, t1) || !(t1 > t0)) return radiance;
  const auto n = static_cast<size_t>(solution_.terms());
  std::vector<double> m(n);
  const int steps = static_cast<int>(std::ceil((t1 - t0) / step_));
  const double dt = (t1 - t0) / steps;
  LightArrival a;
  for (int s = 0; s < steps; ++s) {
    const Vec3 p = ray.at(t0 + (s + 0.5) * dt);
    const TrilinearStencil stencil(density.bounds(), density.resolution(), p);
    const double rho = stencil.apply(density.values().data());
    if (rho <= 0.0) continue;
    Rgb inscattered(0.0);
    for (int ch = 0; ch < solution_.channels; ++ch) {
      std::fill(m.begin(), m.end(), 0.0);
      const float* moments = solution_.moments[static_cast<size_t>(ch)].data();
      for (int e = 0; e < 8; ++e) {
        const float* cell = moments + stencil.offset[e] * n;
        for (size_t k = 0; k < n; ++k) m[k] += stencil.weight[e] * static_cast<double>(cell[k]);
      }
      double j = 0.0;
      for (size_t k = 0; k < n; ++k) j += c(static_cast<int>(k)) * m[k];
      inscattered[ch] = j;
    }
    if (solution_.channels == 1) inscattered = Rgb(inscattered[0]);
    Rgb single(0.0);
    const double radius = cone * (t0 + (s + 0.5) * dt);
    for (size_t l = 0; l < delta_.lights.size(); ++l) {
      if (!arrival(delta_.lights[l], p, a) || a.irradiance == Rgb(0.0)) continue;
      if (a.distance < radius) a.irradiance *= (a.distance / radius) * (a.distance / radius);
      const double depth = stencil.apply(depths_[l].values().data());
      const double visible = visibility_.empty() ? 1.0 : stencil.apply(visibility_[l].values().data());
      single += volume_.phase.eval(-a.to_light, -ray.direction) * a.irradiance * visible * glm::exp(-volume_.sigma_t_scale * depth);
    }
    const Rgb step_transmittance = glm::exp(-sigma_t_ * rho * dt);
    radiance += transmittance * (Rgb(1.0) - step_transmittance) * (albedo_ * inscattered + single_albedo_ * single);
    transmittance *= step_transmittance;
  }
  return radiance;
}

Rgb Gather::arriving(const Vec3& point, int j, const Rgb& sky) const {
  const Ray up{point, around_[j]};
  double t_next = kInfinity;
  Vec3 n;
  const Surface* hit = nearest_surface(delta_.surfaces, up, kInfinity, t_next, n);
  Rgb t_up;
  const Rgb radiance = along(up, t_next, around_weights_[static_cast<size_t>(j)], t_up, cone_);
  if (!hit) return radiance + t_up * sky;
  return surfaces_ ? radiance + t_up * surfaces_->reflected(*hit, up.at(t_next), n, -around_[j]) : radiance;
}

}  // namespace haze::grids::dom
