#include <haze/core/error.h>
#include <haze/grids/grid.h>

namespace haze::grids {

DenseGrid::DenseGrid(std::array<int, 3> resolution, const Aabb& bounds) : resolution_(resolution), bounds_(bounds) {
  for (int a = 0; a < 3; ++a)
    if (resolution[static_cast<size_t>(a)] < 1)
      throw Error("resolution[" + std::to_string(a) + "]", to_text(resolution[static_cast<size_t>(a)]), "an integer >= 1");
  if (!bounds.bounded() || !(bounds.hi.x > bounds.lo.x && bounds.hi.y > bounds.lo.y && bounds.hi.z > bounds.lo.z))
    throw Error("bounds", "empty or unbounded", "finite bounds with lo < hi on every axis");
  double cells = 1.0 * resolution[0] * resolution[1] * resolution[2];
  if (cells > 2147483648.0) throw Error("resolution", to_text(cells) + " cells", "at most 2^31 cells");
  values_.assign(static_cast<size_t>(cells), 0.0f);
}

BrickGrid::BrickGrid(const DenseGrid& grid, int brick_size)
    : resolution_(grid.resolution()), bounds_(grid.bounds()), brick_(brick_size) {
  if (brick_size < 1 || brick_size > 64) throw Error("brick_size", to_text(brick_size), "an integer in [1, 64]");
  for (int a = 0; a < 3; ++a) bricks_[static_cast<size_t>(a)] = (resolution_[static_cast<size_t>(a)] + brick_ - 1) / brick_;
  size_t brick_cells = static_cast<size_t>(brick_) * static_cast<size_t>(brick_) * static_cast<size_t>(brick_);
  values_.assign(brick_cells * static_cast<size_t>(bricks_[0]) * static_cast<size_t>(bricks_[1]) * static_cast<size_t>(bricks_[2]), 0.0f);
}

size_t BrickGrid::index(int i, int j, int k) const {
  const size_t b = static_cast<size_t>(brick_);
  size_t brick = (static_cast<size_t>(k / brick_) * static_cast<size_t>(bricks_[1]) + static_cast<size_t>(j / brick_)) *
                     static_cast<size_t>(bricks_[0]) +
                 static_cast<size_t>(i / brick_);
  size_t local = (static_cast<size_t>(k % brick_) * b + static_cast<size_t>(j % brick_)) * b + static_cast<size_t>(i % brick_);
  return brick * b * b * b + local;
}

BrickGrid BrickGrid::from_dense(const DenseGrid& grid, int brick_size) {
  BrickGrid out(grid, brick_size);
  const auto& r = grid.resolution();
  for (int k = 0; k < r[2]; ++k)
    for (int j = 0; j < r[1]; ++j)
      for (int i = 0; i < r[0]; ++i) out.values_[out.index(i, j, k)] = grid.at(i, j, k);
  return out;
}

DenseGrid BrickGrid::to_dense() const {
  DenseGrid out(resolution_, bounds_);
  for (int k = 0; k < resolution_[2]; ++k)
    for (int j = 0; j < resolution_[1]; ++j)
      for (int i = 0; i < resolution_[0]; ++i) out.at(i, j, k) = at(i, j, k);
  return out;
}

}  // namespace haze::grids
