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

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::analytic {

// out[i] += airlight of segment i (best compiled target this CPU supports).
void add_airlight(const AirlightTable& table, const AirlightChannel& light, const SegmentBatch& batch, float* out);
// The scalar reference: the same float32 formulas, one segment at a time.
void add_airlight_reference(const AirlightTable& table, const AirlightChannel& light, const SegmentBatch& batch, float* out);

}  // namespace haze::analytic

#pragma GCC visibility pop
