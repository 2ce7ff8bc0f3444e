// Sums of truncated isotropic Gaussians at a point, sum_i w_i exp(-|p - x_i|^2 inv_h2_i) over the
// terms with |p - x_i|^2 inv_h2_i < cut2, in float32 lanes with Highway runtime dispatch: the
// particles' density rho(x) (particles/field.h, ParticleDensity), which the path tracer evaluates
// at every tentative collision. ISA-free header: per-target code in src/gaussian_sum-inl.h.
#pragma once

#include <cstddef>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::particles {

// Structure of arrays; `count` a multiple of kGaussianPad (pad with w = 0, inv_h2 = 0).
struct GaussianList {
  const float *x, *y, *z, *inv_h2, *w;
  size_t count;
};
inline constexpr size_t kGaussianPad = 16;

float gaussian_sum(const GaussianList& terms, float px, float py, float pz, float cut2);
// The scalar reference (std::exp, summed in order).
float gaussian_sum_reference(const GaussianList& terms, float px, float py, float pz, float cut2);

}  // namespace haze::particles

#pragma GCC visibility pop
