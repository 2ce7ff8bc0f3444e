// Per-target float16 conversion (Highway: included once per target by foreach_target.h).
#if defined(HAZE_SIMD_HALF_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_SIMD_HALF_INL_H_
#undef HAZE_SIMD_HALF_INL_H_
#else
#define HAZE_SIMD_HALF_INL_H_
#endif

#include <haze/simd/half.h>

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace haze::simd::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Half and hwy::float16_t are both 16 bits of IEEE binary16; the loads and stores below go
// through vector intrinsics, which may alias any type.
inline const hwy::float16_t* bits(const Half* p) { return reinterpret_cast<const hwy::float16_t*>(p); }
inline hwy::float16_t* bits(Half* p) { return reinterpret_cast<hwy::float16_t*>(p); }

inline HWY_NOINLINE void ToHalf(const float* HWY_RESTRICT from, Half* HWY_RESTRICT to, size_t count) {
#if HWY_TARGET == HWY_SSE4 || HWY_TARGET == HWY_SSSE3
  // x86 without F16C: Highway 1.0.3's emulated DemoteTo flushes some subnormals to zero (3.8e-6
  // becomes 0); Eigen's scalar conversion is exact to the rounding.
  for (size_t i = 0; i < count; ++i) to[i] = Half(from[i]);
#else
  const hn::CappedTag<float, 8> d;
  const hn::Rebind<hwy::float16_t, decltype(d)> dh;
  const size_t lanes = hn::Lanes(d);
  size_t i = 0;
  for (; i + lanes <= count; i += lanes) hn::StoreU(hn::DemoteTo(dh, hn::LoadU(d, from + i)), dh, bits(to + i));
  const hn::CappedTag<float, 1> d1;
  const hn::Rebind<hwy::float16_t, decltype(d1)> dh1;
  for (; i < count; ++i) hn::StoreU(hn::DemoteTo(dh1, hn::LoadU(d1, from + i)), dh1, bits(to + i));
#endif
}

inline HWY_NOINLINE void ToFloat(const Half* HWY_RESTRICT from, float* HWY_RESTRICT to, size_t count) {
  const hn::CappedTag<float, 8> d;
  const hn::Rebind<hwy::float16_t, decltype(d)> dh;
  const size_t lanes = hn::Lanes(d);
  size_t i = 0;
  for (; i + lanes <= count; i += lanes) hn::StoreU(hn::PromoteTo(d, hn::LoadU(dh, bits(from + i))), d, to + i);
  const hn::CappedTag<float, 1> d1;
  const hn::Rebind<hwy::float16_t, decltype(d1)> dh1;
  for (; i < count; ++i) hn::StoreU(hn::PromoteTo(d1, hn::LoadU(dh1, bits(from + i))), d1, to + i);
}

}  // namespace haze::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // include guard
