// read_grid (grid_file.h): a scene's binary grid file.
#include "grid_file.h"

#include <bit>
#include <climits>
#include <cstdint>
#include <fstream>
#include <new>

namespace haze::internal {
namespace {

constexpr int kMaxGridAxis = 16384;
// Downstream code may index a grid with int: keep nx * ny * nz within int range.
constexpr std::uint64_t kMaxGridCells = INT_MAX;

}  // namespace

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
  if (cells > kMaxGridCells) throw Error(res_path, text(res), "at most " + std::to_string(kMaxGridCells) + " cells in all (nx * ny * nz)");

  const std::string file_path = o.at("file");
  const char* file_expected = "a float32 little-endian file name (relative to the scene file's folder)";
  const fs::path file = existing_file(o, base_dir, file_expected);
  std::error_code ec;
  const std::uint64_t expected_bytes = cells * 4;
  const std::uint64_t actual_bytes = fs::file_size(file, ec);
  if (ec) throw Error(file_path, file.string(), "a readable file (" + ec.message() + ")");
  if (actual_bytes != expected_bytes)
    throw Error(file_path, file.string() + " of " + std::to_string(actual_bytes) + " bytes",
                std::to_string(expected_bytes) + " bytes (nx * ny * nz * 4 = " + std::to_string(grid.resolution[0]) + " * " +
                    std::to_string(grid.resolution[1]) + " * " + std::to_string(grid.resolution[2]) + " * 4)");

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

}  // namespace haze::internal
