// Scene files (docs/SCENES.md). Every field is checked here, once, so that renderers can trust a
// Scene: a bad value throws haze::Error naming its JSON path, the value and what was expected.
#include <haze/core/error.h>
#include <haze/core/scene.h>

#include <algorithm>
#include <bit>
#include <climits>
#include <cstdint>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <new>
#include <string_view>
#include <utility>

namespace haze {

namespace {

using json = nlohmann::json;
namespace fs = std::filesystem;

constexpr int kMaxImagePx = 16384;
constexpr int kMaxGridAxis = 16384;
// Downstream code may index a grid with int: keep nx * ny * nz within int range.
constexpr std::uint64_t kMaxGridCells = INT_MAX;

const char* const kVec3Text = "an [x, y, z] array of 3 finite numbers";
const char* const kDirectionText = "a non-zero [x, y, z] array of 3 finite numbers";

std::string key_path(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}
std::string index_path(const std::string& path, std::size_t i) { return path + "[" + std::to_string(i) + "]"; }

std::string join(std::initializer_list<std::string_view> names, std::string_view quote = "") {
  std::string out;
  for (auto name : names) {
    if (!out.empty()) out += ", ";
    out.append(quote).append(name).append(quote);
  }
  return out;
}

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

namespace {

std::string text(const json& v) { return json_text(v); }

// A number check: the predicate and the words for the error message. The reader checks types and
// finiteness; ranges are check_scene's (scene_check.cpp), which from_json calls last, and the
// phase constructors'.
struct Check {
  bool (*ok)(double);
  const char* expected;
};
constexpr Check kFinite{[](double) { return true; }, "a finite number"};
// The phase constructors check |g| <= 0.9999 themselves; this only words the type error.
constexpr Check kG{[](double) { return true; }, "a number with |g| <= 0.9999"};

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

// Made unit length where it can be (check_scene refuses one that cannot).
Vec3 read_direction(const json& v, const std::string& path) {
  Vec3 d = read_vec3(v, path);
  Vec3 unit = d;
  return make_unit(unit) ? unit : d;
}

// A colour-like quantity: one number for all channels or an [r, g, b] array, each checked.
Rgb read_color(const json& v, const std::string& path, Check check) {
  if (v.is_number()) return Rgb(read_number(v, path, check));
  if (!v.is_array() || v.size() != 3)
    throw Error(path, text(v), std::string(check.expected) + ", or an [r, g, b] array of such numbers");
  Rgb out;
  for (int i = 0; i < 3; ++i) out[i] = read_number(v[i], index_path(path, i), check);
  return out;
}

std::string read_string(const json& v, const std::string& path, const std::string& expected) {
  if (!v.is_string() || v.get_ref<const std::string&>().empty()) throw Error(path, text(v), expected);
  return v.get<std::string>();
}

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
  std::string type(std::initializer_list<std::string_view> types, const char* fallback = nullptr,
                   const std::vector<std::string>& more = {}) const {
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
    return read_color(need(key, std::string(check.expected) + ", or an [r, g, b] array of such numbers"), at(key),
                      check);
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

Camera read_camera(const Object& o) {
  Camera c;
  std::string type = o.type({"pinhole", "orthographic"}, "pinhole");
  // Each projection's own size field only: "height" on a pinhole camera is a likely mix-up with
  // height_px, and silently ignoring it would hide that.
  if (type == "pinhole") {
    o.allow({"type", "position", "look_at", "up", "fov_y_deg", "width_px", "height_px"});
    c.type = Camera::Type::pinhole;
    c.fov_y_deg = o.number("fov_y_deg", 40.0, kFinite);
  } else {
    o.allow({"type", "position", "look_at", "up", "height", "width_px", "height_px"});
    c.type = Camera::Type::orthographic;
    c.height = o.number("height", 2.0, kFinite);
  }
  c.position = o.vec3("position");
  c.look_at = o.vec3("look_at");
  c.up = o.vec3("up", Vec3(0.0, 1.0, 0.0));
  c.width_px = o.integer("width_px", 64, 1, kMaxImagePx);
  c.height_px = o.integer("height_px", 64, 1, kMaxImagePx);
  if (Vec3 up = c.up; make_unit(up)) c.up = up;
  return c;
}

Aabb read_bounds(const json& v, const std::string& path) {
  const char* expected = "[[x0, y0, z0], [x1, y1, z1]] with x0 < x1, y0 < y1 and z0 < z1";
  if (!v.is_array() || v.size() != 2) throw Error(path, text(v), expected);
  Aabb box;
  box.lo = read_vec3(v[0], index_path(path, 0));
  box.hi = read_vec3(v[1], index_path(path, 1));
  for (int a = 0; a < 3; ++a) {
    if (box.lo[a] < box.hi[a]) continue;
    const std::string axis(1, "xyz"[a]);
    throw Error(path, text(v),
                std::string(expected) + "; " + axis + "0 = " + to_text(box.lo[a]) + " is not below " + axis + "1 = " +
                    to_text(box.hi[a]));
  }
  return box;
}

// The existing file o.file names, relative to the scene's folder, as an absolute path (so that
// messages say exactly where Haze looked).
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

GridDensity read_grid(const Object& o, const fs::path& base_dir) {
  GridDensity grid;
  const std::string res_path = o.at("resolution");
  const std::string res_expected = "[nx, ny, nz], integers in [1, " + std::to_string(kMaxGridAxis) + "]";
  const json& res = o.need("resolution", res_expected);
  if (!res.is_array() || res.size() != 3) throw Error(res_path, text(res), res_expected);
  std::uint64_t cells = 1;
  for (std::size_t i = 0; i < 3; ++i) {
    grid.resolution[i] = read_int(res[i], index_path(res_path, i), 1, kMaxGridAxis);
    cells *= static_cast<std::uint64_t>(grid.resolution[i]);
  }
  if (cells > kMaxGridCells)
    throw Error(res_path, text(res), "at most " + std::to_string(kMaxGridCells) + " cells in all (nx * ny * nz)");

  const std::string file_path = o.at("file");
  const char* file_expected = "a float32 little-endian file name (relative to the scene file's folder)";
  const fs::path file = existing_file(o, base_dir, file_expected);
  std::error_code ec;
  const std::uint64_t expected_bytes = cells * 4;
  const std::uint64_t actual_bytes = fs::file_size(file, ec);
  if (ec) throw Error(file_path, file.string(), "a readable file (" + ec.message() + ")");
  if (actual_bytes != expected_bytes)
    throw Error(file_path, file.string() + " of " + std::to_string(actual_bytes) + " bytes",
                std::to_string(expected_bytes) + " bytes (nx * ny * nz * 4 = " + std::to_string(grid.resolution[0]) +
                    " * " + std::to_string(grid.resolution[1]) + " * " + std::to_string(grid.resolution[2]) +
                    " * 4)");

  try {
    grid.values.resize(static_cast<std::size_t>(cells));
  } catch (const std::bad_alloc&) {
    throw Error(file_path, file.string(), "a grid that fits in memory (" + std::to_string(expected_bytes) + " bytes)");
  }
  std::ifstream in(file, std::ios::binary);
  in.read(reinterpret_cast<char*>(grid.values.data()), static_cast<std::streamsize>(expected_bytes));
  if (!in) throw Error(file_path, file.string(), "a readable file of " + std::to_string(expected_bytes) + " bytes");
  if constexpr (std::endian::native == std::endian::big) {
    for (auto& v : grid.values) {
      auto bits = std::bit_cast<std::uint32_t>(v);
      bits = (bits >> 24) | ((bits >> 8) & 0xff00u) | ((bits << 8) & 0xff0000u) | (bits << 24);
      v = std::bit_cast<float>(bits);
    }
  }
  return grid;
}

struct MediumDensityRegistry {
  std::mutex mutex;
  std::map<std::string, MediumDensityReader> readers;
};
MediumDensityRegistry& medium_densities() {
  static MediumDensityRegistry instance;
  return instance;
}

Density read_density(const json& j, const std::string& path, bool bounded, const fs::path& base_dir) {
  const Object o(j, path);
  std::vector<std::string> modules;
  MediumDensityReader module_reader;
  {
    std::lock_guard lock(medium_densities().mutex);
    for (const auto& [name, reader] : medium_densities().readers) {
      modules.push_back(name);
      if (const json* t = o.find("type"); t && t->is_string() && t->get_ref<const std::string&>() == name) module_reader = reader;
    }
  }
  std::string type = o.type({"constant", "rbf", "grid"}, nullptr, modules);
  if (module_reader) {
    if (bounded)
      throw Error("medium.bounds", "given with a density of type \"" + type + "\"",
                  "no bounds: the " + type + " data places the medium in the world itself");
    return module_reader(j, path, base_dir);
  }
  if (type == "constant") {
    o.allow({"type", "value"});
    return ConstantDensity{o.number("value", 1.0, kFinite)};
  }
  if (type == "grid") {
    o.allow({"type", "resolution", "file"});
    // The grid's cells span the medium's bounds, so without them it has no place in the world.
    if (!bounded) throw Error("medium.bounds", "missing", "[[x0, y0, z0], [x1, y1, z1]]: a grid density needs them");
    return read_grid(o, base_dir);
  }
  o.allow({"type", "blobs"});
  const char* blobs_expected = "a non-empty array of {\"center\", \"weight\", \"sharpness\"} objects";
  const json& blobs = o.need("blobs", blobs_expected);
  if (!blobs.is_array() || blobs.empty()) throw Error(o.at("blobs"), text(blobs), blobs_expected);
  RbfDensity rbf;
  for (std::size_t i = 0; i < blobs.size(); ++i) {
    Object b(blobs[i], index_path(o.at("blobs"), i));
    b.allow({"center", "weight", "sharpness"});
    RbfBlob blob;
    blob.center = b.vec3("center");
    blob.weight = b.number("weight", 1.0, kFinite);
    blob.sharpness = b.number("sharpness", 1.0, kFinite);
    rbf.blobs.push_back(blob);
  }
  return rbf;
}

// Builds with a PhaseFunction constructor; its errors name the bare parameter ("g"), so they are
// rethrown under the full path ("medium.phase.g").
template <class Make>
PhaseFunction make_phase(const Object& o, Make make) {
  try {
    return make();
  } catch (const Error& e) {
    throw Error(o.at(e.field()), e.value(), e.expected());
  }
}

PhaseFunction read_phase(const Object& o) {
  std::string type = o.type({"isotropic", "hg", "rayleigh", "cornette_shanks", "double_hg", "tabulated"});
  if (type == "isotropic" || type == "rayleigh") {
    o.allow({"type"});
    return type == "isotropic" ? PhaseFunction::isotropic() : PhaseFunction::rayleigh();
  }
  if (type == "hg" || type == "cornette_shanks") {
    o.allow({"type", "g"});
    double g = o.number("g", kG);
    return make_phase(o, [&] {
      return type == "hg" ? PhaseFunction::henyey_greenstein(g) : PhaseFunction::cornette_shanks(g);
    });
  }
  if (type == "double_hg") {
    o.allow({"type", "g1", "g2", "w"});
    double g1 = o.number("g1", kG), g2 = o.number("g2", kG);
    double w = o.number("w", {[](double) { return true; }, "a lobe weight in [0, 1]"});
    return make_phase(o, [&] { return PhaseFunction::double_hg(g1, g2, w); });
  }
  o.allow({"type", "values"});
  const char* expected = "an array of at least 2 numbers >= 0 over mu in [-1, 1], evenly spaced";
  const json& values = o.need("values", expected);
  if (!values.is_array()) throw Error(o.at("values"), text(values), expected);
  std::vector<double> table;
  for (std::size_t i = 0; i < values.size(); ++i)
    table.push_back(read_number(values[i], index_path(o.at("values"), i), kFinite));
  return make_phase(o, [&] { return PhaseFunction::tabulated(std::move(table)); });
}

// A grid named by an emission block: another grid of the density's data (a vdb density's file).
std::shared_ptr<const DensityField> sibling_grid(const Object& o, const Density& density) {
  const std::string path = o.at("grid");
  const std::string name = read_string(*o.find("grid"), path, "a grid name of the density's file (\"flame\", \"temperature\")");
  const auto* field = std::get_if<FieldDensity>(&density);
  if (!field || !field->field)
    throw Error(path, "\"" + name + "\"", "no grid: the density has no file of grids (a vdb density's has; without a grid, emission follows the density)");
  return field->field->sibling(name, path);
}

// The medium's (or a particle set's) `emission` and `blackbody` blocks.
Emission read_emission(const Object& medium, const Density& density) {
  Emission e;
  if (const json* j = medium.find("emission")) {
    const Object o(*j, medium.at("emission"));
    o.allow({"strength", "color", "grid"});
    e.strength = o.number("strength", 1.0, kFinite);
    e.color = o.color("color", Rgb(1.0), kFinite);
    if (o.find("grid")) e.grid = sibling_grid(o, density);
  }
  if (const json* j = medium.find("blackbody")) {
    const Object o(*j, medium.at("blackbody"));
    o.allow({"intensity", "tint", "temperature", "grid"});
    e.blackbody_intensity = o.number("intensity", 1.0, kFinite);
    e.blackbody_tint = o.color("tint", Rgb(1.0), kFinite);
    e.temperature = o.number("temperature", 1000.0, kFinite);
    if (o.find("grid")) e.temperature_grid = sibling_grid(o, density);
  }
  return e;
}

MediumDesc read_medium(const Object& o, const fs::path& base_dir) {
  o.allow({"bounds", "density", "sigma_t", "albedo", "phase", "emission", "blackbody"});
  MediumDesc m;
  if (const json* b = o.find("bounds")) m.bounds = read_bounds(*b, o.at("bounds"));
  m.density = read_density(o.need("density", "a density object with a \"type\""), o.at("density"), m.bounds.bounded(), base_dir);
  m.sigma_t = o.color("sigma_t", kFinite);
  m.albedo = o.color("albedo", Rgb(0.8), kFinite);
  if (const json* p = o.find("phase")) m.phase = read_phase(Object(*p, o.at("phase")));
  m.emission = read_emission(o, m.density);
  return m;
}

Light read_light(const Object& o) {
  std::string type = o.type({"point", "spot", "directional", "sky"});
  if (type == "point") {
    o.allow({"type", "position", "intensity"});
    return PointLight{o.vec3("position"), o.color("intensity", kFinite)};
  }
  if (type == "spot") {
    o.allow({"type", "position", "direction", "intensity", "exponent", "cone_deg"});
    SpotLight s;
    s.position = o.vec3("position");
    s.direction = o.direction("direction");
    s.intensity = o.color("intensity", kFinite);
    s.exponent = o.number("exponent", 1.0, kFinite);
    s.cone_deg = o.number("cone_deg", 45.0, kFinite);
    return s;
  }
  if (type == "directional") {
    o.allow({"type", "direction", "irradiance"});
    return DirectionalLight{o.direction("direction"), o.color("irradiance", kFinite)};
  }
  o.allow({"type", "radiance"});
  return SkyLight{o.color("radiance", kFinite)};
}

// A mesh's placement: {"translate": [x, y, z], "rotate_deg": [x, y, z], "scale": s or [x, y, z]}
// (scale, then rotations about x, y and z, then translation), or {"matrix": 16 numbers, row-major,
// the last row 0 0 0 1}.
glm::dmat4 read_transform(const Object& o) {
  if (const json* m = o.find("matrix")) {
    o.allow({"matrix"});
    const char* expected = "16 finite numbers, a 4 x 4 affine matrix row by row (last row 0, 0, 0, 1)";
    if (!m->is_array() || m->size() != 16) throw Error(o.at("matrix"), text(*m), expected);
    glm::dmat4 out(1.0);
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) out[c][r] = read_number((*m)[static_cast<size_t>(4 * r + c)], index_path(o.at("matrix"), static_cast<size_t>(4 * r + c)), kFinite);
    if (out[0][3] != 0.0 || out[1][3] != 0.0 || out[2][3] != 0.0 || out[3][3] != 1.0) throw Error(o.at("matrix"), text(*m), expected);
    return out;
  }
  o.allow({"translate", "rotate_deg", "scale"});
  Vec3 scale(1.0);
  if (const json* v = o.find("scale")) {
    const char* expected = "a number > 0, or an [x, y, z] array of such numbers";
    scale = v->is_array() ? read_vec3(*v, o.at("scale")) : Vec3(read_number(*v, o.at("scale"), {[](double x) { return x > 0.0; }, expected}));
    if (!(scale.x > 0.0 && scale.y > 0.0 && scale.z > 0.0)) throw Error(o.at("scale"), text(*v), expected);
  }
  return placement(o.vec3("translate", Vec3(0.0)), o.vec3("rotate_deg", Vec3(0.0)), scale);
}

Surface read_surface(const Object& o, const fs::path& base_dir) {
  std::string type = o.type({"plane", "sphere", "mesh"});
  Surface s;
  if (type == "plane") {
    o.allow({"type", "point", "normal", "kd", "ks", "shininess"});
    s.shape = Plane{o.vec3("point"), o.direction("normal")};
  } else if (type == "sphere") {
    o.allow({"type", "center", "radius", "kd", "ks", "shininess"});
    s.shape = Sphere{o.vec3("center"), o.number("radius", kFinite)};
  } else {
    o.allow({"type", "file", "transform", "kd", "ks", "shininess", "shaded"});
    const fs::path file = existing_file(o, base_dir, "an OBJ file name (relative to the scene file's folder)");
    glm::dmat4 transform(1.0);
    if (const json* t = o.find("transform")) transform = read_transform(Object(*t, o.at("transform")));
    s.shape = Mesh{TriangleMesh::load_obj(file, transform, o.at("file"))};
    if (const json* shaded = o.find("shaded")) {
      if (!shaded->is_boolean()) throw Error(o.at("shaded"), text(*shaded), "true or false");
      if (!shaded->get<bool>()) {
        // The host shades it: black to Haze (surface.h).
        if (o.find("kd") || o.find("ks")) throw Error(o.at(o.find("kd") ? "kd" : "ks"), "given with \"shaded\": false", "no BRDF for a surface the host shades");
        s.kd = s.ks = Rgb(0.0);
        return s;
      }
    }
  }
  s.kd = o.color("kd", Rgb(0.5), kFinite);
  s.ks = o.color("ks", Rgb(0.0), kFinite);
  s.shininess = o.number("shininess", 1.0, kFinite);
  return s;
}

template <class T, class Read>
std::vector<T> read_array(const Object& top, const char* key, Read read) {
  std::vector<T> out;
  const json* v = top.find(key);
  if (!v) return out;
  if (!v->is_array()) throw Error(top.at(key), text(*v), "an array [...] of objects");
  for (std::size_t i = 0; i < v->size(); ++i) out.push_back(read(Object((*v)[i], index_path(top.at(key), i))));
  return out;
}

constexpr std::string_view kSceneFields[] = {"camera", "medium", "lights", "surfaces", "background", "method"};

struct DensityRegistry {
  std::mutex mutex;
  std::map<std::string, DensityReader> readers;
};
DensityRegistry& densities() {
  static DensityRegistry instance;
  return instance;
}

Scene parse(const json& j, const fs::path& base_dir) {
  Object top(j, "");
  const std::vector<std::string> types = registered_densities();
  for (const auto& [key, value] : j.items()) {
    if (std::find(std::begin(kSceneFields), std::end(kSceneFields), key) != std::end(kSceneFields)) continue;
    if (std::find(types.begin(), types.end(), key) != types.end()) continue;
    std::string fields;
    for (std::string_view f : kSceneFields) fields += (fields.empty() ? "" : ", ") + std::string(f);
    for (const std::string& t : types) fields += ", " + t;
    throw Error(key, "unknown field \"" + key + "\"",
                "a field of the scene: " + fields + ", or a density type a module registers (haze::register_all() registers every one built, haze::particles::register_methods() particles)");
  }
  Scene scene;
  scene.directory = base_dir;
  scene.camera = read_camera(Object(top.need("camera", "a camera object"), "camera"));
  if (const json* m = top.find("medium")) scene.medium = read_medium(Object(*m, "medium"), base_dir);
  for (const std::string& type : types) {
    const json* block = top.find(type.c_str());
    if (!block) continue;
    if (scene.medium) throw Error(type, "given with a medium", "one of `medium` and `" + type + "`: a scene has one medium");
    DensityReader reader;
    {
      std::lock_guard lock(densities().mutex);
      reader = densities().readers.at(type);
    }
    scene.medium = reader(*block, type, base_dir);
  }
  scene.lights = read_array<Light>(top, "lights", read_light);
  scene.surfaces = read_array<Surface>(top, "surfaces", [&](const Object& o) { return read_surface(o, base_dir); });
  scene.background = top.color("background", Rgb(0.0), kFinite);
  if (const json* m = top.find("method")) {
    Object method(*m, "method");
    read_string(method.need("name", "a non-empty method name"), "method.name", "a non-empty method name");
    scene.method = *m;
  }
  return scene;
}

}  // namespace

void register_density(const std::string& type, DensityReader reader) {
  if (type.empty() || !reader || std::find(std::begin(kSceneFields), std::end(kSceneFields), type) != std::end(kSceneFields))
    throw Error("density.type", "\"" + type + "\"", "a name no scene field has, and a reader");
  std::lock_guard lock(densities().mutex);
  densities().readers[type] = std::move(reader);
}

void register_medium_density(const std::string& type, MediumDensityReader reader) {
  if (type.empty() || !reader || type == "constant" || type == "rbf" || type == "grid")
    throw Error("medium.density.type", "\"" + type + "\"", "a name no built-in density type has, and a reader");
  std::lock_guard lock(medium_densities().mutex);
  medium_densities().readers[type] = std::move(reader);
}

std::vector<std::string> registered_densities() {
  std::lock_guard lock(densities().mutex);
  std::vector<std::string> out;
  for (const auto& [type, reader] : densities().readers) out.push_back(type);
  return out;
}

MaterialDesc read_material(const nlohmann::json& j, const std::string& path) {
  const Object o(j, path);
  MaterialDesc m;
  m.sigma_t = o.color("sigma_t", kFinite);
  m.albedo = o.color("albedo", Rgb(0.8), kFinite);
  if (const json* p = o.find("phase")) m.phase = read_phase(Object(*p, o.at("phase")));
  return m;
}

Emission read_emission(const nlohmann::json& j, const std::string& path, const Density& density) { return read_emission(Object(j, path), density); }

namespace scene_fields {

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
  return haze::existing_file(Object(j, path), directory, expected);
}

}  // namespace scene_fields

Scene Scene::from_json(const nlohmann::json& json, const std::filesystem::path& base_dir) {
  try {
    Scene scene = parse(json, base_dir);
    check_scene(scene);
    return scene;
  } catch (const nlohmann::json::exception& e) {
    // The readers check types before every access, so this is a bug; still never let it escape raw.
    throw Error(std::string("scene: unexpected JSON error: ") + e.what());
  }
}

namespace {

// The scene file's JSON, checked as it is parsed (nlohmann's parser callback): arrays and objects
// nested at most kMaxJsonDepth deep (a million-deep file would overflow a recursive reader), and no
// key twice in one object (nlohmann keeps the last silently). Errors name the JSON path.
constexpr std::size_t kMaxJsonDepth = 256;
struct JsonChecks {
  struct Level {
    bool array = false;
    long index = -1;      // an array's element being read
    std::string key;      // an object's key being read
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

Scene Scene::load(const std::filesystem::path& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw Error(path.string(), "missing", "an existing scene file");
  std::ifstream in(path, std::ios::binary);
  std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) throw Error(path.string(), "unreadable", "a readable scene file");

  nlohmann::json j;
  // Line and column of byte `pos` (0-based) of the file.
  auto place = [&](std::size_t pos) {
    pos = std::min(pos, content.size());
    const std::string_view head = std::string_view(content).substr(0, pos);
    const std::size_t last_newline = head.rfind('\n');
    return "line " + std::to_string(1 + std::count(head.begin(), head.end(), '\n')) + ", column " +
           std::to_string(pos - (last_newline == std::string_view::npos ? 0 : last_newline + 1) + 1);
  };
  try {
    j = nlohmann::json::parse(content, JsonChecks{path.string()});
  } catch (const nlohmann::json::out_of_range& e) {
    // A number beyond a double's range ("number overflow parsing '1e999'"): where it is.
    std::string detail = e.what();
    const std::size_t open = detail.find('\''), close = detail.rfind('\'');
    const std::string token = open != std::string::npos && close > open ? detail.substr(open + 1, close - open - 1) : std::string();
    const std::size_t at = token.empty() ? std::string::npos : content.find(token);
    throw Error(path.string(), (at == std::string::npos ? std::string() : "at " + place(at) + ": ") + "the number " + token,
                "numbers within a double's range (up to about 1.8e308)");
  } catch (const nlohmann::json::parse_error& e) {
    // Drop nlohmann's "[json.exception.parse_error.101] " tag: the rest is the useful part.
    std::string detail = e.what();
    if (auto tag_end = detail.find("] "); detail.starts_with("[json.exception") && tag_end != std::string::npos)
      detail.erase(0, tag_end + 2);
    // nlohmann's byte is 1-based: the character where parsing failed.
    throw Error(path.string(), "invalid JSON at " + place(e.byte > 0 ? e.byte - 1 : 0) + " (byte " + std::to_string(e.byte) + ")",
                "valid JSON (" + detail + ")");
  }
  fs::path base = path.parent_path();
  return from_json(j, base.empty() ? fs::path(".") : base);
}

}  // namespace haze
