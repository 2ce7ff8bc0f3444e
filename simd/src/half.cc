// Dispatch and scalar references for float16 conversion (Highway skeleton layout).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "half.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include "half-inl.h"

#include <hwy/highway.h>

#if HWY_ONCE
namespace haze::simd {

HWY_EXPORT(ToHalf);
HWY_EXPORT(ToFloat);

void to_half(const float* from, Half* to, size_t count) { HWY_DYNAMIC_DISPATCH(ToHalf)(from, to, count); }
void to_float(const Half* from, float* to, size_t count) { HWY_DYNAMIC_DISPATCH(ToFloat)(from, to, count); }

void to_half_reference(const float* from, Half* to, size_t count) {
  for (size_t i = 0; i < count; ++i) to[i] = Half(from[i]);
}
void to_float_reference(const Half* from, float* to, size_t count) {
  for (size_t i = 0; i < count; ++i) to[i] = static_cast<float>(from[i]);
}

}  // namespace haze::simd
#endif  // HWY_ONCE
