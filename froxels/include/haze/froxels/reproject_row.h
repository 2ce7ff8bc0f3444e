// The temporal froxels' reprojection (TemporalFroxels, temporal.h, splits the froxels' rows over
// threads), in float32 with Highway runtime dispatch, beside its scalar reference. ISA-free
// header: per-target code in src/reproject-inl.h. Per froxel of a row: where its point was in the
// previous frame's grid, in vectors over froxels, then the previous froxels' eight taps there as
// four-float vectors, blended into this frame's.
#pragma once

#include <haze/froxels/composite_row.h>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::froxels_detail {

// One row of froxels (slice k, row j): per column i of the row, its ray o + d u in the previous
// frame's clip space, A + d B (x, y and w), and |o + d u - previous eye|^2 = dd + d (du2 + d);
// `distance` is the slice's boundary d. inscatter and transmittance hold the row's froxels, three
// floats each, blended in place: froxel += keep (previous there - froxel), where the point was
// inside the previous frustum (clip w > 0, its column coordinates within the grid's edges).
struct ReprojectRow {
  const float *ax, *ay, *aw, *bx, *by, *bw, *dd, *du2;
  float distance, keep;
  int width;
  float* inscatter;
  float* transmittance;
};

void reproject_row(const CompositeVolume& previous, const ReprojectRow& row);
void reproject_row_reference(const CompositeVolume& previous, const ReprojectRow& row);

}  // namespace haze::froxels_detail

#pragma GCC visibility pop
