// OpenVDB (.vdb) and NanoVDB (.nvdb) volumes as densities (docs/SCENES.md, "medium.density"): a float grid
// read by name, placed by its own affine index-to-world transform, kept sparse (NanoVDB) and
// sampled trilinearly, with a majorant grid over its leaves and tiles for the tracers; and a
// solution's lighting fields written back as VDB grids.
#pragma once

#include <haze/core/majorant.h>
#include <haze/core/medium.h>
#include <haze/core/method.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::vdb {

// What a volume holds, for messages and for the grid methods' resolution.
struct VolumeInfo {
  std::filesystem::path file;
  std::string grid;
  std::array<int, 3> voxels{0, 0, 0};  // the extent of its leaves and tiles, in voxels
  Vec3 voxel_size{1.0};                // world units per voxel along the grid's index axes
  double max_value = 0.0;
};

class VolumeField final : public DensityField {
 public:
  // Reads grid `grid` of `file` (.vdb through OpenVDB, .nvdb through NanoVDB). Throws haze::Error
  // naming `field` (the scene's "medium.density") with the file and grid: an unreadable file, a
  // missing grid (the message lists those there are), a value type other than float, a
  // transform that is not affine, a background other than 0, a value that is not finite or < 0.
  static std::shared_ptr<const VolumeField> read(const std::filesystem::path& file, const std::string& grid = "density",
                                                 const std::string& field = "medium.density");
  ~VolumeField() override;

  Aabb bounds() const override;
  double density(const Vec3& x) const override;
  double max_density(const Aabb& region) const override;
  double feature_size() const override;
  std::shared_ptr<const MajorantGrid> majorants() const override;
  // Grid `name` of the same file (emission's "flame", "temperature"), read as read() does.
  std::shared_ptr<const DensityField> sibling(const std::string& name, const std::string& field) const override;

  const VolumeInfo& info() const;

  struct Data;  // internal (src/volume_data.h)

 private:
  explicit VolumeField(std::unique_ptr<Data> data);
  std::unique_ptr<Data> data_;
};

// A FieldDensity of type "vdb" over the volume; the grid methods resample it at their own
// resolution, no finer than its voxels (FieldDensity::max_resolution), unless grid_resolution is set.
FieldDensity volume_density(std::shared_ptr<const VolumeField> volume, int grid_resolution = 0);

// Samples a solution's fields at the cell centres of a grid over its medium's bounds (`resolution`
// cells along the longest side, cubic cells) and writes them as OpenVDB grids of RGB (vec3s)
// with the grid's index-to-world transform: "fluence" (W/m^2, Solution::fluence) and, for each
// light with a transmittance field (point, spot, directional), "transmittance_<i>" with i its index
// in the scene's lights. Zero values are left inactive (sparse). Returns the grids' names. Throws
// haze::Error naming `fields` for an unbounded medium or a method without fields, and the file
// when it cannot be written.
std::vector<std::string> write_fields(const std::filesystem::path& file, const Solution& solution, int resolution = 64, int threads = 0);

// Registers density type "vdb" for a scene's medium (`"density": {"type": "vdb", "file": ...,
// "grid": "density", "grid_resolution": n}`, docs/SCENES.md); safe to call more than once.
void register_readers();

}  // namespace haze::vdb

#pragma GCC visibility pop
