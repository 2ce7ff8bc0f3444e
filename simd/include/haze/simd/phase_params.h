// Float constants of an analytic phase function: shared by every SIMD target, and by the GL
// display's shader uniforms (gl/src/display.cpp).
#pragma once

#include <haze/core/phase.h>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::simd {

// Every analytic phase function is written as
// p = [c0 + c2 mu^2] * [w1 k1 / d1^(3/2) + w2 k2 / d2^(3/2)] with d = a + b (1 - s mu), or a
// plain polynomial c0 + c2 mu^2 when there is no HG lobe (isotropic, Rayleigh).
struct PhaseParams {
  int lobes = 0;          // 0, 1 or 2 HG lobes
  float c0 = 1.0f, c2 = 0.0f;  // polynomial factor c0 + c2 mu^2
  float k[2] = {0, 0};    // (1 - g^2) / (4 pi), times the lobe weight
  // 1 + g^2 - 2 g mu = (1 - |g|)^2 + 2 |g| (1 - s mu), s = sign(g): both terms >= 0, so the
  // denominator does not cancel at the peak as |g| -> 1.
  float a[2] = {1, 1};    // (1 - |g|)^2
  float b[2] = {0, 0};    // 2 |g|
  float s[2] = {1, 1};    // sign(g)
};

// Float constants for an analytic phase function; false for a tabulated one (phase_batch.cc).
bool params_for(const PhaseFunction& phase, PhaseParams& p);

}  // namespace haze::simd

#pragma GCC visibility pop
