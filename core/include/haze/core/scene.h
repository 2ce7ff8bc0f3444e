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
#include <optional>
#include <string>
#include <vector>

namespace haze {

// The fields a medium and a particle set share, read with the scene's validation from the JSON
// object `j` found at `path` (e.g. "particles"); its other fields are left to the caller.
struct MaterialDesc {
  Rgb sigma_t{1.0};  // required: per unit length and unit density
  Rgb albedo{0.8};
  PhaseFunction phase;  // isotropic unless given
};
MaterialDesc read_material(const nlohmann::json& j, const std::string& path);

struct Scene {
  Camera camera;
  std::optional<MediumDesc> medium;
  nlohmann::json particles;  // kept as written until the particle module reads it
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

}  // namespace haze
