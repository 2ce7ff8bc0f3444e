// One row of the discrete-ordinate transport sweep (grids/dom.h, scheme `sweep`) for one octant's
// directions, in float32 lanes over directions with Highway runtime dispatch. ISA-free header:
// per-target code in src/dom_sweep-inl.h.
//
// Per cell c of the row, in sweep order, and direction d of the octant, with x_d, y_d, z_d the
// radiance entering through the upwind faces (seed 000 eq. 9 with the first-collision source):
//   S_d = first[c][d] + sum_k lambda_k Q[d][k] m_in[c][k]
// and the cell's mean radiance L_d and the radiance leaving through its faces by one of two
// spatial schemes. Both hold the cell's balance  sum_e a_e (out_e - in_e) + sigma_t L = sigma_s S.
// - step (seed 000): every face leaves with the cell's mean (first order in the cell size),
//     L_d = (sigma_s S_d + sum_e a_e in_e) / (sigma_t + sum_e a_e),  out_e = L_d.
// - diamond (weighted diamond difference, Lewis and Miller 1984): per axis
//   L = alpha_e out_e + (1 - alpha_e) in_e, with
//     alpha_e = max(alpha(tau_e), 1 - a_e / (sigma_t + 2 sum_(f != e) a_f)),
//     alpha(tau) = (tau^2 + 2 tau + 3) / (tau^2 + 3 tau + 6),  tau_e = sigma_t / a_e,
//   the cell's optical thickness along the direction. alpha(tau) is 1/2 (the plain diamond,
//   second order) in thin cells and goes to 1 (step) in thick ones, within 0.032 of the exact 1D
//   characteristic weight 1 / (1 - e^-tau) - 1 / tau and never below 1 - 1 / tau; the second
//   bound makes every coefficient of the leaving radiance non-negative in three dimensions
//   (1 - alpha_e <= a_e / (sigma_t + sum_(f != e) a_f / alpha_f) is the condition, and
//   a_f / alpha_f <= 2 a_f), so the scheme is positive and cannot oscillate while staying
//   linear, as GMRES needs. It binds on the minor axes of oblique directions, which go toward
//   first order there (Godunov: no linear positive scheme is second order everywhere). With
//   DomRow::bounded, only the cells marked take the bound (the fix-up: a sweep with `mark` marks a
//   cell where alpha(tau) alone would send radiance below 0, and sweeps it again bounded). With
//   g_e = 1 / alpha_e and b_e = a_e g_e:
//     L_d = (sigma_s S_d + sum_e b_e in_e) / (sigma_t + sum_e b_e),  out_e = g_e L_d - (g_e - 1) in_e.
//   Divisions only (reciprocals with a Newton step in the SIMD kernel), no exponential.
//   With first_slope, the first-collision source F is linear over the cell, changing by
//   dF_e = F t_e across it along axis e in the direction of travel (t_e = slope_e sign_e, |t_e|
//   <= 2); the cell's mean then sits below the diamond's face average by
//   c_e = sigma_s dF_e / (12 (a_x + a_y + a_z) + 2 sigma_t) (in one dimension sigma_s dF / (12 a),
//   exact for a linear source in a thin cell, and sigma_s dF / (2 sigma_t), the exit face's local
//   equilibrium, in a thick one; the sum of the a_e bounds it by the time light stays in the
//   cell): L = alpha_e out_e + (1 - alpha_e) in_e - c_e, so
//     L_d = (sigma_s S_d + sum_e b_e (in_e - c_e)) / (sigma_t + sum_e b_e),
//     out_e = g_e (L_d + c_e) - (g_e - 1) in_e,
//   the cell's balance unchanged. Under a grazing sun a top cell's source is far from uniform.
// Then x_d, y_d, z_d take the leaving values (the upwind values the next cells read) and
//   m_out[c][k] += sum_d Q[d][k] L_d          (eq. 10)
// A cell of zero density (sigma_s = 0) reads no source: first and m_in are not touched there.
#pragma once

#include <haze/simd/half.h>

#include <cstddef>
#include <cstdint>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::grids {

// The diamond scheme's floor on a denominator (a cell with sigma_t = 0, a direction along a face).
inline constexpr float kDiamondTiny = 1e-30f;

// The fix-up (DomRow::mark) takes a leaving value as below 0 under -kFixUpSlack times the sum of
// the direction's entering values and mean in size: the rounding of a value that is 0 in exact
// arithmetic stays above.
inline constexpr float kFixUpSlack = 1e-5f;

// One octant's directions, padded to a multiple of 8 with directions that carry nothing (a = 0,
// a_sum = 1, pad = 1, lq = q = 0).
struct DomOctant {
  int directions = 0;    // P, a multiple of 8
  int terms = 0;         // N
  int terms_padded = 0;  // N rounded up to a multiple of 8
  // [e * P + d]: |w_e| / h_e for e = 0, 1, 2; [3 * P + d]: their sum (1 for padding); [4 * P + d]:
  // 1 for padding, else 0 (what keeps the diamond scheme's denominator from 0)
  const float* a = nullptr;
  const float* lq = nullptr;  // [k * P + d]: lambda_k Q[d][k]
  const float* q = nullptr;   // [d * terms_padded + k]: Q[d][k]
  bool diamond = false;       // the spatial scheme: weighted diamond difference, else step
  float sign[3] = {1.0f, 1.0f, 1.0f};  // the sign of the octant's directions along x, y, z
};

// Cells x0 + m * step (step +1 or -1), m < count, of one grid row along x; cell0 is the linear
// index of cell x0 (a row's cells are consecutive).
struct DomRow {
  int count = 0, step = 1, x0 = 0;
  size_t cell0 = 0;
  const float* density = nullptr;  // per cell
  float sigma_t_scale = 1.0f, albedo = 0.0f;
  const float* first = nullptr;    // [cell * first_stride + d], or null
  const simd::Half* first_half = nullptr;  // or the same in float16, times first_scale[cell]
  const float* first_scale = nullptr;
  size_t first_stride = 0;
  // Or, for directional lights (the same phase row in every cell), the source separable:
  // first[cell][d] = sum_l first_factor[cell * first_lights + l] first_rows[l * first_stride + d].
  const float* first_rows = nullptr;
  const float* first_factor = nullptr;
  int first_lights = 0;
  // Or null: [cell * 3 + e], the first-collision source's change across the cell along axis e over
  // its mean (the diamond scheme takes the source as linear over the cell; see above).
  const float* first_slope = nullptr;
  const float* m_in = nullptr;     // [cell * terms + k], or null
  float* m_out = nullptr;          // [cell * terms + k], added to
  float* x_run = nullptr;          // [P]: radiance across x faces, carried along the row
  float* y_row = nullptr;          // [x * P]: across y faces, per x of the row
  float* z_row = nullptr;          // [x * P]: across z faces, per x of the row
  float* scratch = nullptr;        // 4 P + terms_padded floats
  // Or null (every cell takes it): [cell * 8], 1 where the diamond scheme takes its positivity
  // bound, 0 where alpha(tau) alone. With `mark`, a cell at 0 whose leaving radiance would go below
  // 0 (kFixUpSlack) in some direction is set to 1 and swept again with the bound.
  std::uint8_t* bounded = nullptr;
  bool mark = false;
};

void dom_sweep_row(const DomOctant& octant, const DomRow& row);
// The scalar reference: the same float32 formulas, one direction at a time.
void dom_sweep_row_reference(const DomOctant& octant, const DomRow& row);

}  // namespace haze::grids

#pragma GCC visibility pop
