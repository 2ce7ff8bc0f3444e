#include "builtin_methods.h"

#include <haze/core/error.h>
#include <haze/core/light_culling.h>
#include <haze/core/method.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <mutex>

namespace haze {

namespace {

struct Registry {
  std::mutex mutex;
  std::map<std::string, MethodInfo> methods;
  ParticleMediumFactory particle_medium;
  Registry() {
    methods["quadrature"] = {"quadrature",
                             "single scattering by deterministic numerical quadrature (any medium; a yardstick, not fast)",
                             internal::make_quadrature_method, false, true};
    methods["reference"] = {"reference",
                            "unbiased volumetric path tracer with a standard-error image (the yardstick for every method)",
                            internal::make_reference_method};
    methods["analytic"] = {"analytic",
                           "closed-form single scattering, homogeneous medium, point and spot lights (seed 002; no shadows)",
                           internal::make_analytic_method, false, true};
    methods["auto"] = {"auto",
                       "the cheapest method and settings expected to meet --set tolerance=T (0.05), chosen from the scene alone",
                       internal::make_auto_method, true};
  }
};

Registry& registry() {
  static Registry instance;
  return instance;
}

}  // namespace

void register_method(MethodInfo info) {
  if (info.name.empty() || !info.create) throw Error("method.name", "\"" + info.name + "\"", "a name and a factory");
  auto& r = registry();
  std::lock_guard lock(r.mutex);
  r.methods[info.name] = std::move(info);
}

std::vector<MethodInfo> registered_methods() {
  auto& r = registry();
  std::lock_guard lock(r.mutex);
  std::vector<MethodInfo> out;
  for (const auto& [name, info] : r.methods) out.push_back(info);
  return out;
}

void register_particle_medium(ParticleMediumFactory factory) {
  auto& r = registry();
  std::lock_guard lock(r.mutex);
  r.particle_medium = std::move(factory);
}

std::unique_ptr<Method> create_method(const std::string& name) {
  auto& r = registry();
  std::lock_guard lock(r.mutex);
  auto it = r.methods.find(name);
  if (it == r.methods.end()) {
    std::string names;
    for (const auto& [n, info] : r.methods) names += (names.empty() ? "" : ", ") + n;
    throw Error("method.name", "\"" + name + "\"", "one of the available methods: " + names);
  }
  return it->second.create();
}

std::filesystem::path default_cache_dir() {
  if (const char* dir = std::getenv("HAZE_CACHE_DIR"); dir && *dir) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::filesystem::path(xdg) / "haze";
  if (const char* home = std::getenv("HOME"); home && *home) return std::filesystem::path(home) / ".cache" / "haze";
  return std::filesystem::temp_directory_path() / "haze";
}

namespace {

// The method on the scene without the lights that reach nothing it shows (light_culling.h), which
// the stats list. A scene whose lights all reach nothing renders as it is.
RenderResult render_culled(const Method& method, bool single_scattering, const Scene& scene, const RenderOptions& options) {
  const std::vector<CulledLight> culled = culled_lights(scene, single_scattering);
  if (culled.empty() || culled.size() == scene.lights.size()) return method.render(scene, options);
  Scene kept = scene;
  kept.lights.clear();
  std::vector<size_t> original;  // kept light -> its index in scene.lights
  nlohmann::json listed = nlohmann::json::array();
  for (size_t i = 0, c = 0; i < scene.lights.size(); ++i) {
    if (c < culled.size() && culled[c].index == i) listed.push_back({{"index", i}, {"why", culled[c++].why}});
    else kept.lights.push_back(scene.lights[i]), original.push_back(i);
  }
  try {
    RenderResult result = method.render(kept, options);
    result.stats["culled_lights"] = listed;
    return result;
  } catch (const Cancelled&) {
    throw;
  } catch (const Error& e) {
    // An error about "lights[k]..." names the caller's light, not the k-th one kept.
    const std::string& field = e.field();
    const size_t close = field.find(']');
    if (field.rfind("lights[", 0) != 0 || close == std::string::npos || close == 7) throw;
    const std::string digits = field.substr(7, close - 7);
    if (!std::all_of(digits.begin(), digits.end(), [](char ch) { return ch >= '0' && ch <= '9'; })) throw;
    const size_t k = std::stoul(digits);
    if (k >= original.size()) throw;
    throw Error("lights[" + std::to_string(original[k]) + field.substr(close), e.value(), e.expected());
  }
}

}  // namespace

RenderResult render(const Scene& scene, const std::string& method_name, RenderOptions options) {
  std::string name = method_name.empty() ? scene.method_name() : method_name;
  if (name.empty()) throw Error("method.name", "missing", "a method named by the scene or the caller");
  auto method = create_method(name);
  nlohmann::json settings = nlohmann::json::object();
  if (scene.method_name() == name) settings = scene.method;
  for (const auto& [key, value] : options.settings.items()) settings[key] = value;
  settings.erase("name");
  auto& r = registry();
  ParticleMediumFactory factory;
  bool reads_particles = false, single_scattering = false;
  {
    std::lock_guard lock(r.mutex);
    factory = r.particle_medium;
    reads_particles = r.methods.at(name).reads_particles;
    single_scattering = r.methods.at(name).single_scattering;
  }
  if (!scene.particles.is_null()) {
    if (!reads_particles) {
      if (scene.medium)
        throw Error("particles", "given with a medium", "one of `medium` and `particles` for method " + name + ", which renders one medium");
      if (!factory) throw Error("particles", "no particle module registered", "haze::particles::register_methods() before rendering particles");
      Scene converted = scene;
      converted.medium = factory(scene, settings);
      options.settings = std::move(settings);
      return render_culled(*method, single_scattering, converted, options);
    }
  }
  options.settings = std::move(settings);
  return render_culled(*method, single_scattering, scene, options);
}

}  // namespace haze

namespace haze {

Settings::Settings(const nlohmann::json& settings, std::string method) : settings_(settings), method_(std::move(method)) {
  if (!settings_.is_object()) throw Error("method", settings_.dump(), "an object of " + method_ + " settings");
}

long long Settings::integer(const std::string& key, long long fallback, long long min, long long max) {
  known_.push_back(key);
  auto it = settings_.find(key);
  if (it == settings_.end()) return fallback;
  if (!it->is_number_integer() || it->get<long long>() < min || it->get<long long>() > max)
    throw Error("method." + key, it->dump(), "an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]");
  return it->get<long long>();
}

double Settings::number(const std::string& key, double fallback, double min, double max) {
  known_.push_back(key);
  auto it = settings_.find(key);
  if (it == settings_.end()) return fallback;
  if (!it->is_number() || !(it->get<double>() >= min && it->get<double>() <= max))
    throw Error("method." + key, it->dump(), "a number in [" + to_text(min) + ", " + to_text(max) + "]");
  return it->get<double>();
}

std::string Settings::choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& allowed) {
  known_.push_back(key);
  auto it = settings_.find(key);
  if (it == settings_.end()) return fallback;
  if (it->is_string() && std::find(allowed.begin(), allowed.end(), it->get<std::string>()) != allowed.end()) return it->get<std::string>();
  std::string names;
  for (const auto& a : allowed) names += (names.empty() ? "\"" : ", \"") + a + "\"";
  throw Error("method." + key, it->dump(), "one of " + names);
}

void Settings::reject_unknown() const {
  for (const auto& [key, value] : settings_.items()) {
    if (key == "name" || std::find(known_.begin(), known_.end(), key) != known_.end()) continue;
    std::string names;
    for (const auto& k : known_) names += (names.empty() ? "" : ", ") + k;
    throw Error("method." + key, value.dump(), "a setting of " + method_ + ": " + (names.empty() ? "none" : names));
  }
}

}  // namespace haze
