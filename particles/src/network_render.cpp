// Camera rays through the particles' Gaussians (network.h, render_network), and method "network".
#include <haze/core/error.h>
#include <haze/core/stopwatch.h>
#include <haze/particles/network.h>

#include "erf_table.h"
#include "network_internal.h"

#include <algorithm>
#include <cmath>

namespace haze::particles {

using network_internal::FilmProjection;
using network_internal::PixelSink;
using network_internal::SplatInputs;
using network_internal::splat_network;

// The method's name, written once: the registry, its settings and its errors read it here.
constexpr const char* kNetworkName = "network";

namespace {

constexpr int kTile = 16;
constexpr int kSurfaceDirections = 64;  // over the sphere: a surface point's hemisphere gets about half
// The span of the phase matrix's raw row sums past which the network warns (docs/NETWORKS.md).
constexpr double kRowSumRange[2] = {0.8, 1.25};

// A particle's Gaussian along a ray: rho(t) = amplitude / (sqrt(pi) h) exp(-(t - centre)^2 / h^2).
struct Along {
  double centre, h, amplitude;  // amplitude: its integral over the whole line
  int index;
  double enter() const { return centre - kCut * h; }
  double leave() const { return centre + kCut * h; }
};

// The formal solution along the ray through the particles' Gaussians, in steps of at most a
// half of the narrowest active width: each step's optical depth per particle is exact (erf
// differences), and the step's source is the particles' scattered radiance weighted by their
// share of that depth (the SPH interpolation of the source), plus `direct(t)`, the single-scattered
// direct light at the step's middle, up to t_end (a surface). Returns the radiance; leaves the
// transmittance through all of it.
template <class Direct>
Rgb march(std::vector<Along>& along, const Rgb& sigma_t, const std::vector<Rgb>& scattered, const Direct& direct, Rgb& transmittance,
          double t_end) {
  Rgb radiance(0.0);
  if (along.empty()) return radiance;
  std::sort(along.begin(), along.end(), [](const Along& a, const Along& b) { return a.enter() < b.enter(); });
  const ErfTable& erf = ErfTable::instance();
  std::vector<double> erf_at(along.size());  // erf((t - centre) / h) at the current t, per entered particle
  std::vector<size_t> active;
  double t = std::max(0.0, along[0].enter());
  size_t next = 0;
  while ((next < along.size() || !active.empty()) && t < t_end) {
    if (active.empty()) t = std::max(t, along[next].enter());
    if (!(t < t_end)) break;
    while (next < along.size() && along[next].enter() <= t) {
      erf_at[next] = erf((t - along[next].centre) / along[next].h);
      active.push_back(next++);
    }
    double step = kInfinity;
    for (size_t a : active) step = std::min(step, 0.5 * along[a].h);
    double t1 = t + step;
    if (next < along.size()) t1 = std::min(t1, std::max(t + 1e-9, along[next].enter()));
    t1 = std::min(t1, t_end);
    double tau = 0.0;
    Rgb source(0.0);
    for (size_t a : active) {
      const Along& g = along[a];
      const double e1 = erf((t1 - g.centre) / g.h), dtau = 0.5 * g.amplitude * (e1 - erf_at[a]);
      erf_at[a] = e1;
      tau += dtau;
      source += dtau * scattered[static_cast<size_t>(g.index)];
    }
    if (tau > 0.0) {
      source += tau * direct(0.5 * (t + t1));
      const Rgb step_transmittance = glm::exp(-sigma_t * tau);
      radiance += transmittance * (Rgb(1.0) - step_transmittance) * source / tau;
      transmittance *= step_transmittance;
    }
    t = t1;
    std::erase_if(active, [&](size_t a) { return along[a].leave() <= t; });
  }
  return radiance;
}

// render_network, each pixel's layers handed to `sink`; returns the render's stats.
nlohmann::json render_into(const Scene& scene, const ParticleField& field, const NetworkSolution& solution, const RenderOptions& options,
                           const View& view, NetworkRender render, const PixelSink& sink, const LayerSpans* layers = nullptr) {
  const Camera& cam = view.camera;
  if (cam.type == Camera::Type::rays)
    throw Error("view.camera", "per-pixel rays", "a camera with one eye (pinhole, orthographic or matrices) for method network, whose "
                "particles scatter toward the eye");
  // Toward the eye from x: an orthographic camera's is one direction.
  const bool parallel = cam.type == Camera::Type::orthographic || (cam.type == Camera::Type::matrices && cam.projection[2][3] == 0.0);
  const Vec3 backward = cam.type == Camera::Type::matrices ? glm::normalize(Vec3(cam.view_inverse * glm::dvec4(0.0, 0.0, 1.0, 0.0)))
                                                           : glm::normalize(cam.position - cam.look_at);
  Vec3 eye(0.0);
  cam.eye(eye);  // false for parallel rays
  const MaterialDesc& material = field.particles().material;
  Rgb background = scene.background;
  size_t delta = 0;  // point, spot and directional lights
  for (const Light& l : scene.lights) {
    if (const auto* s = std::get_if<SkyLight>(&l)) background += s->radiance;
    else ++delta;
  }
  const size_t n = field.size();
  if (n > 0 && (solution.visibility.particles != static_cast<int>(n) || solution.light_maps.size() != delta))
    throw Error("solution", "one for other particles or lights", "the network solved for these particles and lights");
  // Each particle's multiply scattered radiance toward the eye (seed 001 section 3.3, last
  // paragraphs): albedo times the network's in-scattering at the eye's direction (the phase-matrix
  // row extended off the direction set, PhaseMatrix::row). Direct light is added per ray step.
  const auto d = static_cast<size_t>(solution.directions->size());
  const auto emitted = [&](size_t p) {  // the emission's source function at particle p
    if (solution.emitted[0].empty()) return Rgb(0.0);
    return Rgb(solution.emitted[0][p], solution.emitted[1][p], solution.emitted[2][p]);
  };
  std::vector<Rgb> scattered(n);
  parallel_for(static_cast<long long>(n), options.threads, 64, [&](long long p0, long long p1) {
    for (auto p = static_cast<size_t>(p0); p < static_cast<size_t>(p1); ++p) {
      const Vec3 x = field.position(p);
      const Vec3 w = parallel ? backward : glm::normalize(eye - x);
      const Eigen::VectorXd row = solution.matrix->row(w);
      Rgb j(0.0);
      for (int c = 0; c < 3; ++c)
        for (size_t i = 0; i < d; ++i) j[c] += row(static_cast<long>(i)) * static_cast<double>(solution.incoming[static_cast<size_t>(c)][i * n + p]);
      scattered[p] = material.albedo * j + emitted(p);
    }
  });
  // Single-scattered direct light at any point, from the lights' depth maps, with the exact phase
  // function toward the eye; within a quarter of the mean particle width of a point light, the
  // irradiance there.
  const double nearest = n ? 0.25 * field.mean_h() : 0.0;
  const auto direct = [&](const Vec3& x, const Vec3& w) {
    Rgb s(0.0);
    for (const LightDepthMap& map : solution.light_maps) {
      LightArrival a;
      if (map.arrival(x, material.sigma_t, nearest, a) && !occluded(scene.surfaces, x, a.to_light, a.distance))
        s += material.phase.eval(glm::dot(-a.to_light, w)) * a.irradiance;
    }
    return material.albedo * s;
  };
  // The light the particles scatter onto surfaces (the first bounce, medium to surface): along K
  // Fibonacci directions w_j from a surface point, the same march as a camera ray's toward -w_j
  // (each particle's in-scattering toward -w_j, direct light per step), up to the next surface,
  // plus the sky through the particles where no surface is hit. Every particle is tested against
  // each such ray (rays that miss the particles' bounding sphere skip them).
  const DirectionSet around = DirectionSet::fibonacci(kSurfaceDirections);
  std::vector<std::vector<Rgb>> around_scattered;  // [j][particle]
  Vec3 support_centre(0.0);
  double support_radius = 0.0;
  if (!scene.surfaces.empty() && n > 0) {
    around_scattered.assign(static_cast<size_t>(around.size()), std::vector<Rgb>(n));
    parallel_for(around.size(), options.threads, 1, [&](long long j0, long long j1) {
      for (auto j = j0; j < j1; ++j) {
        const Eigen::VectorXd row = solution.matrix->row(-around[static_cast<int>(j)]);
        for (size_t p = 0; p < n; ++p) {
          Rgb sum(0.0);
          for (int c = 0; c < 3; ++c)
            for (size_t i = 0; i < d; ++i) sum[c] += row(static_cast<long>(i)) * static_cast<double>(solution.incoming[static_cast<size_t>(c)][i * n + p]);
          around_scattered[static_cast<size_t>(j)][p] = material.albedo * sum + emitted(p);
        }
      }
    });
    for (size_t p = 0; p < n; ++p) support_centre += field.position(p) / static_cast<double>(n);
    for (size_t p = 0; p < n; ++p) support_radius = std::max(support_radius, glm::length(field.position(p) - support_centre) + kCut * field.h(p));
  }
  const auto arriving = [&](const Vec3& x, int j, std::vector<Along>& along) {
    const Ray ray{x, around[j]};
    double t_next = kInfinity;
    Vec3 unused;
    const bool blocked = nearest_surface(scene.surfaces, ray, kInfinity, t_next, unused) != nullptr;
    Rgb transmittance(1.0), radiance(0.0);
    const Vec3 o = support_centre - x;
    const double tc = glm::dot(o, ray.direction);
    if (n > 0 && glm::dot(o, o) - tc * tc < support_radius * support_radius && tc > -support_radius) {
      along.clear();
      for (size_t p = 0; p < n; ++p) {
        const Vec3 op = field.position(p) - x;
        const double h = field.h(p), tp = glm::dot(op, ray.direction), perp2 = glm::dot(op, op) - tp * tp;
        if (field.weight(p) <= 0.0 || perp2 >= kCut * kCut * h * h || tp < -kCut * h || tp - kCut * h >= t_next) continue;
        along.push_back({tp, h, field.weight(p) * std::exp(-perp2 / (h * h)) * std::sqrt(kPi) * h, static_cast<int>(p)});
      }
      radiance = march(
          along, material.sigma_t, around_scattered[static_cast<size_t>(j)], [&](double t) { return direct(ray.at(t), -ray.direction); },
          transmittance, t_next);
    }
    return blocked ? radiance : radiance + transmittance * solution.sky;
  };
  // A surface point's light through the BRDF: the direct light, shadowed by surfaces and through
  // the particles, and what the particles scatter onto it.
  const auto surface_light = [&](const Surface& surface, const Vec3& p, const Vec3& normal, const Vec3& wo, std::vector<Along>& along) {
    Rgb s(0.0);
    for (const LightDepthMap& map : solution.light_maps) {
      LightArrival a;
      if (!map.arrival(p, material.sigma_t, 0.0, a)) continue;
      const double cos_i = glm::dot(normal, a.to_light);
      if (cos_i > 0.0 && !occluded(scene.surfaces, p, a.to_light, a.distance)) s += surface.brdf(a.to_light, wo, normal) * a.irradiance * cos_i;
    }
    for (int j = 0; j < around.size(); ++j)
      if (const double cos_i = glm::dot(normal, around[j]); cos_i > 0.0)
        s += around.weight(j) * cos_i * surface.brdf(around[j], wo, normal) * arriving(p, j, along);
    return s;
  };

  // The particles front to back: by the distance to the eye, or along the view for parallel rays.
  std::vector<std::pair<double, uint32_t>> by_depth;
  by_depth.reserve(n);
  for (size_t p = 0; p < n; ++p)
    if (field.weight(p) > 0.0) by_depth.emplace_back(parallel ? -glm::dot(field.position(p), backward) : glm::length(field.position(p) - eye), static_cast<uint32_t>(p));
  std::sort(by_depth.begin(), by_depth.end());
  // Where pixel (x, y)'s ray ends, and what leaves that end toward the camera.
  const auto end_of = [&](int x, int y, const Ray& ray, double& t_hit, std::vector<Along>& gathered) {
    t_hit = kInfinity;
    Vec3 normal;
    const Surface* surface = nearest_surface(scene.surfaces, ray, view.max_distance(x, y), t_hit, normal);
    return surface ? surface_light(*surface, ray.at(t_hit), normal, -ray.direction, gathered)
           : std::isinf(t_hit) ? background : Rgb(0.0);  // none behind a host's depth
  };
  if (render == NetworkRender::splat) {
    SplatInputs in{cam, field, solution, scattered, direct, nearest, background, [&](const Vec3& x) { return parallel ? backward : glm::normalize(eye - x); }, {},
                   layers};
    if (!scene.surfaces.empty() || !view.depth.empty())
      in.end_of = [&](int x, int y, const Ray& ray, double& t_end) {
        thread_local std::vector<Along> gathered;
        return end_of(x, y, ray, t_end, gathered);
      };
    std::vector<uint32_t> order(by_depth.size());
    std::transform(by_depth.begin(), by_depth.end(), order.begin(), [](const auto& e) { return e.second; });
    return {{"splat_lattice", splat_network(in, order, sink, options)}};
  }
  // The march: particles binned to 16 x 16 tiles of pixels by their footprints (march() orders
  // each ray's).
  const int tiles_x = (cam.width_px + kTile - 1) / kTile, tiles_y = (cam.height_px + kTile - 1) / kTile;
  std::vector<std::vector<uint32_t>> tiles(static_cast<size_t>(tiles_x) * static_cast<size_t>(tiles_y));
  const FilmProjection project{cam};
  for (const auto& [depth, index] : by_depth) {
    double px, py, radius;
    if (!project(field.position(index), kCut * field.h(index), px, py, radius)) continue;
    const int x0 = std::max(0, static_cast<int>(std::floor((px - radius) / kTile))), x1 = std::min(tiles_x - 1, static_cast<int>(std::floor((px + radius) / kTile)));
    const int y0 = std::max(0, static_cast<int>(std::floor((py - radius) / kTile))), y1 = std::min(tiles_y - 1, static_cast<int>(std::floor((py + radius) / kTile)));
    for (int ty = y0; ty <= y1; ++ty)
      for (int tx = x0; tx <= x1; ++tx) tiles[static_cast<size_t>(ty * tiles_x + tx)].push_back(index);
  }
  ProgressTracker progress(options.progress, static_cast<long long>(tiles.size()));
  parallel_for(static_cast<long long>(tiles.size()), options.threads, 1, [&](long long t0, long long t1) {
    for (auto t = t0; t < t1 && !progress.cancelled(); ++t) {
      const std::vector<uint32_t>& list = tiles[static_cast<size_t>(t)];
      const int tx = static_cast<int>(t % tiles_x), ty = static_cast<int>(t / tiles_x);
      std::vector<Along> along, gathered;
      for (int y = ty * kTile; y < std::min(cam.height_px, (ty + 1) * kTile); ++y)
        for (int x = tx * kTile; x < std::min(cam.width_px, (tx + 1) * kTile); ++x) {
          const Ray ray = cam.pixel_ray(x, y);
          double t_hit;
          const Rgb leaving = end_of(x, y, ray, t_hit, gathered);
          along.clear();
          for (const uint32_t index : list) {
            const size_t p = index;
            const Vec3 o = field.position(p) - ray.origin;
            const double h = field.h(p), tc = glm::dot(o, ray.direction), perp2 = glm::dot(o, o) - tc * tc;
            if (perp2 >= kCut * kCut * h * h || tc < -kCut * h || tc - kCut * h >= t_hit) continue;
            along.push_back({tc, h, field.weight(p) * std::exp(-perp2 / (h * h)) * std::sqrt(kPi) * h, static_cast<int>(index)});
          }
          Rgb transmittance(1.0);
          const Rgb radiance = march(
              along, material.sigma_t, scattered, [&](double t) { return direct(ray.origin + t * ray.direction, -ray.direction); }, transmittance,
              t_hit);
          const PixelLayers layers{radiance, transmittance, leaving};
          sink(y, x, {&layers, 1});
        }
      progress.advance();
    }
  });
  progress.throw_if_cancelled();
  return nlohmann::json::object();
}

}  // namespace

Image render_network(const Scene& scene, const ParticleField& field, const NetworkSolution& solution, const RenderOptions& options,
                     NetworkRender render) {
  return render_network(scene, field, solution, options, View{scene.camera}, render).radiance;
}

RenderResult render_network(const Scene& scene, const ParticleField& field, const NetworkSolution& solution, const RenderOptions& options,
                            const View& view, NetworkRender render) {
  RenderResult result = RenderResult::for_view(view);
  result.stats = render_into(scene, field, solution, options, view, render, [&](int y, int x0, std::span<const PixelLayers> run) {
    for (size_t i = 0; i < run.size(); ++i) result.set(x0 + static_cast<int>(i), y, run[i]);
  });
  return result;
}

namespace {

// Prepared: the particle set, its field and the networks with the converged I.
class NetworkMethodSolution final : public MethodSolution {
 public:
  NetworkMethodSolution(const Scene& scene, ParticleSet set, int neighbours, const NetworkSettings& settings, NetworkRender render,
                        int warm_iterations, const Emission& emission)
      : scene_(scene), neighbours_(neighbours), settings_(settings), render_(render), warm_iterations_(warm_iterations) {
    set_ = std::make_unique<ParticleSet>(std::move(set));
    field_ = std::make_unique<ParticleField>(set_->view(), neighbours_);
    solution_ = solve_network(*field_, scene_.lights, settings_, nullptr, scene_.surfaces, emission);
    settings_.progress = nullptr;
    describe();
  }

  RenderResult render(const View& view, const RenderOptions& options) const override {
    const Stopwatch watch;
    const Scene seen = view_scene(scene_, view.camera);
    RenderResult result = render_network(seen, *field_, solution_, options, view, render_);
    result.stats["render_seconds"] = watch.seconds();
    return result;
  }
  bool renders_layers() const override { return true; }
  // The splat's pixels straight into the caller's layers.
  bool render_layers(const View& view, LayerSpans out, const RenderOptions& options) const override {
    if (render_ != NetworkRender::splat) return false;
    const Scene seen = view_scene(scene_, view.camera);
    const auto put = [](const ImageSpan& span, int x, int y, const Rgb& v) {
      float* p = span.pixel(x, y);
      p[0] = static_cast<float>(v.r), p[1] = static_cast<float>(v.g), p[2] = static_cast<float>(v.b);
    };
    render_into(seen, *field_, solution_, options, view, render_, [&](int y, int x0, std::span<const PixelLayers> run) {
      for (size_t i = 0; i < run.size(); ++i) {
        const int x = x0 + static_cast<int>(i);
        put(out.inscatter, x, y, run[i].inscatter), put(out.transmittance, x, y, run[i].transmittance);
        if (out.surface.data) put(out.surface, x, y, run[i].surface);
      }
    }, &out);
    return true;
  }

  // Moved particles (a new particle medium of the same count) and new lights: update_network,
  // which redoes only what the moved particles and lights reach, then iterates from the previous
  // I. Anything else (new surfaces included) prepares again.
  std::optional<UpdateReport> update(const Scene& scene, const SceneChange& change, const RenderOptions& options) override {
    if (change.region || change.surfaces) return std::nullopt;
    std::unique_ptr<ParticleSet> set;
    std::unique_ptr<ParticleField> field;
    if (change.medium) {
      const auto* f = std::get_if<FieldDensity>(&change.medium->density);
      const auto* moved = f ? dynamic_cast<const ParticleDensity*>(f->field.get()) : nullptr;
      if (!moved || moved->set().positions.size() != set_->positions.size()) return std::nullopt;
      set = std::make_unique<ParticleSet>(moved->set());
      field = std::make_unique<ParticleField>(set->view(), neighbours_);
      solution_.emission = change.medium->emission;
    }
    UpdateReport report;
    if (change.lights || change.medium) {
      NetworkSettings settings = settings_;
      if (warm_iterations_ > 0) settings.max_iterations = warm_iterations_;  // the paper's frame: one iteration each
      settings.threads = options.threads;
      settings.progress = options.progress;
      solution_ = update_network(std::move(solution_), field ? *field : *field_, scene.lights, settings);
      if (field) set_ = std::move(set), field_ = std::move(field);
      const auto& u = solution_.update;
      if (u.rebuilt) report.redone.push_back("networks rebuilt: " + u.reason);
      else report.redone.push_back("light depth maps: " + to_text(u.maps) + " rebuilt; direct light of " + to_text(u.direct) + " particles");
      report.redone.push_back("I: " + to_text(solution_.iterations) + " iterations from the previous solution");
      describe();
      report.stats = stats;
    }
    scene_ = scene;
    return report;
  }

 private:
  void describe() {
    stats = {{"particles", field_->size()},
             {"directions", settings_.directions},
             {"window", solution_.visibility.window.size},
             {"terms", solution_.terms},
             {"channels", solution_.channels},
             {"iterations", solution_.iterations},
             {"converged", solution_.converged},
             {"final_change", solution_.changes.empty() ? 0.0 : solution_.changes.back()},
             {"build_seconds", solution_.build_seconds},
             {"direct_seconds", solution_.direct_seconds},
             {"iterate_seconds", solution_.iterate_seconds}};
    // No silent failure at strong peaks: the D directions' quadrature of the phase function (the
    // phase matrix's raw row sums, 1 for a lobe they resolve; the rows are then rescaled to 1).
    const Eigen::VectorXd& sums = solution_.matrix->raw_row_sums();
    const double lo = sums.minCoeff(), hi = sums.maxCoeff();
    stats["phase_row_sums"] = {lo, hi};
    stats["warnings"] = nlohmann::json::array();
    if (lo < kRowSumRange[0] || hi > kRowSumRange[1])
      stats["warnings"].push_back("network: the phase function's peak is too narrow for " + to_text(settings_.directions) +
                                  " directions (their quadrature of it gives " + to_text(lo) + " to " + to_text(hi) +
                                  " instead of 1): errors of 10% and more are likely (docs/NETWORKS.md); use more directions or the reference");
  }

  Scene scene_;
  int neighbours_;
  std::unique_ptr<ParticleSet> set_;
  std::unique_ptr<ParticleField> field_;  // views *set_
  NetworkSettings settings_;
  NetworkRender render_;
  int warm_iterations_;
  NetworkSolution solution_;
};

class NetworkMethod final : public Method {
 public:
  std::unique_ptr<MethodSolution> prepare(const Scene& scene, const RenderOptions& options) const override {
    Settings settings(options.settings, kNetworkName);
    NetworkSettings network;
    network.directions = static_cast<int>(settings.integer("directions"));
    network.window = static_cast<int>(settings.integer("window"));
    network.max_iterations = static_cast<int>(settings.integer("iterations"));
    network.tolerance = settings.number("tolerance");
    network.terms = static_cast<int>(settings.integer("terms"));
    if (network.terms > network.directions)
      throw Error("method.terms", to_text(network.terms), "at most method.directions (" + to_text(network.directions) + ")");
    const int neighbours = static_cast<int>(settings.integer("neighbours"));
    const NetworkRender render = settings.choice("render") == "march" ? NetworkRender::march : NetworkRender::splat;
    const int warm_iterations = static_cast<int>(settings.integer("warm_iterations"));
    network.threads = options.threads;
    network.max_memory = options.max_memory;
    settings.reject_unknown();
    const auto* field = scene.medium ? std::get_if<FieldDensity>(&scene.medium->density) : nullptr;
    const auto* particles = field ? dynamic_cast<const ParticleDensity*>(field->field.get()) : nullptr;
    if (!particles)
      throw Error("particles", scene.medium ? "a `medium` instead" : "missing", "a particles block: method network renders particle sets only");
    network.progress = options.progress;
    return std::make_unique<NetworkMethodSolution>(scene, particles->set(), neighbours, network, render, warm_iterations, scene.medium->emission);
  }
};

}  // namespace

MethodInfo network_info() {
  MethodInfo info;
  info.name = kNetworkName;
  info.summary = "multiple scattering in particle media: visibility and illumination networks (seed 001)";
  info.create = [] { return std::make_unique<NetworkMethod>(); };
  info.emission = true;  // where the particles are: each one's L_e / (sigma_t rho) in the iteration and the camera's march
  info.handles = {"particles (a Gaussian each)", "point, spot, directional, sky", "planes, spheres and meshes lit through the particles and by their scattered light, with shadows (also in the particles' direct light)", true};
  const NetworkSettings n;
  info.settings = {SettingInfo::integer("directions", n.directions, 8, 4096, "D, the network's directions"),
                   SettingInfo::integer("window", 0, 0, 65536, "projection window in texels (0: from the particles' sizes)"),
                   SettingInfo::integer("iterations", n.max_iterations, 0, 100000, "network iterations at most (0: single scattering)"),
                   SettingInfo::number("tolerance", n.tolerance, 1e-9, 1.0, "stop when an iteration changes I by less (relative L2)"),
                   SettingInfo::integer("terms", 0, 0, 4096, "eigenpairs of the phase matrix (0: those with |lambda| >= 0.01; D: full)"),
                   SettingInfo::integer("neighbours", 8, 1, 64, "k of the k-th neighbour that sizes particles without diameters"),
                   SettingInfo::integer("warm_iterations", 0, 0, 100000, "iterations per update from the previous I (0: to the tolerance; 1: the paper's one a frame)"),
                   SettingInfo::choice("render", "splat", {"splat", "march"}, "camera rays: the particles splatted front to back (the paper's), or the exact march through their Gaussians")};
  for (int directions : {32, 64, 128}) info.trade_sweep.push_back({{"directions", directions}});
  // Trade suite, particle_cloud: 5.5% at any D in 0.45 s.
  info.offer = [](const SceneFeatures& f, double tolerance) {
    if (f.density != "particles") return AutoOffer{false, {}, 0.0, "needs particles"};
    static const MeasuredOffer measured[] = {{0.06, {{"directions", 64}}, 0.45, "measured at 5.5% on the suite's particle cloud"}};
    return offer_from(measured, tolerance, "particles", "measured at 5.5% on the suite's particle cloud");
  };
  return info;
}

}  // namespace haze::particles
