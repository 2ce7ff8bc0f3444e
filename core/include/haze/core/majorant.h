// A coarse grid of density majorants over a medium's bounds and a DDA that walks a ray through it,
// in the spirit of pbrt-v4's DDAMajorantIterator: the majorant iterator of every haze::Medium
// (Medium::majorants), which the reference path tracer walks.
#pragma once

#include <haze/core/grid_walk.h>
#include <haze/core/math.h>

#include <array>
#include <cstddef>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

struct MajorantSegment {
  double t0, t1;
  double density;  // an upper bound of the density on [t0, t1)
  size_t cell;     // the grid cell, (z * ny + y) * nx + x
};

class DensityField;

class MajorantGrid {
 public:
  // One cell for homogeneous media; `cells` per axis for heterogeneous ones.
  MajorantGrid(const DensityField& field, int cells = 16);
  // Given bounds: density[(z * n[1] + y) * n[0] + x] bounds the density over cell (x, y, z).
  MajorantGrid(const Aabb& bounds, const std::array<int, 3>& n, std::vector<double> density);

  // Walks the ray's [t_min, t_max] through the grid, segment by segment, in order.
  class Iterator {
   public:
    Iterator() = default;
    Iterator(const MajorantGrid* grid, const Ray& ray, double t_min, double t_max)
        : grid_(grid), walk_(grid->bounds_, grid->n_, ray, t_min, t_max) {}
    bool next(MajorantSegment& segment) {
      CellSegment s;
      if (!walk_.next(s)) return false;
      segment = {s.t0, s.t1, grid_->density_[s.cell], s.cell};
      return true;
    }

   private:
    const MajorantGrid* grid_ = nullptr;
    GridWalk walk_;
  };
  Iterator walk(const Ray& ray, double t_min, double t_max) const { return Iterator(this, ray, t_min, t_max); }

 private:
  Aabb bounds_;
  std::array<int, 3> n_{1, 1, 1};
  std::vector<double> density_;
};

}  // namespace haze

#pragma GCC visibility pop
