// VolumeField: trilinear samples of the NanoVDB grid and majorants from its coarse block maxima.
#include "volume_data.h"

#include <nanovdb/util/SampleFromVoxels.h>

#include <algorithm>
#include <cmath>

namespace haze::vdb {
namespace {

// ceil(x) held to [lo, hi] before it becomes an int: x is a world length over a voxel's, which a
// sheared or very anisotropic transform makes huge (fuzz_vdb: 4.8e29), and NaN for zero over zero.
int count(double x, int lo, int hi) { return x >= hi ? hi : x > lo ? static_cast<int>(std::ceil(x)) : lo; }

}  // namespace

VolumeField::VolumeField(std::unique_ptr<Data> data) : data_(std::move(data)) {}
VolumeField::~VolumeField() = default;

Aabb VolumeField::bounds() const { return data_->bounds; }
const VolumeInfo& VolumeField::info() const { return data_->info; }

double VolumeField::feature_size() const {
  const Vec3& v = data_->info.voxel_size;
  return std::min({v.x, v.y, v.z});
}

double VolumeField::density(const Vec3& x) const {
  const glm::dvec4 p = data_->world_to_index * glm::dvec4(x, 1.0);
  if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) return 0.0;
  auto accessor = data_->grid->getAccessor();
  const nanovdb::SampleFromVoxels<decltype(accessor), 1, false> trilinear(accessor);
  // Far outside the index range NanoVDB's integer coordinates would overflow: nothing is there.
  constexpr double kFar = 1e9;
  if (std::abs(p.x) > kFar || std::abs(p.y) > kFar || std::abs(p.z) > kFar) return 0.0;
  return std::max(0.0f, trilinear(nanovdb::Vec3d(p.x, p.y, p.z)));
}

double VolumeField::max_density(const Aabb& region) const {
  const Data& d = *data_;
  const Aabb r{glm::max(region.lo, d.bounds.lo), glm::min(region.hi, d.bounds.hi)};
  if (!(r.lo.x <= r.hi.x && r.lo.y <= r.hi.y && r.lo.z <= r.hi.z)) return 0.0;
  // The region's index box (its 8 corners), widened by the trilinear stencil's one voxel.
  glm::dvec3 lo(kInfinity), hi(-kInfinity);
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1) ? r.hi.x : r.lo.x, (c & 2) ? r.hi.y : r.lo.y, (c & 4) ? r.hi.z : r.lo.z);
    const glm::dvec3 p(d.world_to_index * glm::dvec4(corner, 1.0));
    lo = glm::min(lo, p), hi = glm::max(hi, p);
  }
  std::array<int, 3> b0{}, b1{};
  for (int a = 0; a < 3; ++a) {
    const double first = std::floor((lo[a] - 1.0 - d.origin[a]) / d.block), last = std::floor((hi[a] + 1.0 - d.origin[a]) / d.block);
    if (last < 0.0 || first >= d.blocks[a]) return 0.0;
    b0[a] = static_cast<int>(std::max(first, 0.0));
    b1[a] = static_cast<int>(std::min(last, d.blocks[a] - 1.0));
  }
  float m = 0.0f;
  for (int z = b0[2]; z <= b1[2]; ++z)
    for (int y = b0[1]; y <= b1[1]; ++y) {
      const size_t row = (static_cast<size_t>(z) * static_cast<size_t>(d.blocks[1]) + static_cast<size_t>(y)) * static_cast<size_t>(d.blocks[0]);
      for (int x = b0[0]; x <= b1[0]; ++x) m = std::max(m, d.block_max[row + static_cast<size_t>(x)]);
    }
  return m;
}

std::shared_ptr<const MajorantGrid> VolumeField::majorants() const {
  // About one majorant cell per block (empty blocks give zero majorants: the tracers skip them),
  // at most kMaxMajorants (64) per axis.
  const Aabb b = data_->bounds;
  const Vec3 e = b.extent();
  std::array<int, 3> n{};
  for (int a = 0; a < 3; ++a) n[a] = count(e[a] / (kBlock * feature_size()), 1, kMaxMajorants);
  std::vector<double> m(static_cast<size_t>(n[0]) * static_cast<size_t>(n[1]) * static_cast<size_t>(n[2]));
  const Vec3 cell = e / Vec3(n[0], n[1], n[2]);
  for (int z = 0; z < n[2]; ++z)
    for (int y = 0; y < n[1]; ++y)
      for (int x = 0; x < n[0]; ++x) {
        const Vec3 lo = b.lo + Vec3(x, y, z) * cell;
        m[(static_cast<size_t>(z) * static_cast<size_t>(n[1]) + static_cast<size_t>(y)) * static_cast<size_t>(n[0]) + static_cast<size_t>(x)] =
            max_density({lo, lo + cell});
      }
  return std::make_shared<MajorantGrid>(b, n, std::move(m));
}

std::shared_ptr<const DensityField> VolumeField::sibling(const std::string& name, const std::string& field) const {
  // read() names its fields "<field>.file" and "<field>.grid": the emission block's own.
  const std::string block = field.ends_with(".grid") ? field.substr(0, field.size() - 5) : field;
  return read(data_->info.file, name, block);
}

FieldDensity volume_density(std::shared_ptr<const VolumeField> volume, int grid_resolution) {
  FieldDensity f{"vdb", volume, grid_resolution};
  if (volume) {
    const Vec3 e = volume->bounds().extent();
    f.max_resolution = count(std::max({e.x, e.y, e.z}) / volume->feature_size(), 2, static_cast<int>(kMaxSpan));
  }
  return f;
}

}  // namespace haze::vdb
