// VolumeField::read: a float grid from an OpenVDB or NanoVDB file, checked, its maxima blocked and
// its data handed to NanoVDB for sampling (an OpenVDB grid converted, a NanoVDB grid as read).
// Every failure is a haze::Error naming the file and grid.
#include "checked_read.h"
#include "volume_data.h"

#include <haze/core/error.h>

#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/openvdb.h>

#include <cmath>

namespace haze::vdb {
namespace {

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// The world positions of the voxel centres: index_to_world (column i the world step of index axis
// i), its inverse, and the voxel size along each axis.
void set_transform(const glm::dmat4& index_to_world, const Where& at, VolumeField::Data& d) {
  d.index_to_world = index_to_world;
  const double det = glm::determinant(glm::dmat3(d.index_to_world));
  if (!(std::isfinite(det) && std::abs(det) > 0.0))
    throw Error(at.field + ".grid", at.value() + " with a singular transform", "an invertible index-to-world transform");
  d.world_to_index = glm::inverse(d.index_to_world);
  for (int a = 0; a < 3; ++a) d.info.voxel_size[a] = glm::length(glm::dvec3(d.index_to_world[a]));
}

// OpenVDB's row-vector Mat4: world_j = sum_i index_i m[i][j] + m[3][j].
glm::dmat4 index_to_world(const openvdb::FloatGrid& grid, const Where& at) {
  const openvdb::math::Transform& t = grid.transform();
  if (!t.isLinear())
    throw Error(at.field + ".grid", at.value() + " with a " + t.mapType() + " transform", "an affine index-to-world transform");
  const openvdb::math::Mat4d m = t.baseMap()->getAffineMap()->getMat4();
  glm::dmat4 out(1.0);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) out[i][j] = m[i][j];
  return out;
}

// NanoVDB's map: world_i = sum_j mat[3 i + j] index_j + vec[i] (nanovdb::matMult).
glm::dmat4 index_to_world(const nanovdb::NanoGrid<float>& grid) {
  const nanovdb::Map& map = grid.data()->mMap;
  glm::dmat4 out(1.0);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) out[j][i] = map.mMatD[3 * i + j];
    out[3][i] = map.mVecD[i];
  }
  return out;
}

// One value the sampler may read: a voxel, or a tile over the voxel box [lo, hi].
struct Value {
  std::array<int64_t, 3> lo, hi;
  float v;
};

// Every non-zero value of an OpenVDB grid (leaf voxels and tiles, active or not) to fn(Value): a
// zero is finite, and holds no density.
template <class Fn>
void each_value(const openvdb::FloatGrid& grid, Fn&& fn) {
  for (auto it = grid.cbeginValueAll(); it; ++it) {
    if (*it == 0.0f) continue;
    const openvdb::CoordBBox b = it.isVoxelValue() ? openvdb::CoordBBox(it.getCoord(), it.getCoord()) : it.getBoundingBox();
    fn(Value{{b.min().x(), b.min().y(), b.min().z()}, {b.max().x(), b.max().y(), b.max().z()}, *it});
  }
}

// Every non-zero value of a NanoVDB grid whose nodes check_tree has checked, placed where NanoVDB's
// accessor finds it: by the root tiles' keys and each child's slot in its parent (not by the
// origins the nodes store, which the accessor never reads).
template <class Fn>
void each_value(const nanovdb::NanoGrid<float>& grid, Fn&& fn) {
  using Upper = nanovdb::NanoUpper<float>;
  using Lower = nanovdb::NanoLower<float>;
  using Leaf = nanovdb::NanoLeaf<float>;
  auto tile = [&](const std::array<int64_t, 3>& lo, int64_t dim, float v) {
    if (v != 0.0f) fn(Value{lo, {lo[0] + dim - 1, lo[1] + dim - 1, lo[2] + dim - 1}, v});
  };
  auto child_origin = [](const std::array<int64_t, 3>& o, uint32_t n, uint32_t log2dim, uint32_t child_total) {  // InternalNode::OffsetToLocalCoord
    const uint32_t m = n & ((1u << 2 * log2dim) - 1);
    return std::array<int64_t, 3>{o[0] + (int64_t{n >> 2 * log2dim} << child_total), o[1] + (int64_t{m >> log2dim} << child_total),
                                  o[2] + (int64_t{m & ((1u << log2dim) - 1)} << child_total)};
  };
  const auto* root = grid.tree().root().data();
  for (uint32_t i = 0; i < root->mTableSize; ++i) {
    const auto* t = root->tile(i);
    const nanovdb::Coord c = t->origin();
    const std::array<int64_t, 3> o{c[0], c[1], c[2]};
    if (!t->isChild()) {
      tile(o, Upper::DIM, t->value);
      continue;
    }
    const auto* upper = root->getChild(t)->data();
    for (uint32_t n = 0; n < Upper::SIZE; ++n) {
      const auto uo = child_origin(o, n, Upper::LOG2DIM, Lower::TOTAL);
      if (!upper->mChildMask.isOn(n)) {
        tile(uo, Lower::DIM, upper->mTable[n].value);
        continue;
      }
      const auto* lower = upper->getChild(n)->data();
      for (uint32_t k = 0; k < Lower::SIZE; ++k) {
        const auto lo = child_origin(uo, k, Lower::LOG2DIM, Leaf::TOTAL);
        if (!lower->mChildMask.isOn(k)) {
          tile(lo, Leaf::DIM, lower->mTable[k].value);
          continue;
        }
        const float* values = lower->getChild(k)->data()->mValues;
        for (uint32_t v = 0; v < Leaf::SIZE; ++v) tile(child_origin(lo, v, Leaf::LOG2DIM, 0), 1, values[v]);
      }
    }
  }
}

// Checks every non-zero value (the sampler reads them all), finds their index box and their
// maxima per 8^3 block.
template <class Grid>
void block_values(const Grid& grid, float background, const Where& at, VolumeField::Data& d) {
  if (background != 0.0f)
    throw Error(at.field + ".grid", at.value() + " with background " + to_text(background), "background 0 (a density that does not fill all space)");
  std::array<int64_t, 3> lo{}, hi{};
  bool empty = true;
  each_value(grid, [&](const Value& value) {
    const float v = value.v;
    if (!(std::isfinite(v) && v >= 0.0f))
      throw Error(at.field + ".grid",
                  to_text(v) + " at voxel (" + to_text(value.lo[0]) + ", " + to_text(value.lo[1]) + ", " + to_text(value.lo[2]) + ") of " + at.value(),
                  "finite density values >= 0");
    for (int a = 0; a < 3; ++a) {
      lo[a] = empty ? value.lo[a] : std::min(lo[a], value.lo[a]);
      hi[a] = empty ? value.hi[a] : std::max(hi[a], value.hi[a]);
    }
    empty = false;
    d.info.max_value = std::max(d.info.max_value, static_cast<double>(v));
  });
  if (empty) throw Error(at.field + ".grid", at.value() + " with no value above 0", "a grid with some density");
  // At most 2^24 voxels along each axis (OpenVDB's int32 coordinates overflow in a span past
  // 2^31), and at most 2^24 blocks (64 MB of maxima): blocks of 8^3 voxels, or 16^3, 32^3, ...
  // where large tiles make a grid span more.
  std::array<int64_t, 3> span{};
  for (int a = 0; a < 3; ++a) {
    span[a] = hi[a] - lo[a] + 1;
    if (span[a] > kMaxSpan)
      throw Error(at.field + ".grid", at.value() + " spanning " + std::to_string(span[a]) + " voxels along " + "xyz"[a],
                  "a grid whose non-zero values span at most " + std::to_string(kMaxSpan) + " voxels along each axis");
  }
  auto blocks = [&](int a) { return (span[a] + d.block - 1) / d.block; };
  while (blocks(0) * blocks(1) * blocks(2) > kMaxBlocks) d.block *= 2;
  for (int a = 0; a < 3; ++a) {
    d.info.voxels[a] = static_cast<int>(span[a]);
    d.origin[a] = static_cast<int>(lo[a]);
    d.blocks[a] = static_cast<int>(blocks(a));
  }
  d.block_max.assign(static_cast<size_t>(d.blocks[0]) * static_cast<size_t>(d.blocks[1]) * static_cast<size_t>(d.blocks[2]), 0.0f);
  each_value(grid, [&](const Value& value) {
    std::array<size_t, 3> b0{}, b1{};  // the blocks of the value's box within [lo, hi]
    for (int a = 0; a < 3; ++a) {
      b0[a] = static_cast<size_t>((std::max(value.lo[a], lo[a]) - lo[a]) / d.block);
      b1[a] = static_cast<size_t>((std::min(value.hi[a], hi[a]) - lo[a]) / d.block);
    }
    for (size_t z = b0[2]; z <= b1[2]; ++z)
      for (size_t y = b0[1]; y <= b1[1]; ++y)
        for (size_t x = b0[0]; x <= b1[0]; ++x) {
          float& m = d.block_max[(z * static_cast<size_t>(d.blocks[1]) + y) * static_cast<size_t>(d.blocks[0]) + x];
          m = std::max(m, value.v);
        }
  });
  // The world box of the index box widened by the trilinear stencil's one voxel and half a voxel
  // more: a grid method's cells, as many as the voxels across it, then sit on the voxel centres
  // (and its own trilinear interpolation gives back the trilinear field).
  d.bounds = {Vec3(kInfinity), Vec3(-kInfinity)};
  for (int c = 0; c < 8; ++c) {
    const glm::dvec4 p(static_cast<double>((c & 1) ? hi[0] : lo[0]) + ((c & 1) ? 1.5 : -1.5), static_cast<double>((c & 2) ? hi[1] : lo[1]) + ((c & 2) ? 1.5 : -1.5),
                       static_cast<double>((c & 4) ? hi[2] : lo[2]) + ((c & 4) ? 1.5 : -1.5), 1.0);
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
    if (file.extension() == ".nvdb") {
      d->handle = read_nanovdb_grid(at);
      const auto& nano = *d->handle.grid<float>();
      set_transform(index_to_world(nano), at, *d);
      block_values(nano, nano.tree().background(), at, *d);
    } else {
      const openvdb::FloatGrid::Ptr open = read_openvdb_grid(at);
      set_transform(index_to_world(*open, at), at, *d);
      block_values(*open, open->background(), at, *d);
      // Without NanoVDB's statistics, which Haze does not read (block_values has what it needs)
      // and which print a warning of their own for a tree of inactive root tiles.
      d->handle = nanovdb::openToNanoVDB(*open, nanovdb::StatsMode::Disable, nanovdb::ChecksumMode::Disable);
    }
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
