// Internal: trilinear interpolation on a cell-centred grid, shared by the marcher (one stencil per
// step for the density and every light's depth) and sample_trilinear.
#pragma once

#include <haze/grids/grid.h>

#include <algorithm>
#include <cmath>

namespace haze::grids {

// Trilinear weights of one point on the volume's cell-centred grid (clamped at the edge cells),
// computed once per step and applied to the density and to every light's depth.
struct TrilinearStencil {
  size_t offset[8];
  double weight[8];

  TrilinearStencil(const DenseGrid& grid, const Vec3& p) {
    const Vec3 u = (p - grid.bounds().lo) / grid.cell_size() - 0.5;
    const auto& n = grid.resolution();
    size_t i[2][3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
      const double fl = std::floor(u[a]);
      f[a] = u[a] - fl;
      const int last = n[static_cast<size_t>(a)] - 1;
      i[0][a] = static_cast<size_t>(std::clamp(static_cast<int>(fl), 0, last));
      i[1][a] = static_cast<size_t>(std::clamp(static_cast<int>(fl) + 1, 0, last));
    }
    const auto nx = static_cast<size_t>(n[0]), nxy = nx * static_cast<size_t>(n[1]);
    for (int m = 0; m < 8; ++m) {
      const int bi = m & 1, bj = (m >> 1) & 1, bk = (m >> 2) & 1;
      offset[m] = i[bk][2] * nxy + i[bj][1] * nx + i[bi][0];
      weight[m] = (bi ? f[0] : 1 - f[0]) * (bj ? f[1] : 1 - f[1]) * (bk ? f[2] : 1 - f[2]);
    }
  }
};

}  // namespace haze::grids
