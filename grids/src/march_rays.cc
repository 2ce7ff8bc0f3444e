// Dispatch for the ray-march kernel (Highway skeleton layout).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "march_rays.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include "march_rays-inl.h"

#include <hwy/highway.h>

#if HWY_ONCE
#include <haze/core/error.h>

namespace haze::grids {

HWY_EXPORT(MarchRays);
HWY_EXPORT(RowPacket);
HWY_EXPORT(InterleaveRgb);

void march_interleave_rgb(const float* r, const float* g, const float* b, size_t count, float* out) {
  HWY_DYNAMIC_DISPATCH(InterleaveRgb)(r, g, b, count, out);
}

void march_row_packet(const RowFrame& row, float* rows, size_t stride, size_t count) {
  HWY_DYNAMIC_DISPATCH(RowPacket)(row, rows, stride, count);
}

bool march_supported(const PhaseFunction& phase) {
  simd::PhaseParams p;
  return simd::params_for(phase, p);
}

void march_rays(const MarchVolume& volume, const PhaseFunction& phase, const RayPacket& rays) {
  simd::PhaseParams p;
  if (!simd::params_for(phase, p)) throw Error("phase", phase.name(), "an analytic phase function for the SIMD marcher");
  HWY_DYNAMIC_DISPATCH(MarchRays)(volume, p, rays);
}

}  // namespace haze::grids
#endif  // HWY_ONCE
