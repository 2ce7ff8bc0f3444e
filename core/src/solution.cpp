// haze::prepare, haze::Solution and haze::render (method.h): the registry's method on the caller's
// scene, less the lights that reach nothing (light_culling.h), and errors about lights naming the
// caller's light.
#include "registry.h"

#include <haze/core/error.h>
#include <haze/core/light_culling.h>
#include <haze/core/method.h>
#include <haze/core/stopwatch.h>

#include <algorithm>

namespace haze {

struct Solution::State {
  MethodInfo info;
  std::unique_ptr<Method> method;
  Scene scene;               // the caller's, with every update applied
  RenderOptions options;     // as prepared: settings merged, no progress
  std::vector<size_t> kept;  // the method's light k is scene.lights[kept[k]]
  nlohmann::json culled = nlohmann::json::array();
  // The scene the method sees: the kept lights only.
  Scene seen;
  std::unique_ptr<MethodSolution> solution;

  // Decides which lights the method sees (made again from `scene`); true when that changed.
  bool cull() {
    seen = scene;
    const std::vector<CulledLight> found = culled_lights(seen, info.single_scattering && options.single_view);
    std::vector<size_t> kept_now;
    culled = nlohmann::json::array();
    seen.lights.clear();
    for (size_t i = 0, c = 0; i < scene.lights.size(); ++i) {
      // A scene whose lights all reach nothing renders as it is.
      if (c < found.size() && found[c].index == i && found.size() < scene.lights.size())
        culled.push_back({{"index", i}, {"why", found[c++].why}});
      else
        kept_now.push_back(i), seen.lights.push_back(scene.lights[i]);
    }
    const bool changed = kept_now != kept;
    kept = std::move(kept_now);
    return changed;
  }

  // What a render hands the method: the caller's threads and progress with what the solution was
  // prepared under, but not prepare's settings and cache (a render reads neither): a copy that
  // allocates nothing, so that a frame need not.
  RenderOptions for_render(const RenderOptions& call) const {
    return RenderOptions{call.threads, nullptr, call.progress, {}, options.single_view, options.max_memory, options.ranks};
  }

  // An error about "lights[k]..." from the method names the caller's light, not the k-th kept.
  template <class F>
  auto naming_lights(F f) const {
    try {
      return f();
    } catch (const Cancelled&) {
      throw;
    } catch (const Error& e) {
      const std::string& field = e.field();
      const size_t close = field.find(']');
      if (field.rfind("lights[", 0) != 0 || close == std::string::npos || close == 7) throw;
      const std::string digits = field.substr(7, close - 7);
      if (!std::all_of(digits.begin(), digits.end(), [](char ch) { return ch >= '0' && ch <= '9'; })) throw;
      const size_t k = std::stoul(digits);
      if (k >= kept.size()) throw;
      throw Error("lights[" + std::to_string(kept[k]) + field.substr(close), e.value(), e.expected());
    }
  }

  void prepare(const ProgressCallback& progress) {
    RenderOptions o = options;
    o.progress = progress;
    solution = naming_lights([&] { return method->prepare(seen, o); });
    if (!culled.empty()) solution->stats["culled_lights"] = culled;
  }

  // A field query: the caller's light index, and a clear error for a method without the field.
  template <class F>
  Rgb field(const char* name, F f) const {
    try {
      return f();
    } catch (const Error& e) {
      if (e.field() != name || e.value() != internal::kNoField) throw;
      throw Error(name, "method " + info.name, e.expected());
    }
  }
  size_t method_light(size_t light) const {
    if (light >= scene.lights.size()) throw Error("light", to_text(light), "an index into the scene's " + to_text(scene.lights.size()) + " lights");
    const auto it = std::find(kept.begin(), kept.end(), light);
    if (it == kept.end()) throw Error("light", to_text(light), "a light the solution kept (lights[" + to_text(light) + "] reaches nothing: culled)");
    return static_cast<size_t>(it - kept.begin());
  }
};

Scene view_scene(const Scene& scene, const Camera& camera) {
  Scene seen;
  seen.camera = camera;
  seen.directory = scene.directory;
  seen.lights = scene.lights;
  seen.surfaces = scene.surfaces;
  seen.background = scene.background;
  seen.method = scene.method;
  return seen;
}

Solution::Solution(std::unique_ptr<State> state) : state_(std::move(state)) {}
Solution::Solution(Solution&&) noexcept = default;
Solution& Solution::operator=(Solution&&) noexcept = default;
Solution::~Solution() = default;

const std::string& Solution::method() const { return state_->info.name; }
const Scene& Solution::scene() const { return state_->scene; }
const nlohmann::json& Solution::stats() const { return state_->solution->stats; }
const MethodSolution& Solution::method_solution() const { return state_->solution->fields_owner(); }

RenderResult RenderResult::for_view(const View& view) {
  const int w = view.camera.width_px, h = view.camera.height_px;
  RenderResult r{Image(w, h), std::nullopt, nlohmann::json::object()};
  if (view.layers) r.inscatter = Image(w, h), r.transmittance = Image(w, h), r.surface = Image(w, h);
  return r;
}

void RenderResult::set(int x, int y, const PixelLayers& pixel) {
  radiance.set(x, y, pixel.radiance());
  if (inscatter) inscatter->set(x, y, pixel.inscatter), transmittance->set(x, y, pixel.transmittance), surface->set(x, y, pixel.surface);
}

namespace {

// A host's depth buffer: one value per pixel, each >= 0 or +inf.
// A span of the camera's pixels, named `name` in its errors.
void check_view_span(const ImageSpan& span, const char* name, const Camera& camera) {
  check_span(span, name);
  if (span.width != camera.width_px || span.height != camera.height_px)
    throw Error(name, to_text(span.width) + " x " + to_text(span.height), "the view's size, " + to_text(camera.width_px) + " x " + to_text(camera.height_px));
}

// The view's depth: one value per pixel, and with `values` each a distance >= 0.
void check_depth(const View& view, bool values = true) {
  if (view.depth.empty()) return;
  const size_t count = static_cast<size_t>(view.camera.width_px) * static_cast<size_t>(view.camera.height_px);
  if (view.depth.size() != count)
    throw Error("view.depth", to_text(view.depth.size()) + " values", to_text(count) + " (width_px x height_px), one distance per pixel");
  if (!values) return;
  // A branch-free pass first (it vectorizes: a 1080p frame's check from 2.7 ms), then where.
  bool bad = false;
  for (size_t i = 0; i < count; ++i) bad |= !(view.depth[i] >= 0.0f);
  if (!bad) return;
  for (size_t i = 0; i < count; ++i)
    if (!(view.depth[i] >= 0.0f))
      throw Error("view.depth[" + to_text(i) + "]", to_text(view.depth[i]), "a distance along the pixel's ray >= 0, or +inf for none");
}

}  // namespace

RenderResult Solution::render(const View& view, const RenderOptions& options) const {
  const State& s = *state_;
  check_depth(view);
  if ((view.layers || !view.depth.empty()) && !s.solution->renders_layers())
    throw Error("view", view.layers ? "layers" : "a depth buffer",
                "a method that renders layers and takes a depth buffer (every built-in method does; " + s.info.name + " does not)");
  if (!options.settings.is_null() && (!options.settings.is_object() || !options.settings.empty()))
    throw Error("settings", json_text(options.settings), "none when rendering a solution (settings are given to haze::prepare)");
  if (s.options.single_view && !(view.camera == s.scene.camera))
    throw Error("view.camera", "another camera than the scene's", "the scene's camera for a solution prepared with single_view");
  const RenderOptions o = s.for_render(options);
  RenderResult result = s.naming_lights([&] { return s.solution->render(view, o); });
  nlohmann::json stats = s.solution->stats;
  for (auto& [key, value] : result.stats.items()) stats[key] = std::move(value);
  result.stats = std::move(stats);
  return result;
}

void Solution::render_layers(const View& view, LayerSpans out, const RenderOptions& options) const {
  const Camera& camera = view.camera;
  check_view_span(out.inscatter, "out.inscatter", camera), check_view_span(out.transmittance, "out.transmittance", camera);
  if (out.surface.data) check_view_span(out.surface, "out.surface", camera);  // optional
  const State& s = *state_;
  check_depth(view);
  if (!s.solution->renders_layers())
    throw Error("view", "layers", "a method that renders layers (every built-in method does; " + s.info.name + " does not)");
  if (s.options.single_view && !(camera == s.scene.camera))
    throw Error("view.camera", "another camera than the scene's", "the scene's camera for a solution prepared with single_view");
  const RenderOptions o = s.for_render(options);
  const View layered{camera, view.depth, true};
  if (s.naming_lights([&] { return s.solution->render_layers(layered, out, o); })) return;
  const RenderResult r = render(layered, options);
  for (const auto& [span, image] : {std::pair{out.inscatter, &*r.inscatter}, std::pair{out.transmittance, &*r.transmittance}, std::pair{out.surface, &*r.surface}}) {
    if (!span.data) continue;
    for (int y = 0; y < camera.height_px; ++y)
      for (int x = 0; x < camera.width_px; ++x) {
        const Rgb v = image->at(x, y);
        float* p = span.pixel(x, y);
        p[0] = static_cast<float>(v.r), p[1] = static_cast<float>(v.g), p[2] = static_cast<float>(v.b);
      }
  }
}

void Solution::render_distances(const View& view, std::span<const double> distances, DistanceLayers out, const RenderOptions& options) const {
  for (size_t k = 0; k < distances.size(); ++k)
    if (!(distances[k] > 0.0) || (k > 0 && !(distances[k] >= distances[k - 1])))
      throw Error("distances[" + std::to_string(k) + "]", to_text(distances[k]), "ascending distances > 0");
  const size_t rays = static_cast<size_t>(view.camera.width_px) * static_cast<size_t>(view.camera.height_px), n = distances.size();
  for (const auto& [name, layer] : {std::pair{"out.inscatter", out.inscatter}, std::pair{"out.transmittance", out.transmittance}})
    if (layer.size() != rays * n)
      throw Error(name, to_text(layer.size()) + " entries", to_text(rays * n) + " (width_px x height_px x " + to_text(n) + " distances)");
  const State& s = *state_;
  const View at{view.camera, {}, true};
  if (s.options.single_view && !(view.camera == s.scene.camera))
    throw Error("view.camera", "another camera than the scene's", "the scene's camera for a solution prepared with single_view");
  const RenderOptions o = s.for_render(options);
  if (s.naming_lights([&] { return s.solution->render_distances(at, distances, o, out); })) return;
  std::vector<float> depth(rays);
  RenderOptions slice = options;
  for (size_t k = 0; k < n; ++k) {
    if (options.progress) slice.progress = [&, k](double f) { return options.progress((static_cast<double>(k) + f) / static_cast<double>(n)); };
    std::fill(depth.begin(), depth.end(), static_cast<float>(distances[k]));
    const RenderResult r = render(View{view.camera, depth, true}, slice);
    for (size_t i = 0; i < rays; ++i) {
      const int x = static_cast<int>(i % static_cast<size_t>(view.camera.width_px)), y = static_cast<int>(i / static_cast<size_t>(view.camera.width_px));
      out.inscatter[k * rays + i] = Vec3f(r.inscatter->at(x, y)), out.transmittance[k * rays + i] = Vec3f(r.transmittance->at(x, y));
    }
  }
}

void Solution::add_glow(const View& view, double glow_angle, ImageSpan out, const RenderOptions& options) const {
  check_view_span(out, "out", view.camera);
  // The depth's size only: its values are read near the lights alone, where a NaN or negative
  // distance ends the ray before the medium, as the composite takes it.
  check_depth(view, false);
  if (!(glow_angle >= 0.0 && glow_angle < 1.0)) throw Error("glow_angle", to_text(glow_angle), "an angle in [0, 1) radians");
  if (glow_angle == 0.0) return;
  const State& s = *state_;
  const RenderOptions o = s.for_render(options);
  s.naming_lights([&] { s.solution->add_glow(view, glow_angle, out, o); });
}

UpdateReport Solution::update(const SceneChange& change, const RenderOptions& options) {
  State& s = *state_;
  const Stopwatch watch;
  Scene next = s.scene;
  if (change.medium) {
    check_medium(*change.medium, "change.medium");
    next.medium = change.medium;
  }
  if (change.region && !change.medium) throw Error("change.region", "given without a medium", "the changed medium it bounds");
  if (change.lights) next.lights = *change.lights;
  if (change.surfaces) next.surfaces = *change.surfaces;
  std::swap(s.scene, next);
  UpdateReport report;
  try {
    const bool kept_changed = s.cull();
    SceneChange method_change = change;
    if (change.lights || kept_changed) method_change.lights = s.seen.lights;
    RenderOptions o = s.options;
    o.threads = options.threads;
    o.progress = options.progress;
    std::optional<UpdateReport> done = s.naming_lights([&] { return s.solution->update(s.seen, method_change, o); });
    if (done) {
      report = std::move(*done);
      if (!s.culled.empty())
        s.solution->stats["culled_lights"] = s.culled;
      else
        s.solution->stats.erase("culled_lights");
    } else {
      s.prepare(options.progress);
      report.rebuilt = true;
      report.redone = {"everything: method " + s.info.name + " reuses nothing for this change"};
      report.stats = s.solution->stats;
    }
  } catch (...) {  // a change that cannot be applied leaves the solution as it was
    std::swap(s.scene, next);
    s.cull();
    throw;
  }
  report.seconds = watch.seconds();
  return report;
}

Rgb Solution::transmittance(size_t light, const Vec3& x) const {
  const size_t k = state_->method_light(light);
  return state_->field("transmittance", [&] { return state_->solution->transmittance(k, x); });
}
Rgb Solution::fluence(const Vec3& x) const {
  return state_->field("fluence", [&] { return state_->solution->fluence(x); });
}
Rgb Solution::inscattered(const Vec3& x, const Vec3& w) const {
  return state_->field("inscattered", [&] { return state_->solution->inscattered(x, w); });
}

nlohmann::json method_settings(const Scene& scene, const std::string& method_name, const nlohmann::json& given) {
  nlohmann::json settings = scene.method_name() == method_name ? scene.method : nlohmann::json::object();
  if (!given.is_null() && !given.is_object()) throw Error("settings", json_text(given), "an object of " + method_name + " settings");
  for (const auto& [key, value] : given.items()) settings[key] = value;
  settings.erase("name");
  return settings;
}

Solution prepare(const Scene& scene, const std::string& method_name, RenderOptions options) {
  const std::string name = method_name.empty() ? scene.method_name() : method_name;
  if (name.empty()) throw Error("method.name", "missing", "a method named by the scene or the caller");
  check_scene(scene);
  auto state = std::make_unique<Solution::State>();
  state->info = method_info(name);
  if (scene.medium && scene.medium->emission.emits() && !state->info.emission) {
    std::string methods;
    for (const MethodInfo& info : registered_methods())
      if (info.emission) methods += (methods.empty() ? "" : ", ") + info.name;
    throw Error("medium.emission", "an emitting medium for method " + name, "a method that renders emission: " + methods);
  }
  if (options.ranks) state->method = create_split(name, options.ranks->size());
  if (!state->method) state->method = state->info.create();
  state->scene = scene;
  nlohmann::json settings = method_settings(scene, name, options.settings);
  const ProgressCallback progress = std::move(options.progress);
  options.settings = std::move(settings);
  state->options = std::move(options);
  state->cull();
  state->prepare(progress);
  return Solution(std::move(state));
}

RenderResult render(const Scene& scene, const std::string& method_name, RenderOptions options) {
  return render(scene, method_name, std::move(options), View{scene.camera});
}

RenderResult render(const Scene& scene, const std::string& method_name, RenderOptions options, const View& view) {
  const ProgressCallback progress = options.progress;
  const int threads = options.threads;
  options.single_view = true;
  // Progress: the share each step takes varies by method; prepare reports the first half.
  options.progress = progress ? [&](double f) { return progress(0.5 * f); } : ProgressCallback();
  const Solution solution = prepare(scene, method_name, std::move(options));
  RenderOptions render_options;
  render_options.threads = threads;
  render_options.progress = progress ? [&](double f) { return progress(0.5 + 0.5 * f); } : ProgressCallback();
  return solution.render(view, render_options);
}

}  // namespace haze
