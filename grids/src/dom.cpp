// Method "dom": multiple scattering on grids by discrete ordinates (seed 000). The extinction
// volume and the exact optical depth to every light (propagation's volumes) feed the solver; the
// image is the propagation marcher's unscattered light (surfaces, background) plus, along each
// camera ray, single scattering and the in-scattered diffuse radiance from the solver's moments.
#include <haze/grids/dom.h>

#include <haze/core/error.h>
#include <haze/grids/optical_depth.h>

#include "dom_internal.h"
#include "trilinear.h"

#include <chrono>

namespace haze::grids {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Along each camera ray inside the volume, up to the first surface, the formal solution of the
// (delta-M scaled) equation for light scattered at least once:
//   L += T' (1 - e^(-sigma_t' rho step)) [albedo' sum_k c_k(w) m_k + albedo / (1 - albedo f) q1(w)],
//   q1(w) = sum_lights p(w_light . w) E_light e^(-sigma_t depth_light)   (single scattering),
// c(w) from inscatter_weights toward the eye, density, depths and moments trilinear at the step's
// midpoint. Without delta-M (f = 0) this is the propagation marcher's estimator plus the gather.
Image gather_scattered(const Scene& delta, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths,
                       const DomSolution& solution, double step_cells, const RenderOptions& options) {
  const DenseGrid& density = volume.density;
  const Vec3 h = density.cell_size();
  const double step = step_cells * std::min({h.x, h.y, h.z});
  const auto n = static_cast<size_t>(solution.terms());
  const double f = solution.delta_m_fraction;
  const Rgb sigma_t = dom::delta_m_sigma_t(volume.sigma_t_scale, volume.albedo, f);
  const Rgb albedo = dom::delta_m_albedo(volume.albedo, f);
  const Rgb single_albedo = volume.albedo / (Rgb(1.0) - volume.albedo * f);
  const Camera& camera = delta.camera;
  Image image(camera.width_px, camera.height_px);
  ProgressTracker progress(options.progress, camera.height_px);
  parallel_for(camera.height_px, options.threads, 4, [&](long long y0, long long y1) {
    std::vector<double> m(n);
    LightArrival a;
    for (auto y = static_cast<int>(y0); y < y1 && !progress.cancelled(); ++y) {
      for (int x = 0; x < camera.width_px; ++x) {
        const Ray ray = camera.pixel_ray(x, y);
        double t_hit = kInfinity, t0 = 0.0;
        Vec3 normal;
        nearest_surface(delta.surfaces, ray, kInfinity, t_hit, normal);
        double t1 = t_hit;
        if (!density.bounds().clip(ray, t0, t1) || !(t1 > t0)) continue;
        const int steps = static_cast<int>(std::ceil((t1 - t0) / step));
        const double dt = (t1 - t0) / steps;
        const Eigen::VectorXd c = inscatter_weights(solution, -ray.direction);
        Rgb radiance(0.0), transmittance(1.0);
        for (int s = 0; s < steps; ++s) {
          const Vec3 p = ray.at(t0 + (s + 0.5) * dt);
          const TrilinearStencil stencil(density, p);
          double rho = 0.0;
          for (int e = 0; e < 8; ++e) rho += stencil.weight[e] * static_cast<double>(density.values()[stencil.offset[e]]);
          if (rho <= 0.0) continue;
          Rgb inscattered(0.0);
          for (int ch = 0; ch < solution.channels; ++ch) {
            std::fill(m.begin(), m.end(), 0.0);
            const float* moments = solution.moments[static_cast<size_t>(ch)].data();
            for (int e = 0; e < 8; ++e) {
              const float* cell = moments + stencil.offset[e] * n;
              for (size_t k = 0; k < n; ++k) m[k] += stencil.weight[e] * static_cast<double>(cell[k]);
            }
            double j = 0.0;
            for (size_t k = 0; k < n; ++k) j += c(static_cast<int>(k)) * m[k];
            inscattered[ch] = j;
          }
          if (solution.channels == 1) inscattered = Rgb(inscattered[0]);
          Rgb single(0.0);
          for (size_t l = 0; l < delta.lights.size(); ++l) {
            if (!arrival(delta.lights[l], p, a) || a.irradiance == Rgb(0.0)) continue;
            double depth = 0.0;
            for (int e = 0; e < 8; ++e) depth += stencil.weight[e] * static_cast<double>(depths[l].values()[stencil.offset[e]]);
            single += volume.phase.eval(-a.to_light, -ray.direction) * a.irradiance * glm::exp(-volume.sigma_t_scale * depth);
          }
          const Rgb step_transmittance = glm::exp(-sigma_t * rho * dt);
          radiance += transmittance * (Rgb(1.0) - step_transmittance) * (albedo * inscattered + single_albedo * single);
          transmittance *= step_transmittance;
        }
        image.set(x, y, radiance);
      }
      progress.advance();
    }
  });
  progress.throw_if_cancelled();
  return image;
}

}  // namespace

Image render_dom(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& delta_depths,
                 const DomSolution& solution, double step_cells, const RenderOptions& options) {
  Scene delta = scene;
  delta.lights.clear();
  for (const Light& l : scene.lights) {
    if (const auto* sky = std::get_if<SkyLight>(&l)) delta.background += sky->radiance;
    else delta.lights.push_back(l);
  }
  if (delta_depths.size() != delta.lights.size())
    throw Error("depths", to_text(delta_depths.size()) + " volumes", "one per point, spot or directional light (" + to_text(delta.lights.size()) + ")");
  // Unscattered light (surfaces, background): the marcher with albedo 0 and, under delta-M, the
  // scaled extinction, which counts the forward peak as unscattered (as DISORT does).
  ExtinctionVolume dark = volume;
  dark.sigma_t_scale = dom::delta_m_sigma_t(volume.sigma_t_scale, volume.albedo, solution.delta_m_fraction);
  dark.albedo = Rgb(0.0);
  const ProgressCallback& progress = options.progress;
  RenderOptions march_options = options;
  march_options.progress = progress ? [&](double f) { return progress(0.3 * f); } : ProgressCallback();
  Image image = march_image(delta, dark, delta_depths, MarchSettings{step_cells}, march_options);
  march_options.progress = progress ? [&](double f) { return progress(0.3 + 0.7 * f); } : ProgressCallback();
  const Image scattered = gather_scattered(delta, volume, delta_depths, solution, step_cells, march_options);
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) image.set(x, y, image.at(x, y) + scattered.at(x, y));
  return image;
}

namespace {

class DomMethod final : public Method {
 public:
  RenderResult render(const Scene& scene, const RenderOptions& options) const override {
    const ProgressCallback& progress = options.progress;
    RenderOptions solve_options = options;
    solve_options.progress = progress ? [&](double f) { return progress(0.8 * f); } : ProgressCallback();
    DomFields fields = dom_fields(scene, solve_options);
    const auto start = std::chrono::steady_clock::now();
    RenderOptions render_options = options;
    render_options.progress = progress ? [&](double f) { return progress(0.8 + 0.2 * f); } : ProgressCallback();
    Image image = render_dom(scene, fields.volume, fields.delta_depths, fields.solution, fields.step_cells, render_options);
    RenderResult result{std::move(image), std::nullopt, std::move(fields.stats)};
    result.stats["render_seconds"] = seconds_since(start);
    return result;
  }
};

}  // namespace

DomFields dom_fields(const Scene& scene, const RenderOptions& options) {
  Settings settings(options.settings, "dom");
  const int resolution = static_cast<int>(settings.integer("resolution", 64, 2, 1024));
  DomSettings dom;
  dom.directions = static_cast<int>(settings.integer("directions", dom.directions, 8, 4096));
  dom.terms = static_cast<int>(settings.integer("terms", std::min(dom.terms, dom.directions), 0, dom.directions));
  dom.scheme = dom_scheme_from_name(settings.choice("scheme", "sweep", {"paper", "sweep"}));
  dom.accelerator = dom_accelerator_from_name(settings.choice("accelerator", "gmres", {"none", "gmres"}));
  dom.max_iterations = static_cast<int>(settings.integer("iterations", dom.max_iterations, 1, 100000));
  dom.tolerance = settings.number("tolerance", dom.tolerance, 1e-9, 1.0);
  dom.delta_m = settings.integer("delta_m", 1, 0, 1) != 0;
  dom.storage = dom_storage_from_name(settings.choice("storage", "float32", {"float32", "float16"}));
  dom.threads = options.threads;
  DepthOptions depth;
  depth.scheme = depth_scheme_from_name(settings.choice("optical_depth", "exact", {"exact", "paper", "sweep"}));
  depth.threads = options.threads;
  const double step_cells = settings.number("step", 0.5, 0.01, 4.0);
  settings.reject_unknown();

  auto start = std::chrono::steady_clock::now();
  ExtinctionVolume volume = make_extinction_volume(scene, resolution, 0.0, options.threads);
  // Delta lights get depth volumes; the sky enters the solver through the boundary and reaches
  // the eye as background.
  std::vector<DenseGrid> delta_depths;
  for (const Light& l : scene.lights)
    if (!std::holds_alternative<SkyLight>(l)) delta_depths.push_back(optical_depth(volume.density, l, depth));
  const double depth_seconds = seconds_since(start);

  start = std::chrono::steady_clock::now();
  dom.progress = options.progress;
  DomSolution solution = solve_dom(volume, scene.lights, delta_depths, dom);
  const double solve_seconds = seconds_since(start);
  DomFields fields{std::move(volume), std::move(delta_depths), std::move(solution), step_cells, {}};
  const ExtinctionVolume& v = fields.volume;
  const DomSolution& solved = fields.solution;
  fields.stats = {{"cells", v.density.resolution()},
                  {"directions", dom.directions},
                  {"terms", solved.terms()},
                  {"phase_relative_error", solved.separable->relative_error()},
                  {"delta_m_fraction", solved.delta_m_fraction},
                  {"scheme", name(dom.scheme)},
                  {"accelerator", name(dom.accelerator)},
                  {"storage", name(dom.storage)},
                  {"channels", solved.channels},
                  {"iterations", solved.iterations},
                  {"converged", solved.converged},
                  {"final_change", solved.changes.empty() ? 0.0 : solved.changes.back()},
                  {"skipped_fraction", solved.skipped_fraction},
                  {"memory_bytes", solved.bytes},
                  {"depth_seconds", depth_seconds},
                  {"solve_seconds", solve_seconds}};
  return fields;
}

std::unique_ptr<Method> make_dom_method() { return std::make_unique<DomMethod>(); }

}  // namespace haze::grids
