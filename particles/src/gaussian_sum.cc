// Dispatch and scalar reference for sums of truncated Gaussians (Highway skeleton layout).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "gaussian_sum.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include "gaussian_sum-inl.h"

#include <hwy/highway.h>

#if HWY_ONCE
#include <cmath>

namespace haze::particles {

HWY_EXPORT(GaussianSum);

float gaussian_sum(const GaussianList& terms, float px, float py, float pz, float cut2) {
  return HWY_DYNAMIC_DISPATCH(GaussianSum)(terms, px, py, pz, cut2);
}

float gaussian_sum_reference(const GaussianList& g, float px, float py, float pz, float cut2) {
  float sum = 0.0f;
  for (size_t i = 0; i < g.count; ++i) {
    const float dx = g.x[i] - px, dy = g.y[i] - py, dz = g.z[i] - pz;
    const float r2 = (dx * dx + dy * dy + dz * dz) * g.inv_h2[i];
    if (r2 < cut2) sum += g.w[i] * std::exp(-r2);
  }
  return sum;
}

}  // namespace haze::particles
#endif  // HWY_ONCE
