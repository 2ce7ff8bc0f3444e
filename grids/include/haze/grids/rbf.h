// Gaussian RBF density injected into a grid (seed 003 sec. 4.2, eq. 1-2): the extinction volume.
// rho(x) = sum_i weight_i exp(-sharpness_i^2 |x - center_i|^2), point-sampled at cell centres.
#pragma once

#include <haze/core/medium.h>
#include <haze/grids/grid.h>

#include <array>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::grids {

struct InjectionReport {
  double cutoff = 0.0;            // a blob is skipped where it contributes less than this
  double truncation_bound = 0.0;  // no cell's density is short of the full sum by more than this
  size_t cell_updates = 0;        // blob-cell contributions added
};

// The blobs must be non-empty, with finite centres, finite weight >= 0 and finite sharpness > 0
// (haze::Error names the blob and field otherwise). cutoff <= 0 picks 1e-4 of the largest weight.
// Each blob touches only the box of cells within its cutoff radius r = sqrt(ln(weight / cutoff)) /
// sharpness; a Gaussian is separable, so a blob costs one exp per row, column and slice and a
// multiply-add per cell. Threads split z-slices; every cell sums its blobs in list order, so the
// result does not depend on the thread count. Adds to the grid's values (zero it first).
InjectionReport inject_rbf(const std::vector<RbfBlob>& blobs, DenseGrid& grid, double cutoff = 0.0, int threads = 0);

// Incremental update (seed 003 table 1): recomputes from all blobs only the cells in the bricks
// (brick_size^3, aligned to the grid origin) within `region`, e.g. the union of a moved blob's old
// and new support. Returns the cells recomputed.
size_t reinject_region(const std::vector<RbfBlob>& blobs, DenseGrid& grid, const Aabb& region, double cutoff,
                       int brick_size = 8, int threads = 0);

// The cutoff inject_rbf uses for `cutoff` <= 0: 1e-4 of the largest weight (1 when all are 0);
// a positive cutoff is returned as it is.
double injection_cutoff(const std::vector<RbfBlob>& blobs, double cutoff = 0.0);

// A blob's support: the box around its centre beyond which it contributes less than cutoff.
Aabb blob_support(const RbfBlob& blob, double cutoff);

}  // namespace haze::grids

#pragma GCC visibility pop
