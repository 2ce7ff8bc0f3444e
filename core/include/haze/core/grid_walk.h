// A ray through a regular grid of cells, cell by cell (the 3D DDA of Amanatides and Woo 1987),
// and trilinear interpolation between cell centres: the one DDA and the one trilinear lookup of
// Haze. The majorant iterator (majorant.h), grid media (medium.h) and the grid methods' volumes
// (grids/) all use them.
#pragma once

#include <haze/core/math.h>

#include <array>
#include <cstddef>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

struct CellSegment {
  double t0, t1;
  size_t cell;  // (z * ny + y) * nx + x
};

class GridWalk {
 public:
  GridWalk() = default;
  // The ray's [t_min, t_max] clipped to bounds, through n[0] x n[1] x n[2] cells over them. A
  // single cell may have unbounded bounds.
  GridWalk(const Aabb& bounds, const std::array<int, 3>& n, const Ray& ray, double t_min, double t_max);
  // The next segment, in order along the ray; false when the ray has left the grid or t_max.
  bool next(CellSegment& segment);

 private:
  int n_[3] = {1, 1, 1};
  double t_ = 0.0, t_max_ = 0.0;
  int cell_[3] = {0, 0, 0}, step_[3] = {0, 0, 0};
  double next_t_[3] = {0, 0, 0}, delta_t_[3] = {0, 0, 0};
  bool done_ = true;
};

// The eight cells around p on a cell-centred grid over bounds (x fastest) and their trilinear
// weights, clamped to the outermost centres; computed once and applied to every grid on the same
// cells (a density and each light's depth). With `extrapolate`, a point in the half cell between
// the outermost centres and the bounds takes the line through the last two centres instead (the
// weights stay summing to 1, one of them negative): a field that varies linearly, such as the
// optical depth to a light, keeps its slope up to the faces.
struct TrilinearStencil {
  size_t offset[8];
  double weight[8];

  TrilinearStencil(const Aabb& bounds, const std::array<int, 3>& n, const Vec3& p, bool extrapolate = false);
  template <class T>
  double apply(const T* values) const {
    double v = 0.0;
    for (int m = 0; m < 8; ++m) v += weight[m] * static_cast<double>(values[offset[m]]);
    return v;
  }
};

}  // namespace haze

#pragma GCC visibility pop
