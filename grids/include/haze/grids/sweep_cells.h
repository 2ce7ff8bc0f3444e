// The short-characteristics optical-depth sweep (grids/optical_depth.h, scheme `sweep`) for a run of
// cells along x or y, in float32 lanes with Highway runtime dispatch. ISA-free header: per-target
// code in src/sweep_cells-inl.h.
//
// Per cell (cell coordinates u, cell centres at integer + 0.5; q = direction toward the light in
// cells per unit length; a its dominant axis, ties to the lower axis):
//   len   = path length toward the light inside the grid (to the light, or to the grid's face),
//   s     = layers / |q_a|, the length to the cell-centre plane `layers` layers toward the light,
//   depth = integral of the (piecewise-constant) density over the first min(s, len) of the path,
//           walked cell by cell
//         + (len - s) * mean at the landing point (bilinear in its plane)   where len > s,
//   mean  = depth / len (the cell's density where len = 0);
// s is infinite for cells within exact_radius of light_cell.
// Every cell a landing point reads must have been computed (and its mean stored) before.
#pragma once

#include <cstddef>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::grids {

struct SweepVolume {
  int n[3] = {1, 1, 1};
  float lo[3] = {0, 0, 0}, h[3] = {1, 1, 1};  // grid origin and cell size
  const float* density = nullptr;             // n[0] n[1] n[2] values, x fastest
  const float* mean = nullptr;                // the same layout: mean density of computed cells
  bool directional = false;
  float light[3] = {0, 0, 0};  // position, or (directional) the unit direction toward the light
  int layers = 4;
  // Point lights: cells within this Chebyshev distance of light_cell walk their whole path (near
  // the light a landing point could read a cell of the same pass).
  int light_cell[3] = {0, 0, 0};
  int exact_radius = -1;
};

// Cells (i, j, k) + m e_axis for m < count, axis 0 (x) or 1 (y): depth[m] and mean[m].
void sweep_cells(const SweepVolume& volume, int i, int j, int k, int axis, int count, float* depth, float* mean);
// The scalar reference: the same float32 formulas, one cell at a time.
void sweep_cells_reference(const SweepVolume& volume, int i, int j, int k, int axis, int count, float* depth, float* mean);

}  // namespace haze::grids

#pragma GCC visibility pop
