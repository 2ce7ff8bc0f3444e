#include "registry.h"

#include <haze/core/error.h>
#include <haze/core/method.h>
#include <haze/core/names.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <mutex>
#include <sstream>

namespace haze {

namespace {

struct Registry {
  std::mutex mutex;
  std::map<std::string, MethodInfo> methods;
  std::map<std::string, std::function<std::unique_ptr<Method>()>> splits;  // register_split
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

// The registry's entry for a method (registry.h).
MethodInfo method_info(const std::string& name) {
  auto& r = registry();
  std::lock_guard lock(r.mutex);
  auto it = r.methods.find(name);
  if (it == r.methods.end()) {
    std::string names;
    for (const auto& [n, info] : r.methods) names += (names.empty() ? "" : ", ") + n;
    throw Error("method.name", "\"" + name + "\"", "one of the available methods: " + names);
  }
  return it->second;
}

std::unique_ptr<Method> create_method(const std::string& name) { return method_info(name).create(); }

AutoOffer offer_from(std::span<const MeasuredOffer> table, double tolerance, const std::string& what, const std::string& otherwise) {
  for (const MeasuredOffer& row : table)
    if (tolerance >= row.tolerance) return AutoOffer{true, row.settings, row.seconds, what + ": " + row.measured};
  return AutoOffer{false, {}, 0.0, otherwise};
}

void register_split(const std::string& method, std::function<std::unique_ptr<Method>()> create) {
  if (method.empty() || !create) throw Error("method.name", "\"" + method + "\"", "a name and a factory for its split form");
  auto& r = registry();
  std::lock_guard lock(r.mutex);
  r.splits[method] = std::move(create);
}

std::unique_ptr<Method> create_split(const std::string& name, int ranks) {
  auto& r = registry();
  std::lock_guard lock(r.mutex);
  const auto it = r.splits.find(name);
  if (it != r.splits.end()) return it->second();
  if (ranks == 1) return nullptr;
  std::string names;
  for (const auto& [n, create] : r.splits) names += (names.empty() ? "" : ", ") + n;
  throw Error("method.name", name, "a method split over processes under " + to_text(ranks) + " ranks (" + (names.empty() ? "none is registered" : names) +
                                       "), or one process");
}

std::string method_with_role(MethodInfo::Role role) {
  auto& r = registry();
  std::lock_guard lock(r.mutex);
  for (const auto& [name, info] : r.methods)
    if (info.role == role) return name;
  constexpr Named<MethodInfo::Role> kRoles[] = {
      {MethodInfo::Role::solver, "solver"}, {MethodInfo::Role::reference, "reference"}, {MethodInfo::Role::chooser, "chooser"}};
  throw Error("method.role", name_of<MethodInfo::Role>(kRoles, role), "a registered method of that role");
}

std::filesystem::path default_cache_dir() {
  if (const char* dir = std::getenv("HAZE_CACHE_DIR"); dir && *dir) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::filesystem::path(xdg) / "haze";
  if (const char* home = std::getenv("HOME"); home && *home) return std::filesystem::path(home) / ".cache" / "haze";
  return std::filesystem::temp_directory_path() / "haze";
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

SettingInfo SettingInfo::integer(std::string name, nlohmann::json fallback, long long min, long long max, std::string doc) {
  return {std::move(name), Type::integer, std::move(fallback), static_cast<double>(min), static_cast<double>(max), {}, std::move(doc)};
}
SettingInfo SettingInfo::number(std::string name, nlohmann::json fallback, double min, double max, std::string doc) {
  return {std::move(name), Type::number, std::move(fallback), min, max, {}, std::move(doc)};
}
SettingInfo SettingInfo::choice(std::string name, std::string fallback, std::vector<std::string> choices, std::string doc) {
  return {std::move(name), Type::choice, std::move(fallback), 0.0, 0.0, std::move(choices), std::move(doc)};
}

SettingInfo SettingInfo::cells(std::string name, nlohmann::json fallback, long long min, long long max, std::string doc) {
  return {std::move(name), Type::cells, std::move(fallback), static_cast<double>(min), static_cast<double>(max), {}, std::move(doc)};
}

namespace {
std::string quoted_list(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "\"" : ", \"") + n + "\"";
  return out;
}
std::string range(const SettingInfo& s) {
  if (s.type == SettingInfo::Type::choice) return "one of " + quoted_list(s.choices);
  if (s.type == SettingInfo::Type::integer || s.type == SettingInfo::Type::cells) {
    std::string out = "an integer in [" + to_text(static_cast<long long>(s.min)) + ", " + to_text(static_cast<long long>(s.max)) + "]";
    if (s.type == SettingInfo::Type::cells) out += ", or three [nx, ny, nz]";
    return out;
  }
  return "a number in [" + to_text(s.min) + ", " + to_text(s.max) + "]";
}
}  // namespace

std::string SettingInfo::describe() const {
  return range(*this) + ", default " + (fallback.is_null() ? std::string("as described") : fallback.dump());
}

const SettingInfo* MethodInfo::setting(const std::string& key) const {
  for (const SettingInfo& s : settings)
    if (s.name == key) return &s;
  return nullptr;
}

std::string settings_help(const MethodInfo& info) {
  std::string out;
  for (const SettingInfo& s : info.settings) out += "  " + s.name + ": " + s.doc + " (" + s.describe() + ")\n";
  return out.empty() ? "  (no settings)\n" : out;
}

std::string settings_markdown(const MethodInfo& info) {
  std::ostringstream out;
  out << "| setting | default | accepted | what it does |\n|---|---|---|---|\n";
  for (const SettingInfo& s : info.settings) {
    out << "| `" << s.name << "` | ";
    if (s.fallback.is_null()) out << "see text";
    else out << '`' << s.fallback.dump() << '`';
    out << " | " << range(s) << " | " << s.doc << " |\n";
  }
  return out.str();
}

Settings::Settings(const nlohmann::json& settings, const std::string& method) : settings_(settings), method_(method_info(method)) {
  if (!settings_.is_object()) throw Error("method", json_text(settings_), "an object of " + method + " settings");
}

const SettingInfo& Settings::info(const std::string& key, SettingInfo::Type type) {
  const SettingInfo* s = method_.setting(key);
  HAZE_CHECK(s && s->type == type);  // a method reads only the settings its MethodInfo declares
  known_.push_back(key);
  return *s;
}

long long Settings::integer(const std::string& key) { return integer(key, info(key, SettingInfo::Type::integer).fallback.get<long long>()); }
long long Settings::integer(const std::string& key, long long fallback) {
  const SettingInfo& s = info(key, SettingInfo::Type::integer);
  auto it = settings_.find(key);
  if (it == settings_.end()) return fallback;
  if (!it->is_number_integer() || static_cast<double>(it->get<long long>()) < s.min || static_cast<double>(it->get<long long>()) > s.max)
    throw Error("method." + key, json_text(*it), range(s));
  return it->get<long long>();
}

double Settings::number(const std::string& key) { return number(key, info(key, SettingInfo::Type::number).fallback.get<double>()); }
double Settings::number(const std::string& key, double fallback) {
  const SettingInfo& s = info(key, SettingInfo::Type::number);
  auto it = settings_.find(key);
  if (it == settings_.end()) return fallback;
  if (!it->is_number() || !(it->get<double>() >= s.min && it->get<double>() <= s.max)) throw Error("method." + key, json_text(*it), range(s));
  return it->get<double>();
}

std::string Settings::choice(const std::string& key) { return choice(key, info(key, SettingInfo::Type::choice).fallback.get<std::string>()); }
std::string Settings::choice(const std::string& key, const std::string& fallback) {
  const SettingInfo& s = info(key, SettingInfo::Type::choice);
  auto it = settings_.find(key);
  if (it == settings_.end()) return fallback;
  if (it->is_string() && std::find(s.choices.begin(), s.choices.end(), it->get<std::string>()) != s.choices.end()) return it->get<std::string>();
  throw Error("method." + key, json_text(*it), range(s));
}

std::vector<int> Settings::cells(const std::string& key) {
  const SettingInfo& s = info(key, SettingInfo::Type::cells);
  auto it = settings_.find(key);
  const nlohmann::json& value = it == settings_.end() ? s.fallback : *it;
  auto in_range = [&](const nlohmann::json& v) { return v.is_number_integer() && v.get<double>() >= s.min && v.get<double>() <= s.max; };
  if (in_range(value)) return {value.get<int>()};
  if (value.is_array() && value.size() == 3 && std::all_of(value.begin(), value.end(), in_range))
    return {value[0].get<int>(), value[1].get<int>(), value[2].get<int>()};
  throw Error("method." + key, json_text(value), range(s));
}

void Settings::reject_unknown() const {
  for (const auto& [key, value] : settings_.items()) {
    if (key == "name" || std::find(known_.begin(), known_.end(), key) != known_.end()) continue;
    std::string names;
    for (const auto& k : method_.settings) names += (names.empty() ? "" : ", ") + k.name;
    throw Error("method." + key, json_text(value), "a setting of " + method_.name + ": " + (names.empty() ? "none" : names));
  }
}

}  // namespace haze
