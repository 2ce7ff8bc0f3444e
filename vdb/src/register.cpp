// Density type "vdb" of a scene's medium: `{"type": "vdb", "file": "smoke.vdb", "grid": "density",
// "grid_resolution": n}`, the file relative to the scene's folder.
#include <haze/core/scene.h>
#include <haze/vdb/vdb.h>

namespace haze::vdb {
namespace {

Density read_vdb(const nlohmann::json& j, const std::string& path, const std::filesystem::path& directory) {
  scene_fields::allow(j, path, {"type", "file", "grid", "grid_resolution"}, "vdb");
  const std::filesystem::path file =
      scene_fields::existing_file(j, path, directory, "a .vdb or .nvdb file name (relative to the scene file's folder)");
  const std::string grid = scene_fields::text(j, path, "grid", "density", "a grid name (\"density\")");
  const int resolution = scene_fields::integer(j, path, "grid_resolution", 0, 2, 1024, "the grid methods' cells along the longest side");
  return volume_density(VolumeField::read(file, grid, path), resolution);
}

}  // namespace

void register_readers() { register_medium_density("vdb", read_vdb); }

}  // namespace haze::vdb
