// Method "auto" (haze/auto/auto.h): scene features, the rules that turn them into a method and settings,
// and the method that renders with the choice. The thresholds are the trade suite's measurements
// (docs/TRADEOFFS.md); each rule says which measurement it rests on.
#include <haze/auto/auto.h>

#include <haze/core/error.h>
#include <haze/core/medium.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace haze {

// The method's name, written once: the registry, its settings and its errors read it here.
constexpr const char* kAutoName = "auto";

namespace {

std::string format(const char* f, double a, double b = 0.0, double c = 0.0) {
  char s[256];
  std::snprintf(s, sizeof s, f, a, b, c);
  return s;
}

// The reference path tracer, adding samples until its own relative noise over the lit pixels is
// 0.75 T (the reference's target_noise; at least 1024 spp). On the trade suite the error of a
// reference render on other seeds reached 1.3x that noise estimate (heavy tails: fog_lamps at
// 8192 spp, 7.2% where it estimated 5.6%).
constexpr double kNoiseShare = 0.75;

AutoChoice reference_for(double tolerance, AutoChoice choice) {
  choice.method = method_with_role(MethodInfo::Role::reference);
  // Rounded to 6 decimals so the setting prints as written (0.0375, not 0.037500000000000006).
  choice.settings = {{"target_noise", std::round(kNoiseShare * tolerance * 1e6) / 1e6}, {"seed", 5}};
  choice.why.push_back(format("reference: adds samples until its own noise over the lit pixels is %.2f T (%.2f%%)", kNoiseShare,
                              100.0 * kNoiseShare * tolerance));
  return choice;
}

// The chosen method's solution, with the choice in the stats.
class AutoSolution final : public MethodSolution {
 public:
  explicit AutoSolution(Solution chosen) : chosen_(std::move(chosen)) {}
  RenderResult render(const View& view, const RenderOptions& options) const override {
    RenderOptions o;
    o.threads = options.threads;
    o.progress = options.progress;
    RenderResult result = chosen_.render(view, o);
    result.stats = {{"method_stats", std::move(result.stats)}};
    return result;
  }
  std::optional<UpdateReport> update(const Scene&, const SceneChange& change, const RenderOptions& options) override {
    RenderOptions o;
    o.threads = options.threads;
    o.progress = options.progress;
    return chosen_.update(change, o);
  }
  bool renders_layers() const override { return chosen_.method_solution().renders_layers(); }
  bool render_distances(const View& view, std::span<const double> distances, const RenderOptions& options, DistanceLayers out) const override {
    return chosen_.method_solution().render_distances(view, distances, options, out);
  }
  bool render_layers(const View& view, LayerSpans out, const RenderOptions& options) const override {
    return chosen_.method_solution().render_layers(view, out, options);
  }
  void add_glow(const View& view, double glow_angle, ImageSpan out, const RenderOptions& options) const override {
    chosen_.method_solution().add_glow(view, glow_angle, out, options);
  }
  Rgb transmittance(size_t light, const Vec3& x) const override { return chosen_.transmittance(light, x); }
  Rgb fluence(const Vec3& x) const override { return chosen_.fluence(x); }
  Rgb inscattered(const Vec3& x, const Vec3& w) const override { return chosen_.inscattered(x, w); }
  const MethodSolution& fields_owner() const override { return chosen_.method_solution(); }

 private:
  Solution chosen_;
};

class AutoMethod final : public Method {
 public:
  std::unique_ptr<MethodSolution> prepare(const Scene& scene, const RenderOptions& options) const override {
    Settings settings(options.settings, kAutoName);
    const double tolerance = settings.number("tolerance");
    settings.reject_unknown();
    const AutoChoice choice = choose_method(scene, tolerance);
    RenderOptions delegated = options;
    delegated.settings = choice.settings;
    auto solution = std::make_unique<AutoSolution>(haze::prepare(scene, choice.method, delegated));
    solution->stats = {{kAutoName, {{"tolerance", tolerance}, {"method", choice.method}, {"settings", choice.settings}, {"why", choice.why}}}};
    return solution;
  }
};

}  // namespace

SceneFeatures scene_features(const Scene& scene) {
  SceneFeatures f;
  f.surfaces = !scene.surfaces.empty();
  for (const Light& l : scene.lights) {
    f.sky = f.sky || std::holds_alternative<SkyLight>(l);
    f.directional = f.directional || std::holds_alternative<DirectionalLight>(l);
  }
  if (!scene.medium) return f;
  const MediumDesc& desc = *scene.medium;
  f.homogeneous = std::holds_alternative<ConstantDensity>(desc.density);
  f.density = std::visit(
      [](const auto& d) -> std::string {
        using D = std::decay_t<decltype(d)>;
        if constexpr (std::is_same_v<D, ConstantDensity>) return "constant";
        else if constexpr (std::is_same_v<D, RbfDensity>) return "rbf";
        else if constexpr (std::is_same_v<D, GridDensity>) return "grid";
        else return d.type;
      },
      desc.density);
  if (field_density(f)) return f;
  const auto medium = make_medium(desc);
  Aabb box = medium->bounds();
  f.bounded = box.bounded();
  if (!f.bounded) {
    // An unbounded medium: the box around the camera and the lights that have a position.
    box = {scene.camera.position, scene.camera.position};
    for (const Light& l : scene.lights) {
      Vec3 p;
      if (const auto* point = std::get_if<PointLight>(&l)) p = point->position;
      else if (const auto* spot = std::get_if<SpotLight>(&l)) p = spot->position;
      else continue;
      box.lo = glm::min(box.lo, p), box.hi = glm::max(box.hi, p);
    }
  }
  const Vec3 centre = 0.5 * (box.lo + box.hi);
  double integral = 0.0;
  for (int a = 0; a < 3; ++a) {
    Vec3 from = centre, to = centre;
    from[a] = box.lo[a], to[a] = box.hi[a];
    integral = std::max(integral, medium->density_integral(from, to));
  }
  const Rgb& s = desc.sigma_t;
  f.optical_diameter = integral * std::max({s.r, s.g, s.b});
  f.albedo = std::max({desc.albedo.r, desc.albedo.g, desc.albedo.b});
  f.multiple_share = f.albedo * (1.0 - std::exp(-0.5 * f.optical_diameter));
  return f;
}

namespace {

// The cheapest registered method's offer (MethodInfo::offer), else the reference.
AutoChoice choose(const Scene& scene, double tolerance) {
  const SceneFeatures f = scene_features(scene);
  if (!scene.medium) throw Error("medium", "missing", "a medium (or particles) for method auto");
  AutoChoice c;
  c.why.push_back(format("tolerance %.1f%%", 100.0 * tolerance));
  if (field_density(f)) c.why.push_back("density from the " + f.density + " module: no optical diameter estimated");
  else
    c.why.push_back(format("optical diameter %.2f, albedo %.2f: estimated multiple-scattering share %.0f%%", f.optical_diameter, f.albedo,
                           100.0 * f.multiple_share));
  std::vector<std::pair<std::string, AutoOffer>> offers;
  const bool emits = scene.medium->emission.emits();
  for (const MethodInfo& info : registered_methods()) {
    if (!info.offer) continue;
    offers.emplace_back(info.name, emits && !info.emission ? AutoOffer{false, {}, 0.0, "does not render emission"} : info.offer(f, tolerance));
  }
  const auto best = std::min_element(offers.begin(), offers.end(), [](const auto& a, const auto& b) {
    if (a.second.offered != b.second.offered) return a.second.offered;
    return a.second.expected_seconds < b.second.expected_seconds;
  });
  if (best != offers.end() && best->second.offered) {
    c.method = best->first, c.settings = best->second.settings, c.expected_seconds = best->second.expected_seconds;
    c.why.push_back(best->first + format(", expected %.3g s: ", best->second.expected_seconds) + best->second.why);
  }
  for (const auto& [name, offer] : offers) {
    if (name == c.method) continue;
    c.why.push_back(name + (offer.offered ? format(" (expected %.3g s): ", offer.expected_seconds) : std::string(" declines: ")) + offer.why);
  }
  if (!c.method.empty()) return c;
  c.why.push_back("no registered method offers a fast way under the tolerance");
  return reference_for(tolerance, c);
}

}  // namespace

MethodInfo auto_info() {
  MethodInfo info;
  info.name = kAutoName;
  info.role = MethodInfo::Role::chooser;
  info.emission = true;  // only methods that render emission bid for an emitting medium
  info.summary = "the cheapest registered method and settings expected to meet --set tolerance=T (0.05), chosen from the scene alone";
  info.create = [] { return std::make_unique<AutoMethod>(); };
  info.handles = {"what the chosen method handles", "what the chosen method handles", "what the chosen method handles", true};
  info.settings = {SettingInfo::number("tolerance", 0.05, 1e-4, 0.99, "the relative error to stay under (mean over lit pixels)")};
  for (double t : {0.05, 0.02, 0.01}) info.trade_sweep.push_back({{"tolerance", t}});
  return info;
}

void register_auto() { register_method(auto_info()); }

AutoChoice choose_method(const Scene& scene, double tolerance) {
  if (!(tolerance > 0.0 && tolerance < 1.0)) throw Error("tolerance", format("%g", tolerance), "a relative error in (0, 1), e.g. 0.05");
  return choose(scene, tolerance);
}

}  // namespace haze
