// VolumeField::read: a float grid from an OpenVDB or NanoVDB file, checked, its maxima blocked and
// its data handed to NanoVDB for sampling. Every failure is a haze::Error naming the file and grid.
#include "checked_read.h"
#include "volume_data.h"

#include <haze/core/error.h>

#include <nanovdb/util/NanoToOpenVDB.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/openvdb.h>

#include <cmath>

namespace haze::vdb {
namespace {

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// The transform as glm matrices (OpenVDB's row-vector Mat4: world_j = sum_i index_i m[i][j] + m[3][j]).
void set_transform(const openvdb::FloatGrid& grid, const Where& at, VolumeField::Data& d) {
  const openvdb::math::Transform& t = grid.transform();
  if (!t.isLinear())
    throw Error(at.field + ".grid", at.value() + " with a " + t.mapType() + " transform", "an affine index-to-world transform");
  const openvdb::math::Mat4d m = t.baseMap()->getAffineMap()->getMat4();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) d.index_to_world[i][j] = m[i][j];
  const double det = glm::determinant(glm::dmat3(d.index_to_world));
  if (!(std::isfinite(det) && std::abs(det) > 0.0))
    throw Error(at.field + ".grid", at.value() + " with a singular transform", "an invertible index-to-world transform");
  d.world_to_index = glm::inverse(d.index_to_world);
  const openvdb::Vec3d v = t.voxelSize();
  d.info.voxel_size = Vec3(v.x(), v.y(), v.z());
}

// Checks every value (leaf voxels and tiles, active or not: the sampler reads them all), finds
// the index box of the non-zero ones and their maxima per 8^3 block.
void block_values(const openvdb::FloatGrid& grid, const Where& at, VolumeField::Data& d) {
  if (grid.background() != 0.0f)
    throw Error(at.field + ".grid", at.value() + " with background " + to_text(grid.background()),
                "background 0 (a density that does not fill all space)");
  openvdb::CoordBBox box;  // empty
  for (auto it = grid.cbeginValueAll(); it; ++it) {
    const float v = *it;
    if (!(std::isfinite(v) && v >= 0.0f)) {
      const openvdb::Coord c = it.getCoord();
      throw Error(at.field + ".grid", to_text(v) + " at voxel (" + to_text(c.x()) + ", " + to_text(c.y()) + ", " + to_text(c.z()) + ") of " + at.value(),
                  "finite density values >= 0");
    }
    if (v == 0.0f) continue;
    if (it.isVoxelValue()) box.expand(it.getCoord());
    else box.expand(it.getBoundingBox());
    d.info.max_value = std::max(d.info.max_value, static_cast<double>(v));
  }
  if (box.empty()) throw Error(at.field + ".grid", at.value() + " with no value above 0", "a grid with some density");
  // At most 2^24 voxels along each axis (OpenVDB's int32 coordinates overflow in a span past
  // 2^31), and at most 2^24 blocks (64 MB of maxima): blocks of 8^3 voxels, or 16^3, 32^3, ...
  // where large tiles make a grid span more.
  const openvdb::Coord lo = box.min();
  std::array<int64_t, 3> span{};
  for (int a = 0; a < 3; ++a) {
    span[a] = int64_t{box.max()[a]} - lo[a] + 1;
    if (span[a] > kMaxSpan)
      throw Error(at.field + ".grid", at.value() + " spanning " + std::to_string(span[a]) + " voxels along " + "xyz"[a],
                  "a grid whose non-zero values span at most " + std::to_string(kMaxSpan) + " voxels along each axis");
  }
  auto blocks = [&](int a) { return (span[a] + d.block - 1) / d.block; };
  while (blocks(0) * blocks(1) * blocks(2) > kMaxBlocks) d.block *= 2;
  for (int a = 0; a < 3; ++a) {
    d.info.voxels[a] = static_cast<int>(span[a]);
    d.origin[a] = lo[a];
    d.blocks[a] = static_cast<int>(blocks(a));
  }
  d.block_max.assign(static_cast<size_t>(d.blocks[0]) * static_cast<size_t>(d.blocks[1]) * static_cast<size_t>(d.blocks[2]), 0.0f);
  auto block = [&](int x, int y, int z) -> float& {
    return d.block_max[(static_cast<size_t>(z) * static_cast<size_t>(d.blocks[1]) + static_cast<size_t>(y)) * static_cast<size_t>(d.blocks[0]) + static_cast<size_t>(x)];
  };
  for (auto it = grid.cbeginValueAll(); it; ++it) {
    const float v = *it;
    if (v == 0.0f) continue;
    openvdb::CoordBBox b = it.isVoxelValue() ? openvdb::CoordBBox(it.getCoord(), it.getCoord()) : it.getBoundingBox();
    b.intersect(box);
    std::array<int, 3> b0{}, b1{};
    for (int a = 0; a < 3; ++a) b0[a] = (b.min()[a] - lo[a]) / d.block, b1[a] = (b.max()[a] - lo[a]) / d.block;
    for (int z = b0[2]; z <= b1[2]; ++z)
      for (int y = b0[1]; y <= b1[1]; ++y)
        for (int x = b0[0]; x <= b1[0]; ++x) block(x, y, z) = std::max(block(x, y, z), v);
  }
  // The world box of the index box widened by the trilinear stencil's one voxel and half a voxel
  // more: a grid method's cells, as many as the voxels across it, then sit on the voxel centres
  // (and its own trilinear interpolation gives back the trilinear field).
  d.bounds = {Vec3(kInfinity), Vec3(-kInfinity)};
  for (int c = 0; c < 8; ++c) {
    const glm::dvec4 p((c & 1) ? box.max().x() + 1.5 : lo.x() - 1.5, (c & 2) ? box.max().y() + 1.5 : lo.y() - 1.5,
                       (c & 4) ? box.max().z() + 1.5 : lo.z() - 1.5, 1.0);
    const Vec3 w(d.index_to_world * p);
    d.bounds.lo = glm::min(d.bounds.lo, w), d.bounds.hi = glm::max(d.bounds.hi, w);
  }
  if (!(finite(d.bounds.lo) && finite(d.bounds.hi)))
    throw Error(at.field + ".grid", at.value() + " reaching " + to_text(d.bounds.hi.x), "a grid whose voxels lie at finite world positions");
}

}  // namespace

std::shared_ptr<const VolumeField> VolumeField::read(const std::filesystem::path& file, const std::string& grid, const std::string& field) {
  // (Not std::call_once: openvdb::initialize() calls it inside, and libstdc++'s does not nest.)
  [[maybe_unused]] static const bool initialized = (openvdb::initialize(), true);
  const Where at{field, file.string(), grid};
  auto d = std::make_unique<Data>();
  d->info.file = file;
  d->info.grid = grid;
  try {
    openvdb::FloatGrid::Ptr open;
    if (file.extension() == ".nvdb") {
      d->handle = read_nanovdb_grid(at);
      open = openvdb::gridPtrCast<openvdb::FloatGrid>(nanovdb::nanoToOpenVDB(d->handle));
    } else {
      open = read_openvdb_grid(at);
    }
    set_transform(*open, at, *d);
    block_values(*open, at, *d);
    if (file.extension() != ".nvdb") d->handle = nanovdb::openToNanoVDB(*open);
  } catch (const std::bad_alloc&) {
    throw Error(at.field + ".file", at.value(), "a grid that fits in memory");
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(at.field + ".file", at.value(), std::string("a grid OpenVDB can read (") + e.what() + ")");
  }
  d->grid = d->handle.grid<float>();
  if (!d->grid) throw Error(at.field + ".grid", at.value(), "a float grid (density values)");
  return std::shared_ptr<const VolumeField>(new VolumeField(std::move(d)));
}

}  // namespace haze::vdb
