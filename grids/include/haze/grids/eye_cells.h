// Dom's moments' scattered light toward one eye, a row of cells at a time (dom::TowardEye::fill,
// the radiance per cell its froxels and per-pixel layers march), in float32 with Highway runtime
// dispatch beside its scalar reference. ISA-free header: per-target code in src/eye_cells-inl.h.
//
// Per cell x of the row, w = (x0 + x dx, dy, dz) / |.| the direction from the eye to its centre,
// (u, v) its octahedral coordinates (|u| + |v| + |w.z| = 1, the lower hemisphere folded out), c the
// in-scatter weights bilinear between the table's texel centres at (u, v):
//   out[ch][x] = scale[ch] max(0, c . m_ch(x)).
#pragma once

#include <cstddef>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::grids {

struct EyeCellsRow {
  const float* table = nullptr;  // side x side texels, v-major, `stride` floats each: `terms` weights, then zeros
  int side = 0, terms = 0, stride = 0;  // stride: terms rounded up to 16
  const float* const* moments = nullptr;  // per channel: the row's first cell's moments, cells `terms` floats apart
  size_t readable = 0;  // floats readable from each moments[ch] on (the vector path reads a cell's `stride`)
  const float* scale = nullptr;  // per channel
  int channels = 0;
  float x0 = 0.0f, dx = 0.0f;  // the first cell centre's x minus the eye's, the cells' spacing
  float dy = 0.0f, dz = 0.0f;  // the row's centres' y and z minus the eye's
  int count = 0;  // cells
  float* const* out = nullptr;  // per channel: the row's first cell
};

void eye_cells_row(const EyeCellsRow& row);
void eye_cells_row_reference(const EyeCellsRow& row);

}  // namespace haze::grids

#pragma GCC visibility pop
