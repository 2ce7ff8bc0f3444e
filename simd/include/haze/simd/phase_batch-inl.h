// Per-target phase evaluation (Highway: included once per target by foreach_target.h).
#include <haze/simd/phase_params.h>

#if defined(HAZE_SIMD_PHASE_BATCH_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_SIMD_PHASE_BATCH_INL_H_
#undef HAZE_SIMD_PHASE_BATCH_INL_H_
#else
#define HAZE_SIMD_PHASE_BATCH_INL_H_
#endif

#include <hwy/highway.h>

#include <algorithm>

HWY_BEFORE_NAMESPACE();
namespace haze::simd::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// 1 / sqrt(x) for x > 0 from the hardware estimate and one Newton step (within a few ulp): the
// kernels' divides and square roots share one slow unit, this runs on the FMA ports.
template <class V>
HWY_INLINE V ReciprocalSqrt(V x) {
  const hn::DFromV<V> d;
#if HWY_TARGET == HWY_SCALAR  // its estimate is a bit trick, 1e-5 off after the step
  return hn::Div(hn::Set(d, 1.0f), hn::Sqrt(x));
#endif
  const V r = hn::ApproximateReciprocalSqrt(x);
  return hn::Mul(hn::Mul(r, hn::Set(d, 0.5f)), hn::NegMulAdd(hn::Mul(x, r), r, hn::Set(d, 3.0f)));
}

template <class D, class V>
HWY_INLINE V EvalPhase(D d, const PhaseParams& p, V mu) {
  V poly = hn::MulAdd(hn::Set(d, p.c2), hn::Mul(mu, mu), hn::Set(d, p.c0));
  if (p.lobes == 0) return poly;
  V sum = hn::Zero(d);
  for (int l = 0; l < p.lobes; ++l) {
    V one_minus_s_mu = hn::NegMulAdd(hn::Set(d, p.s[l]), mu, hn::Set(d, 1.0f));
    V denom = hn::MulAdd(hn::Set(d, p.b[l]), one_minus_s_mu, hn::Set(d, p.a[l]));
    const V r = ReciprocalSqrt(denom);  // k denom^(-3/2)
    sum = hn::MulAdd(hn::Set(d, p.k[l]), hn::Mul(r, hn::Mul(r, r)), sum);
  }
  return hn::Mul(poly, sum);
}

// inline: march_rays-inl.h includes this header too.
inline HWY_NOINLINE void EvalPhaseBatch(const PhaseParams& p, const float* HWY_RESTRICT mu, float* HWY_RESTRICT out,
                                 size_t count) {
  const hn::ScalableTag<float> d;
  const size_t lanes = hn::Lanes(d);
  size_t i = 0;
  for (; i + lanes <= count; i += lanes) hn::StoreU(EvalPhase(d, p, hn::LoadU(d, mu + i)), d, out + i);
  if (i < count) {
    // Tail through a padded copy: Highway 1.0's MaskedLoad on SSE targets reads the whole vector,
    // past the end of the caller's array. Padding with mu = 0 keeps every lane finite.
    HWY_ALIGN float in[hn::MaxLanes(d)] = {}, result[hn::MaxLanes(d)];
    std::copy(mu + i, mu + count, in);
    hn::Store(EvalPhase(d, p, hn::Load(d, in)), d, result);
    std::copy(result, result + (count - i), out + i);
  }
}

}  // namespace haze::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HAZE_SIMD_PHASE_BATCH_INL_H_
