// Method "reference": an unbiased volumetric path tracer for the full radiative transfer equation
// (docs/REFERENCE.md). Free flights by spectral delta tracking against a coarse majorant grid
// (Kutz et al. 2017; pbrt-v4's DDA majorants), next-event estimation to point, spot and
// directional lights and the sky with ratio-tracked transmittance (exact for homogeneous media),
// phase-function importance sampling, Russian roulette; planes, spheres and meshes block and reflect.
#include <haze/reference/methods.h>
#include <haze/core/surface.h>

#include <haze/core/error.h>
#include <haze/core/majorant.h>
#include <haze/core/stopwatch.h>
#include <haze/core/image.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

namespace haze::reference {

// The method's name, written once: the registry, its settings and its errors read it here.
constexpr const char* kReferenceName = "reference";

namespace {

constexpr long long kSamplesPerBlock = 1024;  // a work item: one pixel's samples in blocks of this size
constexpr int kRouletteDepth = 4;
// With target_noise: the first round's spp (at fewer samples the noise estimate misses the heavy
// tails; docs/REFERENCE.md) and the default cap.
constexpr long long kFirstRound = 1024;
// Tentative collisions one path may take, its shadow rays' included: about a tenth of a second.
// Past it the tracking would take hours (channels of sigma_t far apart make nearly every collision
// of the thin channels a null one: [1e6, 2.5, 2.9] took a million per unit length), so it stops
// with an error.
constexpr long long kMaxTentative = 1'000'000;

thread_local long long path_tentative = 0;  // the current path's, on this thread

[[noreturn]] void too_many_collisions(const Rgb& sigma_t) {
  throw Error("medium.sigma_t", "[" + to_text(sigma_t.r) + ", " + to_text(sigma_t.g) + ", " + to_text(sigma_t.b) + "]",
              "extinction the reference can track: a path passed 1e6 tentative collisions (channels far apart, or a dense "
              "medium around thin parts, make nearly all of them null; render such channels as separate grey scenes)");
}
constexpr long long kProgressiveCap = 1LL << 20;

double mean3(const Rgb& c) { return (c.r + c.g + c.b) / 3.0; }
double max3(const Rgb& c) { return std::max({c.r, c.g, c.b}); }

// Cosine-weighted direction around n.
Vec3 sample_cosine(const Vec3& n, Rng& rng) {
  double u1 = rng.uniform(), u2 = rng.uniform();
  double r = std::sqrt(u1), phi = 2.0 * kPi * u2;
  return Frame::from_z(n).to_world(Vec3(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u1))));
}

// exp(-sigma * length) per channel, one exp when the channels agree (grey media).
Rgb beer(const Rgb& sigma, double length) {
  if (is_grey(sigma)) return Rgb(std::exp(-sigma.r * length));
  return glm::exp(-sigma * length);
}

struct Tracer {
  const Scene& scene;
  const Medium* medium;
  const MajorantGrid* majorants = nullptr;  // the medium's
  double sigma_max = 0.0;  // largest channel of the medium's sigma_t scale
  Rgb sky{0.0};
  int max_scattering = -1;  // medium scattering events per path; -1 unlimited
  int max_bounces = -1;     // surface reflections per path; -1 unlimited
  bool local_lights = false;  // any point or spot light (equiangular sampling has work to do)
  bool view_scattering = true;  // false: the camera ray to the first surface does not scatter
  // Homogeneous media skip the majorant walk and density lookups: sigma_t is constant in bounds.
  bool homogeneous = false;
  Aabb bounds;
  Rgb sigma_t_homogeneous{0.0};
  bool emits = false;        // the medium's emission (Medium::emission)
  // Tentative collisions per unit length at least where emission may reach past the extinction (a
  // grid of its own, blackbody, sigma_t 0): 4 per feature size, so such stretches are sampled too.
  double emission_rate = 0.0;

  // Transmittance from x along dir over distance (infinite for directional lights and the sky).
  Rgb transmittance(const Vec3& x, const Vec3& dir, double distance, Rng& rng) const {
    if (occluded(scene.surfaces, x, dir, distance)) return Rgb(0.0);
    if (!medium) return Rgb(1.0);
    if (homogeneous) {
      double t0 = 0.0, t1 = distance;
      if (!bounds.clip({x, dir}, t0, t1) || !(t1 > t0)) return Rgb(1.0);
      return std::isfinite(t1) ? beer(sigma_t_homogeneous, t1 - t0) : medium->transmittance_along(x, dir, distance);
    }
    // Ratio tracking: T = prod (1 - sigma_t / sigma_maj) over tentative collisions.
    Ray ray{x, dir};
    Rgb T(1.0);
    auto walk = majorants->walk(ray, 0.0, distance);
    MajorantSegment seg;
    while (walk.next(seg)) {
      if (seg.density <= 0.0) continue;
      const double sigma_bar = seg.density * sigma_max;
      for (double s = seg.t0;;) {
        s -= std::log1p(-rng.uniform()) / sigma_bar;
        if (s >= seg.t1) break;
        if (++path_tentative > kMaxTentative) too_many_collisions(medium->sigma_t_scale());
        T *= Rgb(1.0) - medium->sigma_t(ray.at(s)) / sigma_bar;
        // Russian roulette on small transmittance keeps the estimate unbiased and the walk short.
        if (max3(T) < 0.05) {
          if (rng.uniform() < 0.5) return Rgb(0.0);
          T *= 2.0;
        }
      }
    }
    return T;
  }

  // Light scattered at x toward -d, per unit sigma_s: sum over lights p E T, plus the sky.
  // Point and spot lights: their single-scattered light along a whole ray is estimated by
  // equiangular sampling (Kulla and Fajardo 2012) instead of at delta-tracking vertices, where the
  // 1/d^2 peak near a light would make the estimate heavy-tailed.
  static bool is_local(const Light& light) {
    return std::holds_alternative<PointLight>(light) || std::holds_alternative<SpotLight>(light);
  }

  // sum over point and spot lights of integral_{0}^{t_end} T(o, x) sigma_s(x) p E(x) T(x, light) dx,
  // one equiangular sample per light: x = tc + h tan(theta), theta uniform, pdf h / (dtheta r^2).
  Rgb equiangular_direct(const Ray& ray, double t_end, Rng& rng) const {
    double t0 = 0.0, t1 = t_end;
    if (!medium || !bounds.clip(ray, t0, t1) || !(t1 > t0)) return Rgb(0.0);
    const PhaseFunction& phase = medium->phase();
    Rgb sum(0.0);
    LightArrival a;
    for (const auto& light : scene.lights) {
      if (!is_local(light)) continue;
      const Vec3& position = std::holds_alternative<PointLight>(light) ? std::get<PointLight>(light).position
                                                                       : std::get<SpotLight>(light).position;
      double tc = glm::dot(position - ray.origin, ray.direction);
      double h = std::max(glm::length(position - ray.at(tc)), 1e-12);
      double theta_a = std::atan((t0 - tc) / h);
      double theta_b = std::isfinite(t1) ? std::atan((t1 - tc) / h) : 0.5 * kPi;
      double theta = theta_a + rng.uniform() * (theta_b - theta_a);
      double x = tc + h * std::tan(theta);
      if (!(x > t0 && x < t1)) continue;
      double pdf = h / ((theta_b - theta_a) * (h * h + (x - tc) * (x - tc)));
      Vec3 p = ray.at(x);
      Rgb sigma_s = medium->sigma_s(p);
      if (sigma_s == Rgb(0.0) || !arrival(light, p, a) || a.irradiance == Rgb(0.0)) continue;
      Rgb view = transmittance(ray.origin, ray.direction, x, rng);
      sum += view * sigma_s * phase.eval(a.to_light, ray.direction) * a.irradiance *
             transmittance(p, a.to_light, a.distance, rng) / pdf;
    }
    return sum;
  }

  // Directional lights and the sky at a delta-tracking vertex (point and spot lights: above).
  Rgb volume_nee(const Vec3& x, const Vec3& d, Rng& rng) const {
    const PhaseFunction& phase = medium->phase();
    Rgb sum(0.0);
    LightArrival a;
    for (const auto& light : scene.lights) {
      if (is_local(light) || !arrival(light, x, a) || a.irradiance == Rgb(0.0)) continue;
      sum += phase.eval(a.to_light, d) * a.irradiance * transmittance(x, a.to_light, a.distance, rng);
    }
    if (sky != Rgb(0.0)) {
      // Direction sampled by the phase function: p / pdf = 1.
      Vec3 w = phase.sample(d, rng).wo;
      sum += sky * transmittance(x, w, kInfinity, rng);
    }
    return sum;
  }

  Rgb surface_nee(const Surface& s, const Vec3& p, const Vec3& n, const Vec3& wo, Rng& rng) const {
    Rgb sum(0.0);
    LightArrival a;
    for (const auto& light : scene.lights) {
      if (!arrival(light, p, a) || a.irradiance == Rgb(0.0)) continue;
      double cos_i = glm::dot(n, a.to_light);
      if (cos_i <= 0.0) continue;
      sum += s.brdf(a.to_light, wo, n) * a.irradiance * cos_i * transmittance(p, a.to_light, a.distance, rng);
    }
    if (sky != Rgb(0.0)) {
      // Cosine-weighted: f cos / pdf = f pi.
      Vec3 w = sample_cosine(n, rng);
      sum += kPi * s.brdf(w, wo, n) * sky * transmittance(p, w, kInfinity, rng);
    }
    return sum;
  }

  // One path's radiance along the camera ray, which ends at t_end (a host's depth) if nothing
  // nearer does. With `surface_part`, also the share of it whose first event is the ray's end (a
  // surface or the background): T C of the layers; the rest is L_in.
  Rgb trace(Ray ray, Rng& rng, long long& events, double t_end = kInfinity, Rgb* surface_part = nullptr) const {
    Rgb L(0.0), beta(1.0);
    Rgb inscatter(-1.0);  // once the first event is the ray's end: L up to then
    auto done = [&] {
      if (surface_part) *surface_part = inscatter.r < 0.0 ? Rgb(0.0) : L - inscatter;
      return L;
    };
    int volume_events = 0, bounces = 0;  // medium scattering events and surface reflections so far
    path_tentative = 0;
    for (int depth = 0;; ++depth) {
      Vec3 normal;
      double t_surface;
      const Surface* surface = nearest_surface(scene.surfaces, ray, depth == 0 ? t_end : kInfinity, t_surface, normal);

      // Spectral delta tracking (Kutz et al. 2017, history-aware): tentative collisions at rate
      // sigma_bar = density majorant times the largest channel; scatter, null or absorb with
      // probabilities mean(beta sigma_x) / (sigma_bar mean(beta)), and weights that keep
      // mean(beta) unchanged. For a grey medium this is plain delta tracking with weight 1.
      bool scattered = false;
      Vec3 x(0.0);
      // view_scattering 0: the camera ray only attenuates, so the image is the surfaces' radiance
      // seen through the medium (what the analytic model's surface terms compute).
      const bool may_scatter = view_scattering || depth > 0;
      if (!may_scatter) beta *= transmittance(ray.origin, ray.direction, t_surface, rng);
      if (may_scatter && local_lights && (max_scattering < 0 || volume_events < max_scattering))
        L += beta * equiangular_direct(ray, t_surface, rng);
      if (medium && may_scatter) {
        auto walk = majorants->walk(ray, 0.0, t_surface);
        MajorantSegment seg;
        while (!scattered && walk.next(seg)) {
          if (seg.density <= 0.0 && emission_rate <= 0.0) continue;
          const double sigma_bar = std::max(seg.density * sigma_max, emission_rate);
          for (double s = seg.t0;;) {
            s -= std::log1p(-rng.uniform()) / sigma_bar;
            if (s >= seg.t1) break;
            if (++path_tentative > kMaxTentative) too_many_collisions(medium->sigma_t_scale());
            x = ray.at(s);
            // Emission's collision estimator over every tentative collision (pbrt-v4's volpath):
            // E[sum beta L_e / sigma_bar] = integral T L_e ds.
            if (emits) L += beta * medium->emission(x) / sigma_bar;
            Rgb sigma_t = homogeneous ? sigma_t_homogeneous : medium->sigma_t(x);
            Rgb sigma_s = medium->albedo() * sigma_t;
            Rgb sigma_n = Rgb(sigma_bar) - sigma_t;
            double norm = sigma_bar * mean3(beta);
            double p_s = mean3(beta * sigma_s) / norm, p_n = mean3(beta * sigma_n) / norm;
            double u = rng.uniform();
            if (u < p_s) {
              beta *= sigma_s / (sigma_bar * p_s);
              scattered = true;
              break;
            }
            if (u < p_s + p_n) {
              beta *= sigma_n / (sigma_bar * p_n);
              continue;
            }
            return done();  // absorbed
          }
        }
      }

      if (depth == 0 && !scattered) inscatter = L;
      if (!scattered && !surface) {
        if (depth == 0 && !std::isfinite(t_end)) L += beta * (scene.background + sky);
        return done();
      }
      // A real event: paths with more medium scatterings or surface reflections than allowed end
      // here; their light is not part of the requested orders.
      if (scattered) {
        if (max_scattering >= 0 && volume_events + 1 > max_scattering) return done();
        ++volume_events, ++events;
        L += beta * volume_nee(x, ray.direction, rng);
        if (volume_events == max_scattering && bounces == max_bounces) return done();
        ray = {x, medium->phase().sample(ray.direction, rng).wo};
      } else {
        if (max_bounces >= 0 && bounces + 1 > max_bounces) return done();
        ++bounces;
        Vec3 p = ray.at(t_surface) + normal * kSurfaceOffset, wo = -ray.direction;
        L += beta * surface_nee(*surface, p, normal, wo, rng);
        if (volume_events == max_scattering && bounces == max_bounces) return done();
        Vec3 w = sample_cosine(normal, rng);
        beta *= kPi * surface->brdf(w, wo, normal);
        ray = {p, w};
      }
      if (depth + 1 >= kRouletteDepth) {
        double q = std::min(0.95, max3(beta));
        if (!(q > 0.0) || rng.uniform() >= q) return done();
        beta /= q;
      }
    }
  }
};

// Per pixel: the sum and the sum of squares of its samples, and the sum of their surface parts
// (Tracer::trace) when the view asks for layers.
using Sums = std::vector<std::array<Rgb, 3>>;

// Adds `spp` samples per pixel drawn with `seed` to `sums`; returns the scattering events. Work
// items (pixel, block of kSamplesPerBlock) are reduced in block order, so the sums do not depend
// on the thread count.
long long accumulate(const Tracer& tracer, const View& view, long long spp, std::uint64_t seed, int threads,
                     const ProgressCallback& callback, Sums& sums) {
  const long long pixels = static_cast<long long>(sums.size());
  const long long blocks = (spp + kSamplesPerBlock - 1) / kSamplesPerBlock;
  const Camera& camera = view.camera;
  Sums partial(static_cast<size_t>(pixels * blocks));
  std::vector<long long> events(static_cast<size_t>(pixels * blocks), 0);
  ProgressTracker progress(callback, pixels * blocks);
  parallel_for(pixels * blocks, threads, 1, [&](long long begin, long long end) {
    for (long long item = begin; item < end && !progress.cancelled(); ++item) {
      long long pixel = item / blocks, block = item % blocks;
      Rng rng(seed, static_cast<std::uint64_t>(item));
      const int x = static_cast<int>(pixel % camera.width_px), y = static_cast<int>(pixel / camera.width_px);
      const Ray ray = camera.pixel_ray(x, y);
      Rgb sum(0.0), sum2(0.0), surface_sum(0.0), surface_part;
      long long count = std::min(kSamplesPerBlock, spp - block * kSamplesPerBlock);
      for (long long s = 0; s < count; ++s) {
        Rgb v = tracer.trace(ray, rng, events[static_cast<size_t>(item)], view.max_distance(x, y), view.layers ? &surface_part : nullptr);
        sum += v, sum2 += v * v;
        if (view.layers) surface_sum += surface_part;
      }
      partial[static_cast<size_t>(item)] = {sum, sum2, surface_sum};
      progress.advance();
    }
  });
  progress.throw_if_cancelled();
  long long total_events = 0;
  for (long long pixel = 0; pixel < pixels; ++pixel)
    for (long long b = 0; b < blocks; ++b) {
      const auto& p = partial[static_cast<size_t>(pixel * blocks + b)];
      for (int k = 0; k < 3; ++k) sums[static_cast<size_t>(pixel)][k] += p[k];
      total_events += events[static_cast<size_t>(pixel * blocks + b)];
    }
  return total_events;
}

// The mean of n samples per pixel and its standard error, sqrt(sample variance / n); with layers,
// L_in and C from the mean surface part S and the exact transmittance T to the ray's end: C = S / T
// (0 where T is), L_in = mean - S, so that L_in + T C is the image.
void finish(const Sums& sums, long long spp, const std::vector<Rgb>& ends, RenderResult& result) {
  const int width = result.radiance.width();
  const double n = static_cast<double>(spp);
  for (size_t pixel = 0; pixel < sums.size(); ++pixel) {
    const Rgb mean = sums[pixel][0] / n;
    const Rgb variance = spp > 1 ? glm::max(Rgb(0.0), (sums[pixel][1] - n * mean * mean) / (n - 1.0)) : Rgb(0.0);
    const int px = static_cast<int>(pixel) % width, py = static_cast<int>(pixel) / width;
    result.radiance.set(px, py, mean);
    result.std_error->set(px, py, glm::sqrt(variance / n));
    if (!result.inscatter) continue;
    const Rgb S = sums[pixel][2] / n, T = ends[pixel];
    Rgb C(0.0);
    for (int k = 0; k < 3; ++k) C[k] = T[k] > 0.0 ? S[k] / T[k] : 0.0;
    result.inscatter->set(px, py, mean - S), result.transmittance->set(px, py, T), result.surface->set(px, py, C);
  }
}

struct ReferenceSettings {
  double target_noise = 0.0;
  long long spp = 1024;
  int max_scattering = -1, max_bounces = -1;
  bool view_scattering = true;
  std::uint64_t seed = 1;
};

// Prepared: the medium and its majorant grid; each view is traced from scratch.
class ReferenceSolution final : public MethodSolution {
 public:
  ReferenceSolution(const Scene& scene, const ReferenceSettings& s)
      : scene_(scene),
        settings_(s),
        medium_(scene.medium ? make_medium(*scene.medium) : nullptr),
        tracer_{scene_, medium_.get(), nullptr, 0.0, Rgb(0.0), s.max_scattering, s.max_bounces, false, s.view_scattering,
                false, Aabb{}, Rgb(0.0)} {
    const Stopwatch watch;
    if (medium_) {
      tracer_.majorants = &medium_->majorants();
      tracer_.sigma_max = max3(medium_->sigma_t_scale());
      tracer_.emits = medium_->emits();
      if (tracer_.emits && (medium_->emission_desc().beyond_density() || tracer_.sigma_max <= 0.0))
        tracer_.emission_rate = 4.0 / medium_->feature_size();
      tracer_.homogeneous = medium_->homogeneous();
      tracer_.bounds = medium_->bounds();
      if (tracer_.homogeneous) tracer_.sigma_t_homogeneous = medium_->sigma_t_scale() * medium_->max_density(tracer_.bounds);
    }
    for (const auto& light : scene_.lights) {
      if (auto* sky = std::get_if<SkyLight>(&light)) tracer_.sky += sky->radiance;
      tracer_.local_lights |= Tracer::is_local(light);
    }
    stats["prepare_seconds"] = watch.seconds();
  }

  RenderResult render(const View& view, const RenderOptions& options) const override {
    const Stopwatch watch;
    const ReferenceSettings& s = settings_;
    const Camera& camera = view.camera;
    RenderResult result = RenderResult::for_view(view);
    result.std_error = Image(camera.width_px, camera.height_px);
    std::vector<Rgb> ends;  // with layers: each pixel ray's transmittance to its end
    if (view.layers) {
      ends.assign(static_cast<size_t>(camera.width_px) * camera.height_px, Rgb(1.0));
      parallel_for(static_cast<long long>(ends.size()), options.threads, 64, [&](long long begin, long long end) {
        for (long long pixel = begin; pixel < end; ++pixel) {
          const int x = static_cast<int>(pixel % camera.width_px), y = static_cast<int>(pixel / camera.width_px);
          const Ray ray = camera.pixel_ray(x, y);
          double t;
          Vec3 n;
          nearest_surface(scene_.surfaces, ray, view.max_distance(x, y), t, n);
          if (medium_) ends[static_cast<size_t>(pixel)] = medium_->transmittance_along(ray.origin, ray.direction, t);
        }
      });
    }
    Sums sums(static_cast<size_t>(camera.width_px) * camera.height_px, {Rgb(0.0), Rgb(0.0), Rgb(0.0)});
    long long done = 0, planned = s.target_noise > 0.0 ? std::min(s.spp, kFirstRound) : s.spp, total_events = 0;
    double noise = 0.0;
    for (int round = 0;; ++round) {
      // Round r draws with its own seed, so the rounds' samples are independent.
      const std::uint64_t round_seed = s.seed + static_cast<std::uint64_t>(round) * 0x9E3779B97F4A7C15ULL;
      ProgressCallback callback;
      if (options.progress)
        callback = [&, from = done, to = planned](double f) { return options.progress((from + f * (to - from)) / to); };
      total_events += accumulate(tracer_, view, planned - done, round_seed, options.threads, callback, sums);
      done = planned;
      finish(sums, done, ends, result);
      if (!(s.target_noise > 0.0)) break;
      noise = lit_pixel_error(result.radiance, result.radiance, &*result.std_error).noise_rms;
      if (noise <= s.target_noise || done >= s.spp) break;
      // Noise falls as 1 / sqrt(spp); heavy tails make the estimate grow with spp, so a little
      // more, and at least a quarter more per round.
      const double wanted = 1.05 * static_cast<double>(done) * (noise / s.target_noise) * (noise / s.target_noise);
      const double next = std::clamp(wanted, 1.25 * static_cast<double>(done), 16.0 * static_cast<double>(done));
      planned = std::min(s.spp, static_cast<long long>(std::ceil(next / 64.0)) * 64);
    }
    const double seconds = watch.seconds();
    result.stats = {{"spp", done},
                    {"seed", s.seed},
                    {"max_scattering", s.max_scattering},
                    {"max_bounces", s.max_bounces},
                    {"samples", done * static_cast<long long>(sums.size())},
                    {"scattering_events", total_events},
                    {"events_per_second", static_cast<double>(total_events) / seconds},
                    {"seconds", seconds}};
    if (s.target_noise > 0.0) result.stats["target_noise"] = {{"target", s.target_noise}, {"noise", noise}, {"met", noise <= s.target_noise}};
    return result;
  }
  bool renders_layers() const override { return true; }

 private:
  const Scene scene_;
  const ReferenceSettings settings_;
  const std::unique_ptr<Medium> medium_;
  Tracer tracer_;  // reads scene_ and medium_
};

class ReferenceMethod final : public Method {
 public:
  std::unique_ptr<MethodSolution> prepare(const Scene& scene, const RenderOptions& options) const override {
    Settings settings(options.settings, kReferenceName);
    ReferenceSettings s;
    // With target_noise, samples are added in rounds until the image's own relative noise over
    // the lit pixels (lit_pixel_error's noise_rms) is at most target_noise; spp is then the cap.
    s.target_noise = settings.number("target_noise");
    s.spp = settings.integer("spp", s.target_noise > 0.0 ? kProgressiveCap : 1024);
    s.max_scattering = static_cast<int>(settings.integer("max_scattering"));
    s.max_bounces = static_cast<int>(settings.integer("max_bounces"));
    s.view_scattering = settings.integer("view_scattering") == 1;
    s.seed = static_cast<std::uint64_t>(settings.integer("seed"));
    settings.reject_unknown();
    return std::make_unique<ReferenceSolution>(scene, s);
  }
};

}  // namespace

MethodInfo reference_info() {
  MethodInfo info;
  info.name = kReferenceName;
  info.role = MethodInfo::Role::reference;
  info.summary = "unbiased volumetric path tracer with a standard-error image (the yardstick for every method)";
  info.create = [] { return std::make_unique<ReferenceMethod>(); };
  info.handles = {"any: constant, RBF and grid densities, the particles' density", "point, spot, directional, sky",
                  "planes, spheres and meshes: every light path", true};
  info.settings = {
      SettingInfo::number("target_noise", 0.0, 0.0, 0.99, "add samples until the image's own relative noise over the lit pixels is this (0: off)"),
      SettingInfo::integer("spp", nullptr, 1, 1LL << 32, "samples per pixel: 1024, or with target_noise the cap (2^20)"),
      SettingInfo::integer("max_scattering", -1, -1, 100000, "medium scattering events per path (-1: unlimited)"),
      SettingInfo::integer("max_bounces", -1, -1, 100000, "surface reflections per path (-1: unlimited)"),
      SettingInfo::integer("view_scattering", 1, 0, 1, "0: the camera ray to the first surface does not scatter"),
      SettingInfo::integer("seed", 1, 0, 1LL << 62, "the random streams' seed")};
  for (int spp : {16, 64, 256, 1024, 4096}) info.trade_sweep.push_back({{"spp", spp}, {"seed", 7}});
  info.emission = true;
  return info;
}

void register_methods() {
  register_method(reference_info());
  register_method(quadrature_info());
}

}  // namespace haze::reference
