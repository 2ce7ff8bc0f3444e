// The analytic airlight over batches of view segments in float32 lanes, Highway runtime dispatch
// (the fast path of method `analytic`). ISA-free header: per-target code in analytic/src/airlight_batch-inl.h.
//
// Lanes: float32. Per segment and light: the two tails of the tabulated airlight (airlight.h) with
// bilinear lookups in its fine log table (AirlightTable::log_fine_values), float Log/Exp (Highway
// contrib, <= 4 ulp). Segments where float cannot resolve the geometry (the ray within 1e-3 d_sv
// of the light) or where the two tails nearly cancel are handed to the float64 path,
// AirlightTable::eval. Error against quadrature: below 1e-3 for HG g up to 0.9 and sigma_t up to 5
// (tests/analytic/airlight_batch_test.cpp).
#pragma once

#include <haze/analytic/airlight.h>

#include <cstddef>
#include <span>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::analytic {

// out[i] += airlight of segment i (best compiled target this CPU supports).
void add_airlight(const AirlightTable& table, const AirlightChannel& light, const SegmentBatch& batch, float* out);
// The scalar reference: the same float32 formulas, one segment at a time.
void add_airlight_reference(const AirlightTable& table, const AirlightChannel& light, const SegmentBatch& batch, float* out);

// Froxel slices: the airlight along a row of rays (lanes) to a distance d, from each ray's unit
// tails g(d) = G(d) / (sigma_s I), G(d) the airlight from distance d to infinity (airlight.h's
// near tail; the formulas of add_airlight's kernel). With [t0, t1] a ray's stretch in the medium,
// L_in(d) = sum over lights of sigma_s I (g(t0) - T(d) g(d)) at d clamped to [t0, t1] (the far
// end's tails cancel), T(d) = e^(-sigma_t (d - t0)). The ray's geometry toward each light comes in
// float32 from float64: no lane needs the float64 path.
struct TailLight {
  const float* t = nullptr;  // per ray: the light's projection along the ray, (p - o) . v
  const float* h = nullptr;  // per ray: the light's distance from the ray's line
  float sigma_t = 0.0f;
  float weight[3] = {};      // sigma_s I per channel (zero outside its channel in a coloured medium)
  const float* share = nullptr;  // per ray: the share of the light taken (null: all of it)
};
struct TailRow {
  const TailLight* lights = nullptr;
  size_t light_count = 0;
  const float* t0 = nullptr;         // per ray: where it enters the medium (0 inside)
  const float* t1 = nullptr;         // per ray: where it leaves it (+inf unbounded; t1 = t0: no medium)
  const float* whole[3] = {};        // per ray: the sum of sigma_s I g(t0) (tail_sums): L_in to the medium's end where t1 is infinite
  float sigma_t[3] = {};
  size_t count = 0;                  // rays; every array holds count rounded up to 16
};
// sums[c][i] = sum over lights of weight[c] g(d[i]) for rays i (d[i] >= 0); d and sums, like the
// row's arrays, hold count rounded up to 16 (whole vectors are read and stored).
void tail_sums(const AirlightTable& table, const TailRow& row, const float* d, float* const sums[3]);
// Slice `distance` of the row: L_in and T per ray as RGB triples into inscatter[3 i + c] and
// transmittance[3 i + c] (count rays each): before t0 L_in 0 and T 1, past t1 their values at t1.
void airlight_slice(const AirlightTable& table, const TailRow& row, float distance, float* inscatter, float* transmittance);
// Every slice of `distances` the same way, slice k into inscatter[k slice_stride + 3 i + c]
// (likewise transmittance): a vector of rays through all the slices before the next, so that a
// ray's neighbouring slices find their table values in cache.
void airlight_slices(const AirlightTable& table, const TailRow& row, std::span<const float> distances, float* inscatter, float* transmittance,
                     size_t slice_stride);
// The scalar references: the same float32 formulas, one ray at a time.
void tail_sums_reference(const AirlightTable& table, const TailRow& row, const float* d, float* const sums[3]);
void airlight_slice_reference(const AirlightTable& table, const TailRow& row, float distance, float* inscatter, float* transmittance);

}  // namespace haze::analytic

#pragma GCC visibility pop
