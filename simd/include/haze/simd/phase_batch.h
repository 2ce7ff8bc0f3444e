// Batched phase-function evaluation in float32 with Highway runtime dispatch. ISA-free header:
// the per-target code is in src/phase_batch-inl.h.
//
// Lanes: float32. Valid range: cos_theta in [-1, 1], |g| < 1. Maximum error against the float64
// reference rounded to float32: 8e-7 relative (a few ulps) for every analytic phase function; the
// HG denominator is formed as (1 - |g|)^2 + 2 |g| (1 - sign(g) mu), which does not cancel at the
// peak as |g| -> 1.
// Tabulated phase functions run the scalar reference on every target.
#pragma once

#include <haze/core/phase.h>

#include <cstddef>
#include <string>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::simd {

// out[i] = phase.eval(cos_theta[i]) for i < count (the best compiled target this CPU supports).
void eval_phase(const PhaseFunction& phase, const float* cos_theta, float* out, size_t count);
// The scalar reference: the float64 evaluation rounded to float32.
void eval_phase_reference(const PhaseFunction& phase, const float* cos_theta, float* out, size_t count);

// Highway targets compiled into Haze and supported by this CPU, best first, and the one dispatch picks.
std::vector<std::string> available_targets();
std::string selected_target();

}  // namespace haze::simd

#pragma GCC visibility pop
