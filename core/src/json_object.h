// Reading JSON with checked types and error paths (docs/SCENES.md): the toolkit the scene reader
// (scene.cpp), the grid file reader (grid_file.cpp) and the modules' readers (scene_fields,
// scene.h) share. Types and finiteness are checked as values are read; ranges are check_scene's
// (scene_check.cpp).
#pragma once

#include <haze/core/error.h>
#include <haze/core/math.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <string_view>

namespace haze::internal {

using json = nlohmann::json;
namespace fs = std::filesystem;

inline constexpr const char* kVec3Text = "an [x, y, z] array of 3 finite numbers";
inline constexpr const char* kDirectionText = "a non-zero [x, y, z] array of 3 finite numbers";

std::string key_path(const std::string& path, std::string_view key);
std::string index_path(const std::string& path, std::size_t i);
std::string join(std::initializer_list<std::string_view> names, std::string_view quote = "");
std::string text(const json& v);  // json_text

// A number check: the predicate and the words for the error message. The readers check types and
// finiteness; ranges are check_scene's (scene_check.cpp), which Scene::from_json calls last, and
// the phase constructors'.
struct Check {
  bool (*ok)(double);
  const char* expected;
};
inline constexpr Check kFinite{[](double) { return true; }, "a finite number"};
// The phase constructors check |g| <= 0.9999 themselves; this only words the type error.
inline constexpr Check kG{[](double) { return true; }, "a number with |g| <= 0.9999"};

double read_number(const json& v, const std::string& path, Check check);
int read_int(const json& v, const std::string& path, int lo, int hi);
Vec3 read_vec3(const json& v, const std::string& path);
// Made unit length where it can be (check_scene refuses one that cannot).
Vec3 read_direction(const json& v, const std::string& path);
// A colour-like quantity: one number for all channels or an [r, g, b] array, each checked.
Rgb read_color(const json& v, const std::string& path, Check check);
std::string read_string(const json& v, const std::string& path, const std::string& expected);

// A JSON object being read, with its path for error messages.
class Object {
 public:
  Object(const json& j, std::string path) : j_(j), path_(std::move(path)) {
    if (!j_.is_object()) throw Error(path_.empty() ? "(scene)" : path_, text(j_), "a JSON object {...}");
  }

  std::string at(std::string_view key) const { return key_path(path_, key); }
  const json* find(const char* key) const {
    auto it = j_.find(key);
    return it == j_.end() ? nullptr : &*it;
  }
  const json& need(const char* key, const std::string& expected) const {
    if (const json* v = find(key)) return *v;
    throw Error(at(key), "missing", expected);
  }

  // Unknown fields are almost always typos ("albdeo"): reject them and name the allowed ones.
  void allow(std::initializer_list<std::string_view> fields) const {
    for (const auto& [key, value] : j_.items()) {
      if (std::find(fields.begin(), fields.end(), key) != fields.end()) continue;
      std::string where = path_.empty() ? "the scene" : path_;
      if (!type_.empty()) where += " (type \"" + type_ + "\")";
      throw Error(at(key), "unknown field \"" + key + "\"", "a field of " + where + ": " + join(fields));
    }
  }

  // The "type" field, one of `types`; `fallback` when absent, or required when fallback is null.
  std::string type(std::initializer_list<std::string_view> types, const char* fallback = nullptr, const std::vector<std::string>& more = {}) const {
    std::string expected = "one of " + join(types, "\"");
    for (const std::string& t : more) expected += ", \"" + t + "\"";
    const json* v = find("type");
    if (!v && !fallback) throw Error(at("type"), "missing", expected);
    auto known = [&](const json& t) {
      if (!t.is_string()) return false;
      const std::string& name = t.get_ref<const std::string&>();
      return std::find(types.begin(), types.end(), name) != types.end() || std::find(more.begin(), more.end(), name) != more.end();
    };
    if (v && !known(*v)) throw Error(at("type"), text(*v), expected);
    type_ = v ? v->get<std::string>() : fallback;
    return type_;
  }

  void name_type(const std::string& type) const { type_ = type; }  // for allow()'s message, where type() was not called

  double number(const char* key, Check check) const { return read_number(need(key, check.expected), at(key), check); }
  double number(const char* key, double fallback, Check check) const {
    const json* v = find(key);
    return v ? read_number(*v, at(key), check) : fallback;
  }
  int integer(const char* key, int fallback, int lo, int hi) const {
    const json* v = find(key);
    return v ? read_int(*v, at(key), lo, hi) : fallback;
  }
  Vec3 vec3(const char* key) const { return read_vec3(need(key, kVec3Text), at(key)); }
  Vec3 vec3(const char* key, const Vec3& fallback) const {
    const json* v = find(key);
    return v ? read_vec3(*v, at(key)) : fallback;
  }
  Vec3 direction(const char* key) const { return read_direction(need(key, kDirectionText), at(key)); }
  Rgb color(const char* key, Check check) const {
    return read_color(need(key, std::string(check.expected) + ", or an [r, g, b] array of such numbers"), at(key), check);
  }
  Rgb color(const char* key, const Rgb& fallback, Check check) const {
    const json* v = find(key);
    return v ? read_color(*v, at(key), check) : fallback;
  }

 private:
  const json& j_;
  std::string path_;
  mutable std::string type_;  // once type() has read it: allow() names it, as the fields depend on it
};

// The existing file o.file names, relative to the scene's folder, as an absolute path (so that
// messages say exactly where Haze looked).
fs::path existing_file(const Object& o, const fs::path& base_dir, const std::string& expected);

// A scene file's JSON, checked as it is parsed: arrays and objects nested at most 256 deep, no key
// twice in one object, numbers within a double's range; errors name the file's line and column,
// or the JSON path.
json parse_checked(const std::string& content, const std::string& file);

}  // namespace haze::internal
