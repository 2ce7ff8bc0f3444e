// A scene: camera, medium, lights, surfaces, background and the method to render it with, read
// from JSON (docs/SCENES.md). Every field is validated; a bad one throws haze::Error naming its
// JSON path, its value and what was expected.
#pragma once

#include <haze/core/camera.h>
#include <haze/core/light.h>
#include <haze/core/medium.h>
#include <haze/core/surface.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

// The fields a medium and a particle set share, read with the scene's validation from the JSON
// object `j` found at `path` (e.g. "particles"); its other fields are left to the caller.
struct MaterialDesc {
  Rgb sigma_t{1.0};  // required: per unit length and unit density
  Rgb albedo{0.8};
  PhaseFunction phase;  // isotropic unless given
};
MaterialDesc read_material(const nlohmann::json& j, const std::string& path);
// The `emission` and `blackbody` fields of the object `j` at `path` (a medium, a particle set):
// the medium's emission (MediumDesc::emission); their `grid`s are siblings of `density`'s field.
Emission read_emission(const nlohmann::json& j, const std::string& path, const Density& density);

// A JSON value as an error message shows it: at most 80 characters, never dumped whole (it may be
// megabytes long or nested 100,000 deep); NaN and infinities by name.
std::string json_text(const nlohmann::json& value);

// For modules reading their own blocks with the scene reader's checks and messages (each throws
// haze::Error naming path.key, the value shortened to 80 characters, and what was expected):
namespace scene_fields {
// Rejects a key of the object `j` not among `fields` (the message names the block's `type`, if any).
void allow(const nlohmann::json& j, const std::string& path, std::initializer_list<std::string_view> fields, const std::string& type = "");
// j[key], an integer in [lo, hi], or `fallback` when absent; `meaning` follows the range in messages.
int integer(const nlohmann::json& j, const std::string& path, const char* key, int fallback, int lo, int hi, const std::string& meaning = "");
// j[key], a non-empty string, or `fallback` when absent (required when fallback is empty).
std::string text(const nlohmann::json& j, const std::string& path, const char* key, const std::string& fallback, const std::string& expected);
// j.file: an existing file, relative to `directory` unless absolute, as an absolute path.
std::filesystem::path existing_file(const nlohmann::json& j, const std::string& path, const std::filesystem::path& directory,
                                    const std::string& expected);
}  // namespace scene_fields

// A density a module supplies, read from the scene's top-level block of the type's name
// ("particles": the particle module registers it): the block at `path` into a medium, whose
// density is usually the module's FieldDensity; relative file names resolve against `directory`.
// A second registration under the same type replaces the first.
using DensityReader = std::function<MediumDesc(const nlohmann::json& block, const std::string& path, const std::filesystem::path& directory)>;
void register_density(const std::string& type, DensityReader reader);
std::vector<std::string> registered_densities();

// A density type of the medium block a module supplies (`"medium": {"density": {"type": "vdb",
// ...}}`: the vdb module registers it): the density object at `path` (e.g. "medium.density") into
// a Density, usually the module's FieldDensity, which places itself in the world (the medium then
// takes no `bounds`). A second registration under the same type replaces the first.
using MediumDensityReader = std::function<Density(const nlohmann::json& density, const std::string& path, const std::filesystem::path& directory)>;
void register_medium_density(const std::string& type, MediumDensityReader reader);

struct Scene {
  Camera camera;
  // The medium: from `medium`, or from the block of a module's density type (`particles`).
  std::optional<MediumDesc> medium;
  std::filesystem::path directory = ".";  // relative file names in the scene resolve against it
  std::vector<Light> lights;
  std::vector<Surface> surfaces;
  Rgb background{0.0};
  // The "method" block: "name" and that method's settings (empty when the scene names none).
  nlohmann::json method = nlohmann::json::object();

  std::string method_name() const { return method.value("name", std::string()); }

  // Parses and validates; relative file names (grid densities) resolve against base_dir.
  static Scene from_json(const nlohmann::json& json, const std::filesystem::path& base_dir = ".");
  // Reads a file; JSON syntax errors name the file, line and column.
  static Scene load(const std::filesystem::path& path);
};

// Checks a scene however it was made (haze::prepare calls it): finite values within the limits of
// limits.h (coordinates, radiometric quantities, extinction), a camera that is not degenerate,
// non-zero directions; the medium through check_medium. Throws haze::Error naming the field as the
// JSON path would ("lights[2].position").
void check_scene(const Scene& scene);

}  // namespace haze

#pragma GCC visibility pop
