#include "builtin_methods.h"

#include <haze/core/error.h>
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

// Registry look-ups for solution.cpp.
MethodInfo method_info(const std::string& name) {
  create_method(name);  // the error lists the available methods
  auto& r = registry();
  std::lock_guard lock(r.mutex);
  return r.methods.at(name);
}

ParticleMediumFactory particle_medium_factory() {
  auto& r = registry();
  std::lock_guard lock(r.mutex);
  return r.particle_medium;
}

std::optional<UpdateReport> MethodSolution::update(const Scene&, const SceneChange&, const RenderOptions&) { return std::nullopt; }

namespace {
[[noreturn]] void no_field(const char* field) {
  throw Error(field, std::string(internal::kNoField), "a method that keeps lighting fields on a grid");
}
}  // namespace

Rgb MethodSolution::transmittance(size_t, const Vec3&) const { no_field("transmittance"); }
Rgb MethodSolution::fluence(const Vec3&) const { no_field("fluence"); }
Rgb MethodSolution::inscattered(const Vec3&, const Vec3&) const { no_field("inscattered"); }

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
