// Method "quadrature": single scattering by deterministic numerical quadrature, for any Medium.
// L = integral_{t0}^{t1} T(o, x) [L_e(x) + sigma_s(x) sum_lights p(wi . wo) E_light(x) T(x, light)] dt
//     + T(o, t1) L_surface_or_escape,
// with Gauss-Legendre panels along the view ray (graded geometrically toward each point light's
// closest approach, where the integrand peaks), sky in-scattering over a Fibonacci DirectionSet, and surface direct
// lighting with shadows. Slow and simple on purpose: it checks the fast single-scattering methods.
#include <haze/reference/methods.h>
#include <haze/core/surface.h>

#include <haze/core/directions.h>
#include <haze/core/error.h>
#include <haze/core/stopwatch.h>

#include <algorithm>

namespace haze::reference {

// The method's name, written once: the registry, its settings and its errors read it here.
constexpr const char* kQuadratureName = "quadrature";

namespace {

constexpr int kNodesPerPanel = 8;

struct Context {
  const Scene& scene;
  std::unique_ptr<Medium> medium;
  Rgb sky{0.0};
  DirectionSet sky_directions;
  int steps;

  bool occluded(const Vec3& x, const Vec3& dir, double distance) const { return haze::occluded(scene.surfaces, x, dir, distance); }

  Rgb transmittance(const Vec3& x, const Vec3& dir, double distance) const {
    return medium ? medium->transmittance_along(x, dir, distance) : Rgb(1.0);
  }

  // Light arriving at x that scatters toward the camera: sum over lights of p(wi . wo) E T.
  Rgb in_scattered(const Vec3& x, const Vec3& wo) const {
    const PhaseFunction& phase = medium->phase();
    Rgb sum(0.0);
    LightArrival a;
    for (const auto& light : scene.lights) {
      if (!arrival(light, x, a) || a.irradiance == Rgb(0.0) || occluded(x, a.to_light, a.distance)) continue;
      sum += phase.eval(-a.to_light, wo) * a.irradiance * transmittance(x, a.to_light, a.distance);
    }
    if (sky != Rgb(0.0)) {
      for (int j = 0; j < sky_directions.size(); ++j) {
        const Vec3& wi = sky_directions[j];
        if (occluded(x, -wi, kInfinity)) continue;
        sum += sky_directions.weight(j) * phase.eval(wi, wo) * sky * transmittance(x, -wi, kInfinity);
      }
    }
    return sum;
  }

  Rgb surface_radiance(const Surface& s, const Vec3& p, const Vec3& n, const Vec3& to_viewer) const {
    Vec3 origin = p + n * kSurfaceOffset;
    Rgb sum(0.0);
    LightArrival a;
    for (const auto& light : scene.lights) {
      if (!arrival(light, origin, a)) continue;
      double cos_i = glm::dot(n, a.to_light);
      if (cos_i <= 0.0 || occluded(origin, a.to_light, a.distance)) continue;
      sum += s.brdf(a.to_light, to_viewer, n) * a.irradiance * cos_i * transmittance(origin, a.to_light, a.distance);
    }
    if (sky != Rgb(0.0)) {
      for (int j = 0; j < sky_directions.size(); ++j) {
        Vec3 to_sky = -sky_directions[j];
        double cos_i = glm::dot(n, to_sky);
        if (cos_i <= 0.0 || occluded(origin, to_sky, kInfinity)) continue;
        sum += sky_directions.weight(j) * s.brdf(to_sky, to_viewer, n) * sky * cos_i * transmittance(origin, to_sky, kInfinity);
      }
    }
    return sum;
  }

  // The pixel's layers along `ray` up to Haze's nearest surface or `t_max` (a host's depth).
  PixelLayers pixel(const Ray& ray, double t_max, const std::vector<double>& gl_nodes, const std::vector<double>& gl_weights) const {
    double t_hit;
    Vec3 normal(0.0);
    const Surface* hit = nearest_surface(scene.surfaces, ray, t_max, t_hit, normal);
    Rgb radiance(0.0), view_t(1.0);
    double t0 = 0.0, t1 = t_hit;
    if (medium && medium->bounds().clip(ray, t0, t1) && t1 > t0) {
      if (!std::isfinite(t1)) {
        // Unbounded homogeneous medium: stop where the view transmittance falls below e^-30.
        double sigma_min = kInfinity;
        for (int c = 0; c < 3; ++c)
          if (medium->sigma_t_scale()[c] > 0.0) sigma_min = std::min(sigma_min, medium->sigma_t_scale()[c]);
        double rho = medium->max_density(medium->bounds());
        t1 = (rho > 0.0 && std::isfinite(sigma_min)) ? t0 + 30.0 / (sigma_min * rho) : t0;
      }
      // Panel edges: uniform, plus edges graded geometrically (h 2^k) away from each point or spot
      // light's closest approach, where the integrand peaks with width h, plus cone crossings.
      std::vector<double> edges;
      const int uniform_panels = std::max(1, steps / kNodesPerPanel);
      for (int i = 0; i <= uniform_panels; ++i) edges.push_back(t0 + (t1 - t0) * i / uniform_panels);
      for (const auto& light : scene.lights) {
        const Vec3* p = std::get_if<PointLight>(&light) ? &std::get<PointLight>(light).position
                        : std::get_if<SpotLight>(&light) ? &std::get<SpotLight>(light).position : nullptr;
        if (!p) continue;
        double tc = glm::dot(*p - ray.origin, ray.direction);
        double h = std::max(glm::length(*p - ray.at(tc)), 1e-9 * (t1 - t0));
        if (tc > t0 && tc < t1) edges.push_back(tc);
        for (double d = h / 8.0; d < t1 - t0; d *= 2.0) {
          if (tc - d > t0 && tc - d < t1) edges.push_back(tc - d);
          if (tc + d > t0 && tc + d < t1) edges.push_back(tc + d);
        }
        // A spot light's cone boundary is a jump in the integrand: make it a panel edge.
        if (auto* spot = std::get_if<SpotLight>(&light))
          for (double t : cone_crossings(*spot, ray, t1))
            if (t > t0) edges.push_back(t);
      }
      std::sort(edges.begin(), edges.end());
      const Vec3 wo = -ray.direction;
      Vec3 previous = ray.at(t0);
      for (size_t e = 0; e + 1 < edges.size(); ++e) {
        double a = edges[e], h = edges[e + 1] - a;
        if (!(h > 0.0)) continue;
        for (size_t q = 0; q < gl_nodes.size(); ++q) {
          Vec3 x = ray.at(a + h * (0.5 + 0.5 * gl_nodes[q]));
          view_t *= glm::exp(-medium->sigma_t_scale() * medium->density_integral(previous, x));
          previous = x;
          const Rgb sigma_s = medium->sigma_s(x);
          const Rgb emitted = medium->emits() ? medium->emission(x) : Rgb(0.0);  // L_e: the source's own term
          if (sigma_s == Rgb(0.0) && emitted == Rgb(0.0)) continue;
          radiance += 0.5 * h * gl_weights[q] * view_t * (emitted + (sigma_s == Rgb(0.0) ? Rgb(0.0) : sigma_s * in_scattered(x, wo)));
        }
      }
      view_t *= glm::exp(-medium->sigma_t_scale() * medium->density_integral(previous, ray.at(t1)));
    }
    PixelLayers layers{radiance, view_t, Rgb(0.0)};
    if (hit) layers.surface = surface_radiance(*hit, ray.at(t_hit), normal, -ray.direction);
    else if (std::isinf(t_hit)) layers.surface = scene.background + sky;
    return layers;
  }
};

// Prepared: the medium and the sky's directions; each view is integrated from scratch.
class QuadratureSolution final : public MethodSolution {
 public:
  QuadratureSolution(const Scene& scene, int steps, int sky_count)
      : scene_(scene), ctx_{scene_, scene.medium ? make_medium(*scene.medium) : nullptr, Rgb(0.0), DirectionSet::fibonacci(sky_count), steps} {
    for (const auto& light : scene_.lights)
      if (auto* sky = std::get_if<SkyLight>(&light)) ctx_.sky += sky->radiance;
    gauss_legendre(kNodesPerPanel, nodes_, weights_);
    stats = {{"steps", steps}, {"sky_directions", sky_count}};
  }

  RenderResult render(const View& view, const RenderOptions& options) const override {
    const Stopwatch watch;
    const Camera& camera = view.camera;
    RenderResult result = RenderResult::for_view(view);
    ProgressTracker progress(options.progress, camera.height_px);
    parallel_for(camera.height_px, options.threads, 1, [&](long long y0, long long y1) {
      for (auto y = static_cast<int>(y0); y < y1 && !progress.cancelled(); ++y) {
        for (int x = 0; x < camera.width_px; ++x) result.set(x, y, ctx_.pixel(camera.pixel_ray(x, y), view.max_distance(x, y), nodes_, weights_));
        progress.advance();
      }
    });
    progress.throw_if_cancelled();
    result.stats = {{"seconds", watch.seconds()}};
    return result;
  }
  bool renders_layers() const override { return true; }

 private:
  const Scene scene_;
  Context ctx_;  // reads scene_
  std::vector<double> nodes_, weights_;
};

class QuadratureMethod final : public Method {
 public:
  std::unique_ptr<MethodSolution> prepare(const Scene& scene, const RenderOptions& options) const override {
    Settings settings(options.settings, kQuadratureName);
    const int steps = static_cast<int>(settings.integer("steps"));
    const int sky_count = static_cast<int>(settings.integer("sky_directions"));
    settings.reject_unknown();
    return std::make_unique<QuadratureSolution>(scene, steps, sky_count);
  }
};

}  // namespace

MethodInfo quadrature_info() {
  MethodInfo info;
  info.name = kQuadratureName;
  info.summary = "single scattering by deterministic numerical quadrature (any medium; a yardstick, not fast)";
  info.create = [] { return std::make_unique<QuadratureMethod>(); };
  info.handles = {"any: constant, RBF and grid densities, the particles' density", "point, spot, directional, sky",
                  "planes, spheres and meshes lit by unscattered light, with shadows", false};
  info.settings = {SettingInfo::integer("steps", 512, kNodesPerPanel, 1 << 20, "quadrature nodes along each view ray"),
                   SettingInfo::integer("sky_directions", 256, 1, 1 << 16, "directions the sky's light is integrated over")};
  for (int steps : {32, 64, 128, 256}) info.trade_sweep.push_back({{"steps", steps}, {"sky_directions", 64}});
  // Trade suite, thin_haze: 128 steps in 0.056 s; slower than analytic and propagation, so it is
  // chosen where they decline (a sky light).
  info.offer = [](const SceneFeatures& f, double tolerance) {
    if (!single_scattering_suffices(f, tolerance)) return AutoOffer{false, {}, 0.0, "multiple scattering matters"};
    return AutoOffer{true, {{"steps", 128}}, 0.06, "single scattering of any medium and light (thin_haze: 0.056 s at 128 steps)"};
  };
  info.single_scattering = true;
  info.emission = true;
  return info;
}

}  // namespace haze::reference
