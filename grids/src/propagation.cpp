// Method "propagation": single scattering in heterogeneous media (seed 003). The density goes into
// an extinction volume (RBF injection, or the grid file as is), the optical depth from every light
// to every cell into one volume per light (exact, paper or sweep: optical_depth.h), and camera rays
// march through both (eq. 8-10), with the scene's phase function instead of the paper's isotropic
// one, and surfaces lit through the propagated depth. Like the paper: no surface shadows.
#include <haze/grids/propagation.h>

#include <haze/core/error.h>
#include <haze/core/method.h>
#include <haze/grids/optical_depth.h>
#include <haze/grids/rbf.h>

#include <chrono>

namespace haze::grids {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

class PropagationMethod final : public Method {
 public:
  RenderResult render(const Scene& scene, const RenderOptions& options) const override {
    PropagationFields fields = propagation_fields(scene, options);
    const auto start = std::chrono::steady_clock::now();
    RenderResult result{march_image(scene, fields.volume, fields.depths, fields.march, options), std::nullopt, std::move(fields.stats)};
    result.stats["march_seconds"] = seconds_since(start);
    return result;
  }
};

}  // namespace

PropagationFields propagation_fields(const Scene& scene, const RenderOptions& options) {
  Settings settings(options.settings, "propagation");
  const int resolution = static_cast<int>(settings.integer("resolution", 64, 2, 1024));
  DepthOptions depth;
  depth.scheme = depth_scheme_from_name(settings.choice("optical_depth", "sweep", {"exact", "paper", "sweep"}));
  depth.sweep_layers = static_cast<int>(settings.integer("sweep_layers", depth.sweep_layers, 1, 64));
  depth.threads = options.threads;
  const double step_cells = settings.number("step", 0.5, 0.01, 4.0);
  const double cutoff = settings.number("cutoff", 0.0, 0.0, 1e30);
  settings.reject_unknown();

  for (size_t i = 0; i < scene.lights.size(); ++i)
    if (std::holds_alternative<SkyLight>(scene.lights[i]))
      throw Error("lights[" + std::to_string(i) + "].type", "sky", "point, spot or directional lights for the propagation method");
  auto start = std::chrono::steady_clock::now();
  VolumeReport report;
  PropagationFields fields{make_extinction_volume(scene, resolution, cutoff, options.threads, &report), {}, MarchSettings{step_cells}, {}};
  const double inject_seconds = seconds_since(start);
  start = std::chrono::steady_clock::now();
  DepthStats depth_stats;
  fields.depths = optical_depths(fields.volume.density, scene.lights, depth, &depth_stats);
  fields.stats = {{"cells", fields.volume.density.resolution()},
                  {"optical_depth", name(depth.scheme)},
                  {"sweep_layers", depth.sweep_layers},
                  {"paper_iterations", depth.scheme == DepthScheme::paper ? depth_stats.iterations : 0},
                  {"truncation_bound", report.truncation_bound},
                  {"inject_seconds", inject_seconds},
                  {"propagate_seconds", seconds_since(start)}};
  return fields;
}

std::unique_ptr<Method> make_propagation_method() { return std::make_unique<PropagationMethod>(); }

}  // namespace haze::grids
