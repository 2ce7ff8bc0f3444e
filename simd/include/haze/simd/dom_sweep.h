// One row of the discrete-ordinate transport sweep (grids/dom.h, scheme `sweep`) for one octant's
// directions, in float32 lanes over directions with Highway runtime dispatch. ISA-free header:
// per-target code in src/dom_sweep-inl.h.
//
// Per cell c of the row, in sweep order, and direction d of the octant (step characteristics: a
// face carries its upwind cell's value; seed 000 eq. 9 with the first-collision source):
//   S_d = first[c][d] + sum_k lambda_k Q[d][k] m_in[c][k]
//   L_d = (sigma_s S_d + a_x,d x_d + a_y,d y_d + a_z,d z_d) / (sigma_t + a_x,d + a_y,d + a_z,d)
//   x_d = y_d = z_d = L_d                    (the upwind values the next cells read)
//   m_out[c][k] += sum_d Q[d][k] L_d          (eq. 10)
// A cell of zero density (sigma_s = 0) reads no source: first and m_in are not touched there.
#pragma once

#include <haze/simd/half.h>

#include <cstddef>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::simd {

// One octant's directions, padded to a multiple of 8 with directions that carry nothing (a = 0,
// a_sum = 1, lq = q = 0).
struct DomOctant {
  int directions = 0;    // P, a multiple of 8
  int terms = 0;         // N
  int terms_padded = 0;  // N rounded up to a multiple of 8
  const float* a = nullptr;   // [e * P + d]: |w_e| / h_e for e = 0, 1, 2; [3 * P + d]: their sum
  const float* lq = nullptr;  // [k * P + d]: lambda_k Q[d][k]
  const float* q = nullptr;   // [d * terms_padded + k]: Q[d][k]
};

// Cells x0 + m * step (step +1 or -1), m < count, of one grid row along x; cell0 is the linear
// index of cell x0 (a row's cells are consecutive).
struct DomRow {
  int count = 0, step = 1, x0 = 0;
  size_t cell0 = 0;
  const float* density = nullptr;  // per cell
  float sigma_t_scale = 1.0f, albedo = 0.0f;
  const float* first = nullptr;    // [cell * first_stride + d], or null
  const Half* first_half = nullptr;  // or the same in float16, times first_scale[cell]
  const float* first_scale = nullptr;
  size_t first_stride = 0;
  const float* m_in = nullptr;     // [cell * terms + k], or null
  float* m_out = nullptr;          // [cell * terms + k], added to
  float* x_run = nullptr;          // [P]: upwind values across x faces, carried along the row
  float* y_row = nullptr;          // [x * P]: across y faces, per x of the row
  float* z_row = nullptr;          // [x * P]: across z faces, per x of the row
  float* scratch = nullptr;        // P + terms_padded floats
};

void dom_sweep_row(const DomOctant& octant, const DomRow& row);
// The scalar reference: the same float32 formulas, one direction at a time.
void dom_sweep_row_reference(const DomOctant& octant, const DomRow& row);

}  // namespace haze::simd

#pragma GCC visibility pop
