// The analytic airlight over batches of view segments in float32 lanes, Highway runtime dispatch
// (the fast path of method `analytic`). ISA-free header: per-target code in analytic/src/airlight_batch-inl.h.
//
// Lanes: float32. Per segment and light: the two tails of the tabulated airlight (airlight.h) with
// bilinear lookups in its fine log table (AirlightTable::log_fine_pairs), float Log/Exp (Highway
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
// Every slice of `distances` (ascending) the same way, slice k into inscatter[k slice_stride + 3 i
// + c] (likewise transmittance): a vector of rays through all the slices before the next, four
// slices' tails at a time; once T g is below 1e-6 of g(t0) in every ray and channel, the further
// slices take L_in = g(t0) without their tails (both factors only fall with distance). The even
// slices (and the last) take their tails; an odd slice k takes the cubic through the tails' sums
// at k - 3, k - 1, k + 1 and k + 3 where, in every ray and channel of its vector, T(k) times the
// cubic's error as the fourth differences about it estimate it is within kSliceTolerance of the
// whole ray's in-scatter, else its own tails (log-spaced slices: past the lights and before them
// the sums vary smoothly from slice to slice; 160 x 90 x 64 froxels of 4 lights: 17% faster).
void airlight_slices(const AirlightTable& table, const TailRow& row, std::span<const float> distances, float* inscatter, float* transmittance,
                     size_t slice_stride);
// Where the far tail T g(end) exceeds this share of the near one g(t0), their difference is left
// to the float64 path. The table's errors at two points of one ray nearly cancel in it: over
// random rays and stretches (lights in an 8-unit box, sigma_t 0.26, HG g 0 / 0.5 / 0.9) the
// difference stays within 3e-4 / 2.5e-3 / 1.8e-3 of quadrature (relative) up to a ratio of 0.9
// and within 1.1e-2 (worst, g 0.5) up to 0.999; in the trade suite's fog_lamps with a sphere's
// shadows the worst pixel's L_in is 2.9e-4 off the float64 kernel's.
inline constexpr float kTailsCancel = 0.999f;
// airlight_slices' interpolated slices: the estimated error of L_in as a share of the whole ray's.
inline constexpr float kSliceTolerance = 1e-4f;

// Per-pixel layers from the tails at each ray's entry (row.whole) and its end: ray i ends at
// ends[i] (+inf: never, T = 0), sums[c][i] its tails there; L_in = max(0, whole - T sums) and
// T = e^(-sigma_t (end - t0)) as RGB triples into inscatter[3 i + c] and transmittance[3 i + c]
// (L_in 0 and T 1 where end <= t0), and redo[i] 1 where T sums exceeds kTailsCancel of whole in a
// channel, else 0. Arrays hold count rounded up to 16 (times 3 for the triples).
void layers_from_tails(const TailRow& row, const float* ends, const float* const sums[3], float* inscatter, float* transmittance, float* redo);
void layers_from_tails_reference(const TailRow& row, const float* ends, const float* const sums[3], float* inscatter, float* transmittance,
                                 float* redo);

// A row's geometry toward its lights, in float64, stored as float32 (the TailRow's inputs): ray x's
// stretch [t0[x], t1[x]] inside the box [lo, hi] (0 and 0 where it misses; t1 +inf where the box
// is unbounded that way), and per light l its projection t = (p - o) . v along the ray at
// geometry[l light_stride + x] and its distance h from the ray's line at geometry[l light_stride +
// h_offset + x]. Arrays hold count rounded up to 16.
struct RowGeometry {
  double lo[3], hi[3];
  const double* lights;  // xyz per light
  size_t light_count;
  float *t0, *t1;
  float* geometry;
  size_t light_stride, h_offset;
  float* t(size_t l) const { return geometry + l * light_stride; }
  float* h(size_t l) const { return t(l) + h_offset; }
};
// Rays from one eye: ray x leaves `origin` along normalize(a + b (px0 + x)) (Camera::row_frame),
// float64 lanes.
void row_geometry(const RowGeometry& g, const double origin[3], const double a[3], const double b[3], double px0, size_t count);
// Any rays, one at a time: the reference of row_geometry and the path of cameras without a row frame.
void row_geometry_rays(const RowGeometry& g, const Ray* rays, size_t count);

// The scalar references: the same float32 formulas, one ray at a time.
void tail_sums_reference(const AirlightTable& table, const TailRow& row, const float* d, float* const sums[3]);
void airlight_slice_reference(const AirlightTable& table, const TailRow& row, float distance, float* inscatter, float* transmittance);

}  // namespace haze::analytic

#pragma GCC visibility pop
