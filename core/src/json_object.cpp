// The JSON toolkit of json_object.h: readers with checked types and error paths, short texts of
// values for messages, the modules' scene_fields helpers, and the checked parse of a scene file.
#include "json_object.h"

#include <haze/core/scene.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <set>
#include <vector>

namespace haze {
namespace {

using json = nlohmann::json;

// A string as JSON, at most `most` of its characters.
std::string quoted(const std::string& s, size_t most) {
  return json(s.substr(0, most)).dump(-1, ' ', false, json::error_handler_t::replace) + (s.size() > most ? "..." : "");
}

// Appends v as JSON text until `out` holds `limit` characters, no deeper than 16 levels: a value
// may be megabytes long or nested 100,000 deep, so it is never dumped whole.
void brief(const json& v, std::string& out, size_t limit, int depth) {
  if (out.size() >= limit) return;
  if (v.is_string()) {
    out += quoted(v.get_ref<const std::string&>(), limit - out.size());
  } else if (v.is_number_float() && !std::isfinite(v.get<double>())) {
    out += to_text(v.get<double>());  // nlohmann dumps NaN and inf as null
  } else if (!v.is_structured()) {
    out += v.dump();
  } else if (depth >= 16) {
    out += v.is_array() ? "[...]" : "{...}";
  } else {
    out += v.is_array() ? '[' : '{';
    for (auto it = v.begin(); it != v.end(); ++it) {
      if (it != v.begin()) out += ", ";
      if (out.size() >= limit) return;
      if (v.is_object()) out += quoted(it.key(), limit) + ": ";
      brief(*it, out, limit, depth + 1);
    }
    out += v.is_array() ? ']' : '}';
  }
}

}  // namespace

std::string json_text(const nlohmann::json& v) {
  std::string s;
  brief(v, s, 81, 0);
  if (s.size() > 80) s = s.substr(0, 77) + "...";
  return s;
}

namespace internal {

std::string key_path(const std::string& path, std::string_view key) { return path.empty() ? std::string(key) : path + "." + std::string(key); }
std::string index_path(const std::string& path, std::size_t i) { return path + "[" + std::to_string(i) + "]"; }

std::string join(std::initializer_list<std::string_view> names, std::string_view quote) {
  std::string out;
  for (auto name : names) {
    if (!out.empty()) out += ", ";
    out.append(quote).append(name).append(quote);
  }
  return out;
}

std::string text(const json& v) { return json_text(v); }

double read_number(const json& v, const std::string& path, Check check) {
  if (!v.is_number()) throw Error(path, text(v), check.expected);
  double x = v.get<double>();
  if (!std::isfinite(x) || !check.ok(x)) throw Error(path, text(v), check.expected);
  return x;
}

int read_int(const json& v, const std::string& path, int lo, int hi) {
  const std::string expected = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (!v.is_number_integer()) throw Error(path, text(v), expected);
  // Unsigned JSON integers may not fit int64_t; compare before converting.
  if (v.is_number_unsigned()) {
    auto u = v.get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(hi) || static_cast<std::int64_t>(u) < lo) throw Error(path, text(v), expected);
    return static_cast<int>(u);
  }
  auto i = v.get<std::int64_t>();
  if (i < lo || i > hi) throw Error(path, text(v), expected);
  return static_cast<int>(i);
}

Vec3 read_vec3(const json& v, const std::string& path) {
  if (!v.is_array() || v.size() != 3) throw Error(path, text(v), kVec3Text);
  Vec3 out;
  for (int i = 0; i < 3; ++i) out[i] = read_number(v[i], index_path(path, i), kFinite);
  return out;
}

Vec3 read_direction(const json& v, const std::string& path) {
  Vec3 d = read_vec3(v, path);
  Vec3 unit = d;
  return make_unit(unit) ? unit : d;
}

Rgb read_color(const json& v, const std::string& path, Check check) {
  if (v.is_number()) return Rgb(read_number(v, path, check));
  if (!v.is_array() || v.size() != 3) throw Error(path, text(v), std::string(check.expected) + ", or an [r, g, b] array of such numbers");
  Rgb out;
  for (int i = 0; i < 3; ++i) out[i] = read_number(v[i], index_path(path, i), check);
  return out;
}

std::string read_string(const json& v, const std::string& path, const std::string& expected) {
  if (!v.is_string() || v.get_ref<const std::string&>().empty()) throw Error(path, text(v), expected);
  return v.get<std::string>();
}

fs::path existing_file(const Object& o, const fs::path& base_dir, const std::string& expected) {
  const std::string name = read_string(o.need("file", expected), o.at("file"), expected);
  // A NUL would end the name early for the C library: "a.raw\u0000.vdb" is not "a.raw".
  if (name.find('\0') != std::string::npos) throw Error(o.at("file"), text(o.need("file", expected)), "a file name without NUL characters");
  fs::path file = name;
  if (file.is_relative()) file = base_dir / file;
  std::error_code ec;
  if (fs::path absolute = fs::absolute(file, ec); !ec) file = absolute;
  file = file.lexically_normal();
  if (!fs::is_regular_file(file, ec))
    throw Error(o.at("file"), text(o.need("file", expected)) + " (resolved to " + file.string() + ")",
                "an existing file, but there is none at that path");
  return file;
}

namespace {

// The scene file's JSON, checked as it is parsed (nlohmann's parser callback): arrays and objects
// nested at most kMaxJsonDepth deep (a million-deep file would overflow a recursive reader), and no
// key twice in one object (nlohmann keeps the last silently). Errors name the JSON path.
constexpr std::size_t kMaxJsonDepth = 256;
struct JsonChecks {
  struct Level {
    bool array = false;
    long index = -1;  // an array's element being read
    std::string key;  // an object's key being read
    std::set<std::string> keys;
  };
  std::string file;
  std::shared_ptr<std::vector<Level>> levels = std::make_shared<std::vector<Level>>();  // the callback is copied

  std::string where() const {
    std::string out;
    for (const Level& l : *levels) out += l.array ? "[" + std::to_string(l.index) + "]" : (out.empty() ? "" : ".") + l.key;
    return out.empty() ? "(scene)" : out;
  }
  bool operator()(int, json::parse_event_t event, json& parsed) const {
    using Event = json::parse_event_t;
    std::vector<Level>& stack = *levels;
    const auto element = [&] {
      if (!stack.empty() && stack.back().array) ++stack.back().index;
    };
    switch (event) {
      case Event::object_start:
      case Event::array_start:
        element();
        if (stack.size() >= kMaxJsonDepth)
          throw Error(file, "arrays and objects nested deeper than " + std::to_string(kMaxJsonDepth) + " at " + where(),
                      "at most " + std::to_string(kMaxJsonDepth) + " levels");
        stack.push_back({event == Event::array_start, -1, {}, {}});
        break;
      case Event::key: {
        Level& object = stack.back();
        object.key = parsed.get<std::string>();
        if (!object.keys.insert(object.key).second) throw Error(where(), "given twice", "each key once in an object");
        break;
      }
      case Event::value:
        element();
        break;
      case Event::object_end:
      case Event::array_end:
        stack.pop_back();
        break;
    }
    return true;
  }
};

}  // namespace

json parse_checked(const std::string& content, const std::string& file) {
  // Line and column of byte `pos` (0-based) of the file.
  auto place = [&](std::size_t pos) {
    pos = std::min(pos, content.size());
    const std::string_view head = std::string_view(content).substr(0, pos);
    const std::size_t last_newline = head.rfind('\n');
    return "line " + std::to_string(1 + std::count(head.begin(), head.end(), '\n')) + ", column " +
           std::to_string(pos - (last_newline == std::string_view::npos ? 0 : last_newline + 1) + 1);
  };
  try {
    return nlohmann::json::parse(content, JsonChecks{file});
  } catch (const nlohmann::json::out_of_range& e) {
    // A number beyond a double's range ("number overflow parsing '1e999'"): where it is.
    std::string detail = e.what();
    const std::size_t open = detail.find('\''), close = detail.rfind('\'');
    const std::string token = open != std::string::npos && close > open ? detail.substr(open + 1, close - open - 1) : std::string();
    const std::size_t at = token.empty() ? std::string::npos : content.find(token);
    throw Error(file, (at == std::string::npos ? std::string() : "at " + place(at) + ": ") + "the number " + token,
                "numbers within a double's range (up to about 1.8e308)");
  } catch (const nlohmann::json::parse_error& e) {
    // Drop nlohmann's "[json.exception.parse_error.101] " tag: the rest is the useful part.
    std::string detail = e.what();
    if (auto tag_end = detail.find("] "); detail.starts_with("[json.exception") && tag_end != std::string::npos) detail.erase(0, tag_end + 2);
    // nlohmann's byte is 1-based: the character where parsing failed.
    throw Error(file, "invalid JSON at " + place(e.byte > 0 ? e.byte - 1 : 0) + " (byte " + std::to_string(e.byte) + ")",
                "valid JSON (" + detail + ")");
  }
}

}  // namespace internal

namespace scene_fields {

using namespace internal;

void allow(const nlohmann::json& j, const std::string& path, std::initializer_list<std::string_view> fields, const std::string& type) {
  const Object o(j, path);
  o.name_type(type);
  o.allow(fields);
}

int integer(const nlohmann::json& j, const std::string& path, const char* key, int fallback, int lo, int hi, const std::string& meaning) {
  const Object o(j, path);
  try {
    return o.integer(key, fallback, lo, hi);
  } catch (const Error& e) {
    if (meaning.empty()) throw;
    throw Error(e.field(), e.value(), e.expected() + ": " + meaning);
  }
}

std::string text(const nlohmann::json& j, const std::string& path, const char* key, const std::string& fallback, const std::string& expected) {
  const Object o(j, path);
  const json* v = o.find(key);
  if (!v && !fallback.empty()) return fallback;
  return read_string(v ? *v : o.need(key, expected), o.at(key), expected);
}

std::filesystem::path existing_file(const nlohmann::json& j, const std::string& path, const std::filesystem::path& directory,
                                    const std::string& expected) {
  return internal::existing_file(internal::Object(j, path), directory, expected);
}

}  // namespace scene_fields

}  // namespace haze
