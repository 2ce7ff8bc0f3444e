// Method "dom": multiple scattering on grids by discrete ordinates (seed 000). The extinction
// volume and the exact optical depth to every light (propagation's volumes) feed the solver; the
// image is the propagation marcher's unscattered light (surfaces, background) plus, along each
// camera ray, single scattering and the in-scattered diffuse radiance from the solver's moments.
#include <haze/grids/dom.h>

#include <haze/core/error.h>
#include <haze/core/grid_walk.h>
#include <haze/core/stopwatch.h>
#include <haze/grids/optical_depth.h>
#include <haze/grids/solution.h>

#include "dom_gather.h"
#include "dom_toward_eye.h"
#include "dom_surfaces.h"
#include "dom_internal.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>

namespace haze::grids {

// The method's name, written once: the registry, its settings and its errors read it here.
constexpr const char* kDomName = "dom";

namespace {

// The cells an integer resolution gives at least through a thinner side, per optical depth
// through it (CellCount::per_optical_depth).
constexpr double kCellsPerOpticalDepth = 4.0;

// A cell's optical thickness across its thinnest side above which dom_fields warns.
constexpr double kThickCell = 2.0;

// The largest optical thickness of a cell across its thinnest side, at the largest sigma_t.
double thickest_cell(const ExtinctionVolume& volume) {
  const Vec3 h = volume.density.cell_size();
  const std::vector<float>& rho = volume.density.values();
  const float densest = rho.empty() ? 0.0f : *std::max_element(rho.begin(), rho.end());
  return std::max({volume.sigma_t_scale.r, volume.sigma_t_scale.g, volume.sigma_t_scale.b}) * static_cast<double>(densest) * std::min({h.x, h.y, h.z});
}

// No silent failure: writes stats "thickest_cell" and "warnings", cells thicker than kThickCell
// across their thinnest side (they smear light; the diamond scheme falls back to the step
// scheme's first order there) and a solve that did not converge to the settings' tolerance (unless
// it ran a `budget` of sweeps, not converging by design).
void say_warnings(const ExtinctionVolume& v, const DomSolution& solved, const DomSettings& settings, bool budget, nlohmann::json& stats) {
  const double thickest = thickest_cell(v);
  stats["thickest_cell"] = thickest;
  stats["warnings"] = nlohmann::json::array();
  if (thickest > kThickCell) {
    std::string enough = "[";
    for (int n : v.density.resolution())
      (enough += enough.size() > 1 ? ", " : "") += to_text(static_cast<int>(std::min(1024.0, std::ceil(n * thickest / kThickCell))));
    stats["warnings"].push_back("dom: cells up to " + to_text(thickest) + " optical depths thick across (above " + to_text(kThickCell) +
                                ", errors of 5% and more are likely: docs/DOM.md); set resolution to " + enough + "] or more");
  }
  // Strong peaks the directions and terms cannot hold (HG in the fog box against the reference):
  // g = -0.8 gives a phase error of 0.58 and the image 4% off, -0.9 0.76 and 41%; g = 0.95 leaves
  // delta-M 0.77 of the scattering and 4%, g = 0.99 0.95 and 50%.
  const double phase_error = solved.separable->relative_error();
  if (phase_error > 0.6 || solved.delta_m_fraction > 0.9)
    stats["warnings"].push_back("dom: the phase function's peak is too narrow for " + to_text(settings.directions) + " directions and " +
                                to_text(solved.terms()) + " terms (phase error " + to_text(phase_error) + ", delta-M fraction " +
                                to_text(solved.delta_m_fraction) + "): errors of 10% and more are likely (docs/DOM.md); use the reference");
  if (!budget && !solved.converged)
    stats["warnings"].push_back("dom: not converged in " + to_text(settings.max_iterations) + " iterations (last change " +
                                to_text(solved.changes.empty() ? 0.0 : solved.changes.back()) + " > tolerance " +
                                to_text(settings.tolerance) + "); raise iterations");
}

// The depths the first-collision source reads at cell centres: those of the cells a surface hides
// from a light made opaque (shadowed_depths); the depths themselves without surfaces.
std::vector<DenseGrid> source_depths(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths, int threads) {
  if (scene.surfaces.empty()) return depths;
  std::vector<Light> delta;
  for (const Light& l : scene.lights)
    if (!std::holds_alternative<SkyLight>(l)) delta.push_back(l);
  return shadowed_depths(depths, surface_visibility(volume.density, delta, scene.surfaces, threads));
}

// The scene with its point, spot and directional lights only; writes the sky's radiance.
Scene without_sky(const Scene& scene, Rgb& sky) {
  Scene delta = scene;
  delta.lights.clear();
  sky = Rgb(0.0);
  for (const Light& l : scene.lights) {
    if (const auto* s = std::get_if<SkyLight>(&l)) sky += s->radiance;
    else delta.lights.push_back(l);
  }
  return delta;
}

// The moments with the scene's surfaces in the transport: solve_dom (from `warm` when given),
// then `passes` times the light the surfaces reflect from that solution (direct light and the
// medium's, dom_surfaces.h) entering through the grid's faces, solved again from the last moments.
// Each pass carries the light one more bounce between surfaces and medium. Progress is shared out
// over the solves.
struct SurfaceSolve {
  DomSolution solution;
  int iterations = 0, passes = 0;
  double surface_seconds = 0.0;
};
SurfaceSolve solve_with_surfaces(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths, DomSettings settings,
                                 const DomSolution* warm, int passes, double step_cells, std::vector<std::vector<float>>* spare = nullptr) {
  SurfaceSolve out;
  if (scene.surfaces.empty() || settings.scheme == DomScheme::paper) passes = 0;
  const ProgressCallback progress = settings.progress;
  auto share = [&](int solve) {
    if (progress) settings.progress = [&progress, solve, passes](double f) { return progress((solve + f) / (passes + 1)); };
  };
  const std::vector<DenseGrid> sources = source_depths(scene, volume, depths, settings.threads);
  share(0);
  out.solution = solve_dom(volume, scene.lights, sources, settings, warm, nullptr, spare);
  out.iterations = out.solution.iterations;
  Rgb sky;
  const Scene delta = without_sky(scene, sky);
  // Each set of texels also gathers what other surfaces reflect, from the set before it.
  std::shared_ptr<const SurfaceTexels> texels;
  auto next_texels = [&] {
    std::optional<dom::SurfaceLight> previous;
    if (texels) previous.emplace(delta, volume, depths, *texels, sky, out.solution.delta_m_fraction);
    texels = std::make_shared<SurfaceTexels>(
        dom::surface_texels(delta, volume, depths, out.solution, sky, step_cells, settings.threads, previous ? &*previous : nullptr));
  };
  for (; out.passes < passes; ++out.passes) {
    Stopwatch watch;
    next_texels();
    const dom::SurfaceLight light(delta, volume, depths, *texels, sky, out.solution.delta_m_fraction);
    const DomBoundary boundary = light.boundary();
    out.surface_seconds += watch.seconds();
    share(out.passes + 1);
    out.solution = solve_dom(volume, scene.lights, sources, settings, &out.solution, &boundary);
    out.iterations += out.solution.iterations;
  }
  if (!scene.surfaces.empty()) {
    Stopwatch watch;
    next_texels();
    out.solution.surfaces = texels;
    out.surface_seconds += watch.seconds();
  }
  return out;
}

// Along each camera ray inside the volume, up to the first surface, the light scattered at least
// once (Gather::along; without delta-M this is the propagation marcher's estimator plus the
// gather). Then, where the ray meets a surface, the light the medium scatters onto it and the sky
// through the medium, reflected toward the eye and seen through T' (Gather::around through the
// BRDF: the first bounce, medium to surface), with what other surfaces reflect onto it when the
// solution carries its surfaces' texels (which hold the bounces between surfaces so far).
// Per pixel of `view`: the gathered in-scatter, its transmittance and the scattered light leaving
// the surface (not yet seen through it).
// With `planes`, only the steps in those z planes, and no surfaces (gather_planes).
std::vector<PixelLayers> gather_scattered(const Scene& delta, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths,
                                          const DomSolution& solution, double step_cells, const Rgb& sky, const View& view,
                                          const RenderOptions& options, const std::array<int, 2>* planes = nullptr) {
  std::optional<dom::SurfaceLight> light;
  if (solution.surfaces) light.emplace(delta, volume, depths, *solution.surfaces, sky, solution.delta_m_fraction);
  dom::Gather gather(delta, volume, depths, solution, step_cells, options.threads, light ? &*light : nullptr);
  if (planes) gather.only_planes((*planes)[0], (*planes)[1]);
  const Camera& camera = view.camera;
  std::vector<PixelLayers> out(static_cast<size_t>(camera.width_px) * static_cast<size_t>(camera.height_px));
  ProgressTracker progress(options.progress, camera.height_px);
  parallel_for(camera.height_px, options.threads, 4, [&](long long y0, long long y1) {
    for (auto y = static_cast<int>(y0); y < y1 && !progress.cancelled(); ++y) {
      for (int x = 0; x < camera.width_px; ++x) {
        const Ray ray = camera.pixel_ray(x, y);
        double t_hit = kInfinity;
        Vec3 normal;
        const Surface* surface = nearest_surface(delta.surfaces, ray, view.max_distance(x, y), t_hit, normal);
        PixelLayers& p = out[static_cast<size_t>(y) * static_cast<size_t>(camera.width_px) + static_cast<size_t>(x)];
        double t0 = 0.0, t1 = t_hit;
        if (volume.density.bounds().clip(ray, t0, t1) && t1 > t0)
          p.inscatter = gather.along(ray, t_hit, inscatter_weights(solution, -ray.direction), p.transmittance);
        if (surface) {
          const Vec3 wo = -ray.direction;
          if (solution.texel_surfaces && light)
            p.surface = (surface->kd + surface->ks) / kPi * light->irradiance(*surface, ray.at(t_hit), normal);
          else
            p.surface = gather.around(ray.at(t_hit), normal, sky, [&](const Vec3&) { return surface->kd / kPi; }) +
                        gather.glossy(ray.at(t_hit), normal, wo, *surface, sky);
        }
      }
      progress.advance();
    }
  });
  progress.throw_if_cancelled();
  return out;
}

}  // namespace

RenderResult render_dom(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& delta_depths,
                        const DomSolution& solution, double step_cells, const RenderOptions& options, const View& view) {
  Rgb sky;
  const Scene delta = without_sky(scene, sky);
  if (delta_depths.size() != delta.lights.size())
    throw Error("depths", to_text(delta_depths.size()) + " volumes", "one per point, spot or directional light (" + to_text(delta.lights.size()) + ")");
  const ProgressCallback& progress = options.progress;
  RenderOptions gather_options = options;
  gather_options.progress = progress ? [&](double f) { return progress(0.7 * f); } : ProgressCallback();
  const std::vector<PixelLayers> scattered = gather_scattered(delta, volume, delta_depths, solution, step_cells, sky, view, gather_options);
  RenderOptions march_options = options;
  march_options.progress = progress ? [&](double f) { return progress(0.7 + 0.3 * f); } : ProgressCallback();
  return add_unscattered(scene, volume, delta_depths, solution.delta_m_fraction, step_cells, march_options, view, scattered);
}

std::vector<PixelLayers> gather_planes(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& delta_depths,
                                       const DomSolution& part, double step_cells, std::array<int, 2> planes, const View& view,
                                       const RenderOptions& options) {
  if (!scene.surfaces.empty())
    throw Error("surfaces", to_text(scene.surfaces.size()) + " surfaces", "none (the scattered light of a part of the planes reaches no surface)");
  const int nz = volume.density.resolution()[2];
  const int first = part.first_plane, last = part.first_plane + part.resolution[2];
  if (!(0 <= planes[0] && planes[0] < planes[1] && planes[1] <= nz) || first > std::max(planes[0] - 1, 0) || last < std::min(planes[1] + 1, nz))
    throw Error("planes", "[" + to_text(planes[0]) + ", " + to_text(planes[1]) + ") of a part holding [" + to_text(first) + ", " + to_text(last) + ")",
                "planes within the grid's " + to_text(nz) + ", the part holding one more on each side (the trilinear stencil's reach)");
  Rgb sky;
  const Scene delta = without_sky(scene, sky);
  return gather_scattered(delta, volume, delta_depths, part, step_cells, sky, view, options, &planes);
}

RenderResult add_unscattered(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& delta_depths, double delta_m_fraction,
                             double step_cells, const RenderOptions& options, const View& view, const std::vector<PixelLayers>& scattered) {
  Rgb sky;
  Scene delta = without_sky(scene, sky);
  delta.background += sky;
  const size_t pixels = static_cast<size_t>(view.camera.width_px) * static_cast<size_t>(view.camera.height_px);
  if (delta_depths.size() != delta.lights.size())
    throw Error("depths", to_text(delta_depths.size()) + " volumes", "one per point, spot or directional light (" + to_text(delta.lights.size()) + ")");
  if (scattered.size() != pixels) throw Error("scattered", to_text(scattered.size()) + " pixels", "one per pixel of the view (" + to_text(pixels) + ")");
  // Unscattered light (surfaces, background): the marcher with albedo 0 and, under delta-M, the
  // scaled extinction, which counts the forward peak as unscattered (as DISORT does).
  ExtinctionVolume dark = volume;
  dark.sigma_t_scale = dom::delta_m_sigma_t(volume.sigma_t_scale, volume.albedo, delta_m_fraction);
  dark.albedo = Rgb(0.0);
  const RenderResult direct = march_view(delta, dark, delta_depths, MarchSettings{step_cells}, options, View{view.camera, view.depth, true});
  // One transmittance for both, the march's: the gather's own differs from it only by float
  // rounding (the same steps and extinction, in double).
  RenderResult result = RenderResult::for_view(view);
  for (int y = 0; y < view.camera.height_px; ++y)
    for (int x = 0; x < view.camera.width_px; ++x) {
      const PixelLayers& s = scattered[static_cast<size_t>(y) * static_cast<size_t>(view.camera.width_px) + static_cast<size_t>(x)];
      result.set(x, y, {direct.inscatter->at(x, y) + s.inscatter, direct.transmittance->at(x, y), direct.surface->at(x, y) + s.surface});
    }
  return result;
}

namespace {

// Prepared: the extinction volume, the depth to every delta light and the converged moments.
class DomMethodSolution final : public GridSolution {
 public:
  DomMethodSolution(const Scene& scene, DomFields fields)
      : GridSolution(scene, std::move(fields.volume), std::move(fields.delta_depths), fields.step_cells),
        solution_(std::move(fields.solution)),
        cells_(fields.cells),
        settings_(fields.settings),
        depth_(fields.depth),
        warm_iterations_(fields.warm_iterations),
        surface_passes_(fields.surface_passes) {
    stats = std::move(fields.stats);
  }

  const DomSolution* dom() const override { return &solution_; }

  RenderResult render(const View& view, const RenderOptions& options) const override {
    const Stopwatch watch;
    const Scene seen = view_scene(scene_, view.camera);
    RenderResult result = render_dom(seen, volume_, depths_, solution_, step_cells_, options, view);
    result.stats["render_seconds"] = watch.seconds();
    return result;
  }
  bool renders_layers() const override { return true; }

  // Without surfaces or emission, into the caller's spans, C the background and the sky where no
  // depth ends the ray: for rays from one eye and directional lights only, render_distances'
  // kernel path to each pixel's depth (the moments' light toward the eye per cell, TowardEye, made
  // each frame; a point light's 1 / r^2 between the steps puts it 3.5% off the gather in the layers
  // test's box); else per pixel the gather along its ray to its depth (render's scattered light,
  // its T' the delta-M scaled transmittance).
  bool render_layers(const View& view, LayerSpans out, const RenderOptions& options) const override {
    if (!scene_.surfaces.empty() || volume_.emission.emits()) return false;
    const dom::Gather& gather = froxel_gather();
    const Rgb background = delta_.background + sky_;
    const bool suns = std::all_of(delta_.lights.begin(), delta_.lights.end(), [](const Light& l) { return std::holds_alternative<DirectionalLight>(l); });
    if (Vec3 eye; suns && toward_eye_ && view.camera.eye(eye)) {
      thread_local std::vector<float> kept;  // as render_distances'
      std::vector<float>& radiance = kept;
      const MarchScattered toward = scattered_toward(eye, radiance, options);
      MarchSettings march;
      march.step_cells = step_cells_;
      if (march_layers(delta_, volume_, depths_, march, options, view, {out.inscatter, out.transmittance, {}}, &packed_, &toward)) {
        if (out.surface.data)
          for (int y = 0; y < view.camera.height_px; ++y)
            for (int x = 0; x < view.camera.width_px; ++x) {
              const Rgb surface = std::isinf(view.max_distance(x, y)) ? background : Rgb(0.0);
              float* si = out.surface.pixel(x, y);
              for (int ch = 0; ch < 3; ++ch) si[ch] = static_cast<float>(surface[ch]);
            }
        return true;
      }
    }
    each_ray(view.camera, options, [&](int x, int y, const Ray& ray, const Eigen::VectorXd& c, double, double) {
      const double depth = view.max_distance(x, y);
      Rgb t;
      const Rgb l = gather.along(ray, depth, c, t);
      float* li = out.inscatter.pixel(x, y);
      float* ti = out.transmittance.pixel(x, y);
      for (int ch = 0; ch < 3; ++ch) li[ch] = static_cast<float>(l[ch]), ti[ch] = static_cast<float>(t[ch]);
      if (out.surface.data) {
        const Rgb surface = std::isinf(depth) ? background : Rgb(0.0);
        float* si = out.surface.pixel(x, y);
        for (int ch = 0; ch < 3; ++ch) si[ch] = static_cast<float>(surface[ch]);
      }
    });
    return true;
  }

  // Without surfaces or emission, each ray marched once. For rays from one eye, the propagation
  // marcher's SIMD kernel (march_distances) with the moments' scattered light toward that eye as a
  // radiance per cell (TowardEye, made each frame) beside the lights' single scattering, the
  // delta-M scaled steps of the gather's formula (dom_gather.h); else each ray's stretch between
  // consecutive distances gathered in steps of its own (Gather::along_stretch) and the stretches
  // chained front to back, L(d_k) = L(d_k-1) + T(d_k-1) L_k, T(d_k) = T(d_k-1) T_k (what the
  // layered render at d_k gives, but for where the steps fall).
  bool render_distances(const View& view, std::span<const double> distances, const RenderOptions& options, DistanceLayers out) const override {
    if (!scene_.surfaces.empty() || volume_.emission.emits()) return false;
    const dom::Gather& gather = froxel_gather();
    if (Vec3 eye; toward_eye_ && view.camera.eye(eye)) {
      thread_local std::vector<float> kept;  // this thread's frame after frame; the rows read it meanwhile
      std::vector<float>& radiance = kept;
      const MarchScattered toward = scattered_toward(eye, radiance, options);
      MarchSettings march;
      march.step_cells = step_cells_;
      if (march_distances(delta_, volume_, depths_, march, options, view, distances, out, &packed_, &toward)) return true;
    }
    const Camera& camera = view.camera;
    const auto width = static_cast<size_t>(camera.width_px);
    const size_t per_slice = width * static_cast<size_t>(camera.height_px);
    const double pitch = camera.pixel_angle();  // a column's width per unit distance: no finer steps along it
    each_ray(camera, options, [&](int x, int y, const Ray& ray, const Eigen::VectorXd& c, double t0, double t1) {
      const bool inside = t1 > t0;
      Rgb l(0.0), t(1.0);
      for (size_t k = 0; k < distances.size(); ++k) {
        const double from = std::max(t0, k == 0 ? 0.0 : distances[k - 1]), to = std::min(t1, distances[k]);
        if (inside && to > from) {
          Rgb t_k;
          const Rgb l_k = gather.along_stretch(ray, from, to, c, t_k, pitch * from);
          l += t * l_k, t *= t_k;
        }
        const size_t at = k * per_slice + static_cast<size_t>(y) * width + static_cast<size_t>(x);
        out.inscatter[at] = Vec3f(l), out.transmittance[at] = Vec3f(t);
      }
    });
    return true;
  }

  // A new density (re-injected by region where it can: replace_volume) redoes every light's depth,
  // new lights only those that differ; the moments then iterate from the previous ones
  // (warm_iterations sweeps, or to the tolerance).
  std::optional<UpdateReport> update(const Scene& scene, const SceneChange& change, const RenderOptions& options) override {
    UpdateReport report;
    Stopwatch watch;
    gather_.reset();  // it views the scene, volume, depths and moments about to change
    depth_.threads = settings_.threads = options.threads;
    if (change.medium) {
      const std::array<int, 3> shape = volume_.density.resolution();
      report.redone.push_back(replace_volume(scene, change, cells_, 0.0, options.threads));
      if (volume_.density.resolution() != shape) return std::nullopt;  // a new shape: solve again
    }
    update_depths(scene, change.medium.has_value(), depth_, report);
    report.stats["depth_seconds"] = watch.lap();
    const bool relit = change.medium || change.lights || change.surfaces;  // surfaces shadow the first-collision source
    if (relit) {
      DomSettings warm = settings_;
      warm.progress = options.progress;
      // A budget of sweeps: source iteration, each sweep with the first-collision source in it.
      if (warm_iterations_ > 0) warm.max_iterations = warm_iterations_, warm.accelerator = DomAccelerator::none, warm.fold_first_collision = true;
      SurfaceSolve next = solve_with_surfaces(scene, volume_, depths_, warm, &solution_, surface_passes_, step_cells_, &spare_);
      report.redone.push_back("moments: first-collision source and " + to_text(next.iterations) + " sweeps over " +
                              to_text(next.solution.channels) + " channel(s) from the previous solution" +
                              (next.passes > 0 ? ", " + to_text(next.passes) + " surface pass(es)" : std::string()));
      report.stats["iterations"] = next.iterations;
      report.stats["final_change"] = next.solution.changes.empty() ? 0.0 : next.solution.changes.back();
      report.stats["converged"] = next.solution.converged;
      report.stats["sweep_seconds"] = next.solution.sweep_seconds;
      next.solution.texel_surfaces = solution_.texel_surfaces;
      for (std::vector<float>& m : solution_.moments) spare_.push_back(std::move(m));  // the next update's buffers
      spare_.resize(std::min<size_t>(spare_.size(), 2 * static_cast<size_t>(next.solution.channels)));
      solution_ = std::move(next.solution);
      // The warnings hold for the solution as it now is (a new density may have thicker cells).
      say_warnings(volume_, solution_, settings_, warm_iterations_ > 0, stats);
      report.stats["thickest_cell"] = stats["thickest_cell"];
      report.stats["warnings"] = stats["warnings"];
    }
    report.stats["solve_seconds"] = watch.lap();
    scene_ = scene;
    return report;
  }

 private:
  // fn(x, y, ray, c, t0, t1) for each pixel's ray of the camera, row by row on the threads:
  // [t0, t1] its stretch in the medium (t1 <= t0 where it misses) and c its direction's in-scatter
  // weights (inscatter_weights) where it meets it. Each thread keeps its rays and weights: a frame
  // allocates nothing once they have grown.
  template <class Fn>
  void each_ray(const Camera& camera, const RenderOptions& options, const Fn& fn) const {
    const auto width = static_cast<size_t>(camera.width_px);
    const Aabb bounds = volume_.density.bounds();
    const auto rows = [&](long long y0, long long y1) {
      thread_local std::vector<Ray> rays;
      thread_local Eigen::VectorXd row, c;
      rays.resize(width);
      for (auto y = static_cast<int>(y0); y < y1; ++y) {
        camera.row_rays(y, rays.data());
        for (size_t x = 0; x < width; ++x) {
          double t0 = 0.0, t1 = kInfinity;
          if (!bounds.clip(rays[x], t0, t1)) t1 = t0;
          if (t1 > t0) inscatter_weights(solution_, -rays[x].direction, row, c);
          fn(static_cast<int>(x), y, rays[x], c, t0, t1);
        }
      }
    };
    parallel_for(camera.height_px, options.threads, 1, [&rows](long long y0, long long y1) { rows(y0, y1); });
  }

  // The moments' light toward `eye` per cell into `radiance` (TowardEye), as the marcher's steps
  // take it with the delta-M scaled extinction and albedo. froxel_gather() first.
  MarchScattered scattered_toward(const Vec3& eye, std::vector<float>& radiance, const RenderOptions& options) const {
    const double f = solution_.delta_m_fraction;
    const Rgb single = volume_.albedo / (Rgb(1.0) - volume_.albedo * f), scattered = dom::delta_m_albedo(volume_.albedo, f);
    Rgb scale(0.0);
    for (int c = 0; c < 3; ++c) scale[c] = single[c] > 0.0 ? scattered[c] / single[c] : 0.0;
    toward_eye_->fill(volume_.density, eye, scale, radiance, options.threads);
    return {radiance.data(), toward_eye_->channels(), dom::delta_m_sigma_t(volume_.sigma_t_scale, volume_.albedo, f), single};
  }

  // render_distances' gather over the scene less its sky, made on first use after a prepare or
  // update (renders may run on several threads at once: made under the lock).
  // With it, render_distances' kernel path: the weights' table and the lights' depths packed for
  // the marcher (where the moments fit TowardEye's 64 terms and the solution holds the whole grid).
  const dom::Gather& froxel_gather() const {
    std::lock_guard lock(gather_mutex_);
    if (!gather_) {
      delta_ = without_sky(scene_, sky_);
      gather_ = std::make_unique<dom::Gather>(delta_, volume_, depths_, solution_, step_cells_, 1, nullptr);
      if (solution_.terms() <= 64 && solution_.first_plane == 0 && solution_.resolution == volume_.density.resolution()) {
        if (!toward_eye_ || !toward_eye_->made_for(solution_)) toward_eye_ = std::make_unique<dom::TowardEye>(solution_);
        packed_ = pack_lights(delta_, volume_, depths_, settings_.threads);
      } else {
        toward_eye_.reset();
      }
    }
    return *gather_;
  }

  DomSolution solution_;
  std::vector<std::vector<float>> spare_;  // moments' buffers an update reuses (solve_dom's spare)
  mutable std::mutex gather_mutex_;
  mutable Scene delta_;
  mutable Rgb sky_;
  mutable std::unique_ptr<dom::Gather> gather_;
  mutable std::unique_ptr<dom::TowardEye> toward_eye_;
  mutable PackedLights packed_;
  CellCount cells_;
  DomSettings settings_;
  DepthOptions depth_;
  int warm_iterations_;
  int surface_passes_;
};

class DomMethod final : public Method {
 public:
  std::unique_ptr<MethodSolution> prepare(const Scene& scene, const RenderOptions& options) const override {
    return std::make_unique<DomMethodSolution>(scene, dom_fields(scene, options));
  }
};

}  // namespace

DomFields dom_setup(const Scene& scene, const RenderOptions& options) {
  Settings settings(options.settings, kDomName);
  // Cells along the longest side, at least 4 per optical depth through a thinner axis (up to 32),
  // or exactly the three counts given.
  CellCount cells;
  if (const std::vector<int> n = settings.cells("resolution"); n.size() == 3) {
    cells.axes = {n[0], n[1], n[2]};
  } else {
    cells.longest = n[0];
    cells.per_optical_depth = kCellsPerOpticalDepth;
  }
  DomSettings dom;
  dom.directions = static_cast<int>(settings.integer("directions"));
  dom.terms = static_cast<int>(settings.integer("terms", std::min(dom.terms, dom.directions)));
  if (dom.terms > dom.directions)
    throw Error("method.terms", to_text(dom.terms), "at most method.directions (" + to_text(dom.directions) + "), or 0 for the full matrix");
  dom.scheme = dom_scheme_from_name(settings.choice("scheme"));
  // The paper's scheme is the step scheme: it takes diamond only when asked (and refuses it).
  dom.spatial = dom_spatial_from_name(dom.scheme == DomScheme::paper ? settings.choice("spatial", name(DomSpatial::step)) : settings.choice("spatial"));
  dom.accelerator = dom_accelerator_from_name(settings.choice("accelerator"));
  dom.max_iterations = static_cast<int>(settings.integer("iterations"));
  dom.tolerance = settings.number("tolerance");
  dom.delta_m = settings.integer("delta_m") != 0;
  dom.diffusion_acceleration = settings.integer("dsa") != 0;
  dom.storage = dom_storage_from_name(settings.choice("storage"));
  dom.threads = options.threads;
  dom.max_memory = options.max_memory;
  DepthOptions depth;
  depth.scheme = depth_scheme_from_name(settings.choice("optical_depth"));
  depth.threads = options.threads;
  const double step_cells = settings.number("step");
  const int warm_iterations = static_cast<int>(settings.integer("warm_iterations"));
  const int surface_passes = static_cast<int>(settings.integer("surface_passes"));
  const bool texel_surfaces = settings.choice("surface_view") == "texels";
  settings.reject_unknown();

  Stopwatch watch;
  ExtinctionVolume volume = make_extinction_volume(scene, cells, 0.0, options.threads);
  // Delta lights get depth volumes; the sky enters the solver through the boundary and reaches
  // the eye as background.
  std::vector<DenseGrid> delta_depths;
  check_depth_memory(volume.density, scene.lights, options.max_memory);
  for (const Light& l : scene.lights)
    if (!std::holds_alternative<SkyLight>(l)) delta_depths.push_back(optical_depth(volume.density, l, depth));
  DomFields fields{std::move(volume), std::move(delta_depths), {}, step_cells, {}, cells, dom, depth, warm_iterations, surface_passes};
  fields.solution.texel_surfaces = texel_surfaces;
  fields.stats["depth_seconds"] = watch.seconds();
  return fields;
}

DomFields dom_fields(const Scene& scene, const RenderOptions& options) {
  DomFields fields = dom_setup(scene, options);
  const Stopwatch watch;
  DomSettings dom = fields.settings;
  dom.progress = options.progress;
  SurfaceSolve solved_surfaces = solve_with_surfaces(scene, fields.volume, fields.delta_depths, dom, nullptr, fields.surface_passes, fields.step_cells);
  const double solve_seconds = watch.seconds(), depth_seconds = fields.stats["depth_seconds"];
  solved_surfaces.solution.texel_surfaces = fields.solution.texel_surfaces;
  fields.solution = std::move(solved_surfaces.solution);
  const ExtinctionVolume& v = fields.volume;
  const DomSolution& solved = fields.solution;
  fields.stats = {{"cells", v.density.resolution()},
                  {"directions", dom.directions},
                  {"terms", solved.terms()},
                  {"phase_relative_error", solved.separable->relative_error()},
                  {"delta_m_fraction", solved.delta_m_fraction},
                  {"scheme", name(dom.scheme)},
                  {"spatial", name(dom.spatial)},
                  {"accelerator", name(dom.accelerator)},
                  {"storage", name(dom.storage)},
                  {"channels", solved.channels},
                  {"iterations", solved_surfaces.iterations},
                  {"surface_passes", solved_surfaces.passes},
                  {"surface_seconds", solved_surfaces.surface_seconds},
                  {"converged", solved.converged},
                  {"final_change", solved.changes.empty() ? 0.0 : solved.changes.back()},
                  {"skipped_fraction", solved.skipped_fraction},
                  {"sweep_seconds", solved.sweep_seconds},
                  {"first_collision_seconds", solved.first_collision_seconds},
                  {"memory_bytes", solved.bytes},
                  {"depth_seconds", depth_seconds},
                  {"solve_seconds", solve_seconds}};
  say_warnings(v, solved, dom, false, fields.stats);
  return fields;
}

namespace {

// Settings for fine cells: 64 directions (8 per octant, the kernel's lanes), float16 storage (the
// first-collision source and GMRES's basis; the dense cloud's image is unchanged).
nlohmann::json fine_cell_settings(int resolution, int terms) {
  return {{"resolution", resolution}, {"directions", 64}, {"terms", terms}, {"storage", "float16"}};
}
nlohmann::json cells(int resolution, int directions, int terms) { return {{"resolution", resolution}, {"directions", directions}, {"terms", terms}}; }
// Surfaces in fog: the diamond bounded in every cell, whose diffusion damps the lamps' ray effects
// (fog_lamps 2.19% at 48^3 against 2.58% with the fix-up alone; thin_haze 1.61% and 1.59%).
nlohmann::json fog_cells(int resolution, int directions, int terms) {
  nlohmann::json settings = cells(resolution, directions, terms);
  settings["spatial"] = "bounded";
  return settings;
}

// Auto's offers, from the trade suite's scenes against their references (haze bench trade, 2
// threads), cheapest first.
struct Offers {
  // Surfaces in fog: fog_lamps and thin_haze (constant fog over a floor with a sphere inside the
  // grid; multiple shares 58% and 16%). No better past 48^3 (2.4% and 1.6% at 96^3: the sphere
  // neither blocks nor sends light in the sweeps).
  std::vector<MeasuredOffer> fog, thin_fog;
  // A cloud over surfaces: cloud_sun (an RBF cloud over a floor, albedo 0.92, the diamond's
  // fix-up). Clouds of higher albedo are not measured.
  std::vector<MeasuredOffer> cloud_over_surfaces;
  // The dense cloud (albedo 0.99, three channels) against its 262144-spp reference: the diamond
  // with its fix-up, 64 directions, 9 terms, float16 storage.
  std::vector<MeasuredOffer> dense_cloud;
  std::vector<MeasuredOffer> particles;

  Offers() {
    const MeasuredOffer fog16{0.05, fog_cells(16, 32, 9), 0.35, "fog_lamps and thin_haze measured 4.0% and 3.0% at 16^3 (2026-12-02)"},
        fog24{0.035, fog_cells(24, 48, 16), 0.8, "fog_lamps and thin_haze measured 3.1% and 2.0% at 24^3 (2026-12-02)"},
        fog32{0.03, fog_cells(32, 80, 25), 1.7, "fog_lamps and thin_haze measured 2.3% and 1.6% at 32^3 (2026-12-02)"};
    fog = {fog16, fog24, fog32, {0.025, fog_cells(48, 128, 25), 4.0, "fog_lamps measured 2.2% at 48^3 (2026-12-02)"}};
    thin_fog = {fog16, fog24, fog32, {0.02, fog_cells(32, 80, 25), 1.7, "thin_haze (multiple share 16%) measured 1.6% at 32^3 (2026-12-02)"}};
    cloud_over_surfaces = {{0.04, cells(16, 32, 9), 0.20, "cloud_sun measured 3.3% at 16^3 (2026-12-02)"},
                           {0.025, cells(24, 48, 16), 0.44, "cloud_sun measured 1.9% at 24^3 (2026-12-02)"},
                           {0.014, cells(32, 80, 25), 1.2, "cloud_sun measured 1.1% at 32^3 (2026-12-02)"},
                           {0.008, fine_cell_settings(48, 16), 2.4, "cloud_sun measured 0.68% at 48^3 with 64 directions (2026-12-02)"},
                           {0.006, cells(48, 128, 25), 4.0, "cloud_sun measured 0.49% at 48^3 (2026-12-02)"},
                           {0.0045, cells(64, 128, 25), 8.9, "cloud_sun measured 0.37% at 64^3 (2026-12-02)"}};
    dense_cloud = {{0.03, fine_cell_settings(48, 9), 0.67, "the suite's dense cloud measured 2.75% at 48^3 (2026-12-02)"},
                   {0.02, fine_cell_settings(60, 9), 1.2, "the suite's dense cloud measured 1.75% at 60^3 (2026-12-02)"},
                   {0.014, fine_cell_settings(72, 9), 2.1, "the suite's dense cloud measured 1.22% at 72^3 (2026-12-02)"},
                   {0.009, fine_cell_settings(88, 9), 3.4, "the suite's dense cloud measured 0.82% at 88^3 (2026-12-02)"},
                   {0.005, fine_cell_settings(128, 9), 11.0, "the suite's dense cloud measured 0.45% at 128^3 (2026-12-02)"}};
    particles = {{0.0, cells(16, 32, 9), 4.0, "the suite's particle cloud measured 0.42% at 16^3 and 32 directions in 4 s"}};
  }
};

AutoOffer dom_offer(const SceneFeatures& f, double tolerance) {
  static const Offers offers;
  if (f.density == "particles") return offer_from(offers.particles, tolerance, "on the particles' density", "");
  if (f.homogeneous && !f.bounded) return AutoOffer{false, {}, 0.0, "an unbounded homogeneous medium has no grid"};
  if (f.surfaces && f.homogeneous) {
    const bool thin = f.multiple_share < 0.3;
    return offer_from(thin ? offers.thin_fog : offers.fog, tolerance, thin ? "surfaces in thin fog" : "surfaces in fog",
                      thin ? "surfaces in thin fog: 1.6% at best on the suite"
                           : "surfaces in fog: 2.2% at best on the suite (a sphere inside the grid is left out of the sweeps)");
  }
  if (f.surfaces && f.albedo > 0.95) return AutoOffer{false, {}, 0.0, "surfaces under a cloud of albedo over 0.95: not measured"};
  if (f.surfaces) return offer_from(offers.cloud_over_surfaces, tolerance, "a cloud over surfaces", "a cloud over surfaces: 0.37% at best measured (64^3)");
  return offer_from(offers.dense_cloud, tolerance, "a cloud", "under its measured 0.45% at 128^3 on the suite's dense cloud");
}

}  // namespace

MethodInfo dom_info() {
  MethodInfo info;
  info.name = kDomName;
  info.emission = true;  // an isotropic source in the sweeps (lights the medium and surfaces) and in the camera's march
  info.summary = "multiple scattering on grids: discrete ordinates with a separable phase function (seed 000)";
  info.create = [] { return std::make_unique<DomMethod>(); };
  info.handles = {"RBF, grid and bounded constant densities, the particles' density", "point, spot, directional, sky",
                  "planes, spheres and meshes: shadows, the medium's light onto them and theirs into it (outside the grid or on its faces), and between them", true};
  const DomSettings d;
  info.settings = {
      SettingInfo::cells("resolution", 64, 2, 1024,
                         "RBF and constant media: cells along the longest side of the bounds (and at least 4 per optical depth through a thinner side, up to 32), or [nx, ny, nz]"),
      SettingInfo::integer("directions", d.directions, 8, 4096, "D, spherical Fibonacci directions"),
      SettingInfo::integer("terms", nullptr, 0, 4096, "N separable terms of the phase matrix: min(25, D); 0 or D: the full matrix"),
      SettingInfo::choice("scheme", name(d.scheme), names_of<DomScheme>(kDomSchemes), "sweep: upwind transport sweeps; paper: seed 000's Jacobi scheme"),
      SettingInfo::choice("spatial", name(d.spatial), names_of<DomSpatial>(kDomSpatials),
                          "how radiance leaves a cell: weighted diamond difference (second order; bounded where radiance would go below 0), "
                          "bounded everywhere (damps lamps' ray effects in fog), or seed 000's step (step with scheme paper)"),
      SettingInfo::choice("accelerator", name(d.accelerator), names_of<DomAccelerator>(kDomAccelerators), "GMRES on the moments, or plain source iteration"),
      SettingInfo::integer("iterations", d.max_iterations, 1, 100000, "transport sweeps per channel at most"),
      SettingInfo::number("tolerance", d.tolerance, 1e-9, 1.0, "stop when an iteration changes the moments by less (relative)"),
      SettingInfo::integer("delta_m", 1, 0, 1, "delta-M scaling of the phase function when N < D"),
      SettingInfo::integer("dsa", 1, 0, 1, "diffusion synthetic acceleration of source iteration (warm updates with a sweep budget)"),
      SettingInfo::choice("storage", name(d.storage), names_of<DomStorage>(kDomStorages), "float16 halves the first-collision source and GMRES basis"),
      SettingInfo::choice("optical_depth", name(DepthScheme::exact), names_of<DepthScheme>(kDepthSchemes), "how the depth to each light is computed"),
      SettingInfo::number("step", 0.5, 0.01, 4.0, "camera gather's ray-march step in cells"),
      SettingInfo::integer("warm_iterations", 0, 0, 100000, "source-iteration sweeps per update, the first-collision source in each (0: GMRES to the tolerance)"),
      SettingInfo::integer("surface_passes", 2, 0, 100, "solves with the light surfaces reflect into the medium, one more bounce each (scheme sweep)"),
      SettingInfo::choice("surface_view", "rays", {"rays", "texels"},
                          "visible surfaces' scattered light: 64 rays per pixel, or the surfaces' texels (what the GL display shows)")};
  for (auto [resolution, directions, terms] : {std::tuple{16, 32, 9}, {24, 48, 16}, {32, 80, 25}, {48, 128, 25}, {64, 128, 25}, {96, 128, 25}})
    info.trade_sweep.push_back({{"resolution", resolution}, {"directions", directions}, {"terms", terms}});
  // Finer cells with fewer directions and terms: 64 fill the kernel's 8 lanes in each octant, and
  // the dense cloud's error is in the cell size, not the directions (at 64^3: 2.10% with 64, 2.12%
  // with 128, bounded everywhere); 9 terms (delta-M's truncation at l = 3) beat 16 there (0.70%
  // and 0.75% at 96^3), not on cloud_sun (1.18% and 0.68% at 48^3).
  for (int resolution : {48, 60, 88, 128})
    info.trade_sweep.push_back(fine_cell_settings(resolution, 9));
  // Fog with lamps: bounded everywhere (fog_cells).
  info.trade_sweep.push_back({{"resolution", 32}, {"directions", 80}, {"terms", 25}, {"spatial", "bounded"}});
  info.trade_sweep.push_back({{"resolution", 48}, {"directions", 128}, {"terms", 25}, {"spatial", "bounded"}});
  info.offer = dom_offer;
  return info;
}

}  // namespace haze::grids
