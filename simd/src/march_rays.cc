// Dispatch for the ray-march kernel (Highway skeleton layout).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "march_rays.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include "march_rays-inl.h"

#include <hwy/highway.h>

#if HWY_ONCE
#include <haze/core/error.h>

namespace haze::simd {

HWY_EXPORT(MarchRays);

bool march_supported(const PhaseFunction& phase) {
  PhaseParams p;
  return params_for(phase, p);
}

void march_rays(const MarchVolume& volume, const PhaseFunction& phase, const RayPacket& rays) {
  PhaseParams p;
  if (!params_for(phase, p)) throw Error("phase", phase.name(), "an analytic phase function for the SIMD marcher");
  HWY_DYNAMIC_DISPATCH(MarchRays)(volume, p, rays);
}

}  // namespace haze::simd
#endif  // HWY_ONCE
