// Scene files (docs/SCENES.md): the schema, read through the JSON toolkit (json_object.h) and the
// grid file reader (grid_file.h), the modules' density types (register_density,
// register_medium_density), and loading a file. Types are checked as fields are read, ranges by
// check_scene last, so that renderers can trust a Scene: a bad value throws haze::Error naming its
// JSON path, the value and what was expected.
#include "grid_file.h"
#include "json_object.h"

#include <haze/core/error.h>
#include <haze/core/scene.h>

#include <algorithm>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <map>
#include <memory>
#include <mutex>
#include <string_view>
#include <utility>

namespace haze {

using namespace internal;

namespace {

constexpr int kMaxImagePx = 16384;

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

Scene Scene::load(const std::filesystem::path& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw Error(path.string(), "missing", "an existing scene file");
  std::ifstream in(path, std::ios::binary);
  std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) throw Error(path.string(), "unreadable", "a readable scene file");

  const nlohmann::json j = parse_checked(content, path.string());
  fs::path base = path.parent_path();
  return from_json(j, base.empty() ? fs::path(".") : base);
}

}  // namespace haze
