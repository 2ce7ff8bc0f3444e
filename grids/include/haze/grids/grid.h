// Dense scalar grids (docs/ARCHITECTURE.md): cell-centred over an AABB, public order x fastest, then
// y, then z; float32 values. BrickGrid is the cache-blocked internal layout solvers sweep over.
#pragma once

#include <haze/core/math.h>

#include <array>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::grids {

class DenseGrid {
 public:
  // Zero-filled; throws haze::Error for a resolution entry < 1, more than 2^31 cells, or empty bounds.
  DenseGrid(std::array<int, 3> resolution, const Aabb& bounds);

  const std::array<int, 3>& resolution() const { return resolution_; }
  const Aabb& bounds() const { return bounds_; }
  size_t cell_count() const { return values_.size(); }
  Vec3 cell_size() const { return bounds_.extent() / Vec3(resolution_[0], resolution_[1], resolution_[2]); }
  Vec3 cell_center(int i, int j, int k) const { return bounds_.lo + (Vec3(i, j, k) + 0.5) * cell_size(); }

  size_t index(int i, int j, int k) const {
    return (static_cast<size_t>(k) * static_cast<size_t>(resolution_[1]) + static_cast<size_t>(j)) * static_cast<size_t>(resolution_[0]) +
           static_cast<size_t>(i);
  }
  float& at(int i, int j, int k) { return values_[index(i, j, k)]; }
  float at(int i, int j, int k) const { return values_[index(i, j, k)]; }
  std::vector<float>& values() { return values_; }
  const std::vector<float>& values() const { return values_; }

 private:
  std::array<int, 3> resolution_;
  Aabb bounds_;
  std::vector<float> values_;
};

// The same cells in B x B x B bricks (x fastest inside a brick, bricks x fastest): a sweep over a
// brick touches B^3 contiguous floats. Cells past the grid's edge in the last bricks are zero.
class BrickGrid {
 public:
  static BrickGrid from_dense(const DenseGrid& grid, int brick_size = 8);
  DenseGrid to_dense() const;

  int brick_size() const { return brick_; }
  const std::array<int, 3>& bricks() const { return bricks_; }
  float at(int i, int j, int k) const { return values_[index(i, j, k)]; }
  const std::vector<float>& values() const { return values_; }

 private:
  BrickGrid(const DenseGrid& grid, int brick_size);
  size_t index(int i, int j, int k) const;
  std::array<int, 3> resolution_, bricks_;
  Aabb bounds_;
  int brick_;
  std::vector<float> values_;
};

}  // namespace haze::grids

#pragma GCC visibility pop
