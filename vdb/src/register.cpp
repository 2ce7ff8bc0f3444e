// Density type "vdb" of a scene's medium: `{"type": "vdb", "file": "smoke.vdb", "grid": "density",
// "grid_resolution": n}`, the file relative to the scene's folder.
#include <haze/core/error.h>
#include <haze/core/scene.h>
#include <haze/vdb/vdb.h>

namespace haze::vdb {
namespace {

std::string shortened(const nlohmann::json& v) {
  std::string s = v.dump();
  return s.size() > 80 ? s.substr(0, 77) + "..." : s;
}

Density read_vdb(const nlohmann::json& j, const std::string& path, const std::filesystem::path& directory) {
  for (const auto& [key, value] : j.items())
    if (key != "type" && key != "file" && key != "grid" && key != "grid_resolution")
      throw Error(path + "." + key, "unknown field \"" + key + "\"", "a field of " + path + " (type \"vdb\"): type, file, grid, grid_resolution");
  const char* file_expected = "a .vdb or .nvdb file name (relative to the scene file's folder)";
  const auto file_it = j.find("file");
  if (file_it == j.end()) throw Error(path + ".file", "missing", file_expected);
  if (!file_it->is_string() || file_it->get_ref<const std::string&>().empty()) throw Error(path + ".file", shortened(*file_it), file_expected);
  std::filesystem::path file = file_it->get<std::string>();
  if (file.is_relative()) file = directory / file;
  std::error_code ec;
  if (auto absolute = std::filesystem::absolute(file, ec); !ec) file = absolute.lexically_normal();
  if (!std::filesystem::is_regular_file(file, ec))
    throw Error(path + ".file", shortened(*file_it) + " (resolved to " + file.string() + ")", "an existing file, but there is none at that path");

  std::string grid = "density";
  if (const auto it = j.find("grid"); it != j.end()) {
    if (!it->is_string() || it->get_ref<const std::string&>().empty()) throw Error(path + ".grid", shortened(*it), "a grid name (\"density\")");
    grid = it->get<std::string>();
  }
  int resolution = 0;
  if (const auto it = j.find("grid_resolution"); it != j.end()) {
    if (!it->is_number_integer() || it->get<long long>() < 2 || it->get<long long>() > 1024)
      throw Error(path + ".grid_resolution", shortened(*it), "an integer in [2, 1024]: the grid methods' cells along the longest side");
    resolution = it->get<int>();
  }
  return volume_density(VolumeField::read(file, grid, path), resolution);
}

}  // namespace

void register_readers() { register_medium_density("vdb", read_vdb); }

}  // namespace haze::vdb
