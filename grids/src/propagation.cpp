// Method "propagation": single scattering in heterogeneous media (seed 003). The density goes into
// an extinction volume (RBF injection, or the grid file as is), the optical depth from every light
// to every cell into one volume per light (exact, paper or sweep: optical_depth.h), and camera rays
// march through both (eq. 8-10), with the scene's phase function instead of the paper's isotropic
// one, and surfaces lit through the propagated depth. Like the paper: no surface shadows.
#include <haze/grids/propagation.h>

#include <haze/core/error.h>
#include <haze/core/method.h>
#include <haze/grids/optical_depth.h>
#include <haze/core/stopwatch.h>
#include <haze/grids/solution.h>

namespace haze::grids {

// The method's name, written once: the registry, its settings and its errors read it here.
constexpr const char* kPropagationName = "propagation";

namespace {

void check_lights(const std::vector<Light>& lights) {
  for (size_t i = 0; i < lights.size(); ++i)
    if (std::holds_alternative<SkyLight>(lights[i]))
      throw Error("lights[" + std::to_string(i) + "].type", "sky", "point, spot or directional lights for the propagation method");
}

// Prepared: the extinction volume and one optical-depth volume per light.
class PropagationSolution final : public GridSolution {
 public:
  PropagationSolution(const Scene& scene, PropagationFields fields)
      : GridSolution(scene, std::move(fields.volume), std::move(fields.depths), fields.march.step_cells),
        march_(fields.march),
        depth_(fields.depth),
        resolution_(fields.resolution),
        cutoff_(fields.cutoff),
        auto_step_(fields.auto_step),
        packed_(std::move(fields.packed)) {
    stats = std::move(fields.stats);
  }

  RenderResult render(const View& view, const RenderOptions& options) const override {
    const Stopwatch watch;
    RenderResult result = march_view(view_scene(scene_, view.camera), volume_, depths_, march_, options, view, &packed_);
    result.stats["march_seconds"] = watch.seconds();
    return result;
  }
  bool renders_layers() const override { return true; }
  bool render_distances(const View& view, std::span<const double> distances, const RenderOptions& options, DistanceLayers out) const override {
    return march_distances(scene_, volume_, depths_, march_, options, view, distances, out, &packed_);  // the view's camera, not the scene's
  }
  bool render_layers(const View& view, LayerSpans out, const RenderOptions& options) const override {
    return march_layers(scene_, volume_, depths_, march_, options, view, out, &packed_);
  }

  // A new density (re-injected by region where it can: replace_volume) redoes every light's depth,
  // new lights only the lights that differ.
  std::optional<UpdateReport> update(const Scene& scene, const SceneChange& change, const RenderOptions& options) override {
    check_lights(scene.lights);
    UpdateReport report;
    Stopwatch watch;
    depth_.threads = options.threads;
    if (change.medium) {
      report.redone.push_back(replace_volume(scene, change, resolution_, cutoff_, options.threads));
      report.stats["inject_seconds"] = watch.lap();
    }
    update_depths(scene, change.medium.has_value(), depth_, report);
    report.stats["propagate_seconds"] = watch.lap();
    packed_ = pack_lights(scene, volume_, depths_, options.threads);
    if (auto_step_) {
      march_.step_cells = step_cells_ = auto_step_cells(scene, volume_, depths_, packed_, options.threads);
      report.stats["step_cells"] = step_cells_;
    }
    scene_ = scene;
    return report;
  }

 private:
  MarchSettings march_;
  DepthOptions depth_;
  int resolution_;
  double cutoff_;
  bool auto_step_;  // setting step 0: chosen again after an update
  PackedLights packed_;  // the depths and the surfaces' shadows as the marcher reads them, made once per prepare or update
};

class PropagationMethod final : public Method {
 public:
  std::unique_ptr<MethodSolution> prepare(const Scene& scene, const RenderOptions& options) const override {
    return std::make_unique<PropagationSolution>(scene, propagation_fields(scene, options));
  }
};

}  // namespace

PropagationFields propagation_fields(const Scene& scene, const RenderOptions& options) {
  Settings settings(options.settings, kPropagationName);
  const int resolution = static_cast<int>(settings.integer("resolution"));
  DepthOptions depth;
  depth.scheme = depth_scheme_from_name(settings.choice("optical_depth"));
  depth.sweep_layers = static_cast<int>(settings.integer("sweep_layers"));
  depth.threads = options.threads;
  const double step_cells = settings.number("step");
  if (step_cells > 0.0 && step_cells < 0.01) throw Error("method.step", to_text(step_cells), "0 (chosen for the medium) or a step in [0.01, 4] cells");
  const double cutoff = settings.number("cutoff");
  const bool surface_light = settings.integer("surface_light") != 0;
  settings.reject_unknown();

  check_lights(scene.lights);
  Stopwatch watch;
  VolumeReport report;
  PropagationFields fields{make_extinction_volume(scene, resolution, cutoff, options.threads, &report), {}, MarchSettings{step_cells, false, surface_light}, {}, {}};
  const double inject_seconds = watch.lap();
  DepthStats depth_stats;
  check_depth_memory(fields.volume.density, scene.lights, options.max_memory);
  fields.depths = optical_depths(fields.volume.density, scene.lights, depth, &depth_stats);
  const double propagate_seconds = watch.lap();
  fields.packed = pack_lights(scene, fields.volume, fields.depths, options.threads);
  fields.auto_step = step_cells == 0.0;
  if (fields.auto_step) fields.march.step_cells = auto_step_cells(scene, fields.volume, fields.depths, fields.packed, options.threads);
  fields.stats = {{"cells", fields.volume.density.resolution()},
                  {"step_cells", fields.march.step_cells},
                  {"optical_depth", name(depth.scheme)},
                  {"sweep_layers", depth.sweep_layers},
                  {"paper_iterations", depth.scheme == DepthScheme::paper ? depth_stats.iterations : 0},
                  {"truncation_bound", report.truncation_bound},
                  {"inject_seconds", inject_seconds},
                  {"propagate_seconds", propagate_seconds},
                  {"step_seconds", watch.seconds()}};
  fields.resolution = resolution, fields.cutoff = cutoff, fields.depth = depth;
  return fields;
}

MethodInfo propagation_info() {
  MethodInfo info;
  info.name = kPropagationName;
  info.summary = "single scattering in heterogeneous media: RBF injection, optical-depth volumes, ray marching (seed 003)";
  info.create = [] { return std::make_unique<PropagationMethod>(); };
  info.handles = {"RBF, grid and bounded constant densities, the particles' density", "point, spot, directional",
                  "planes, spheres and meshes lit by unscattered light through the depth volumes, with shadows", false};
  info.settings = {SettingInfo::integer("resolution", 64, 2, 1024, "cells along the longest side of the medium's bounds (RBF and constant)"),
                   SettingInfo::choice("optical_depth", name(DepthOptions{}.scheme), names_of<DepthScheme>(kDepthSchemes), "how the depth to each light is computed"),
                   SettingInfo::integer("sweep_layers", 4, 1, 64, "sweep: cell layers each short characteristic walks exactly"),
                   SettingInfo::number("step", 0.0, 0.0, 4.0,
                                       "ray-march step in cells (0: chosen for the medium and lights, the longest of 0.5, 1, 2, 3 and 4 cells within 5e-4 of 0.5 cells' march over 256 chords; stats: step_cells)"),
                   SettingInfo::number("cutoff", 0.0, 0.0, 1e30, "RBF injection cutoff (0: 1e-4 of the largest weight)"),
                   SettingInfo::integer("surface_light", 0, 0, 1, "1: surfaces also receive the single-scattered light (64 directions, about 4x the render; not in the GL display)")};
  for (int resolution : {16, 32, 64, 96})
    for (double step : {1.0, 0.5}) info.trade_sweep.push_back({{"resolution", resolution}, {"step", step}});
  info.offer = [](const SceneFeatures& f, double tolerance) {
    if (!single_scattering_suffices(f, tolerance)) return AutoOffer{false, {}, 0.0, "multiple scattering matters (or particles)"};
    if (f.sky) return AutoOffer{false, {}, 0.0, "a sky light"};
    if (f.homogeneous && !f.bounded) return AutoOffer{false, {}, 0.0, "an unbounded homogeneous medium has no grid"};
    return AutoOffer{true, {{"resolution", 64}, {"step", 0.5}}, 0.008, "heterogeneous medium or a directional light (thin_haze: 0.0078 s at 64^3)"};
  };
  info.single_scattering = true;
  info.emission = true;  // in the float64 marcher (the SIMD kernel takes none)
  return info;
}

}  // namespace haze::grids
