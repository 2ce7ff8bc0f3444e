// One light's single scattering at a vector of points (Highway: included once per target by the
// kernels that take it, march_rays-inl.h and toward_eye-inl.h).
#if defined(HAZE_GRIDS_MARCH_LIGHT_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_GRIDS_MARCH_LIGHT_INL_H_
#undef HAZE_GRIDS_MARCH_LIGHT_INL_H_
#else
#define HAZE_GRIDS_MARCH_LIGHT_INL_H_
#endif

#include <haze/grids/march_rays.h>
#include <haze/simd/phase_params.h>

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include <haze/simd/phase_batch-inl.h>

HWY_BEFORE_NAMESPACE();
namespace haze::grids::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// p(to_light . w) E(x) visible at points x, w the unit vectors away from the eye, E a point
// light's I / r^2 (a spot's times its cone; per unit intensity), a directional light's irradiance.
template <class D, class V = hn::Vec<D>>
HWY_INLINE V LightWeight(D d, const MarchLight& light, const simd::PhaseParams& phase, const V* x, const V* w, V visible) {
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0f);
  V to[3], falloff = visible;
  if (light.type == MarchLight::directional) {
    for (int e = 0; e < 3; ++e) to[e] = hn::Set(d, light.to_light[e]);
  } else {
    for (int e = 0; e < 3; ++e) to[e] = hn::Sub(hn::Set(d, light.position[e]), x[e]);
    const V inv_r = simd::HWY_NAMESPACE::ReciprocalSqrt(hn::MulAdd(to[0], to[0], hn::MulAdd(to[1], to[1], hn::Mul(to[2], to[2]))));
    for (int e = 0; e < 3; ++e) to[e] = hn::Mul(to[e], inv_r);
    falloff = hn::Mul(falloff, hn::Mul(inv_r, inv_r));
    if (light.type == MarchLight::spot) {
      const V cos_theta = hn::Neg(hn::MulAdd(to[0], hn::Set(d, light.axis[0]), hn::MulAdd(to[1], hn::Set(d, light.axis[1]), hn::Mul(to[2], hn::Set(d, light.axis[2])))));
      const auto inside = hn::And(hn::Ge(cos_theta, hn::Set(d, light.cos_cone)), hn::Gt(cos_theta, zero));
      const V cone = hn::Exp(d, hn::Mul(hn::Set(d, light.exponent), hn::Log(d, hn::IfThenElse(inside, cos_theta, one))));
      falloff = hn::IfThenElseZero(inside, hn::Mul(falloff, cone));
    }
  }
  const V mu = hn::MulAdd(to[0], w[0], hn::MulAdd(to[1], w[1], hn::Mul(to[2], w[2])));
  return hn::Mul(simd::HWY_NAMESPACE::EvalPhase(d, phase, mu), falloff);
}

// in[c] += LightWeight I[c] e^(-sigma_t[c] depth_scale[c] depth); `grey`: one exponential for
// every channel.
template <int C, class D, class V = hn::Vec<D>>
HWY_INLINE void AddLight(D d, const MarchVolume& v, const MarchLight& light, const simd::PhaseParams& phase, const V* x, const V* w, V depth,
                         V visible, bool grey, V* in) {
  const V weight = LightWeight(d, light, phase, x, w, visible);
  V attenuation[C];
  for (int c = 0; c < C; ++c)
    attenuation[c] = c > 0 && grey ? attenuation[0] : hn::Exp(d, hn::Mul(hn::Set(d, -v.sigma_t[c] * v.depth_scale[c]), depth));
  for (int c = 0; c < C; ++c) in[c] = hn::MulAdd(hn::Mul(weight, hn::Set(d, light.intensity[c])), attenuation[c], in[c]);
}

}  // namespace haze::grids::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HAZE_GRIDS_MARCH_LIGHT_INL_H_
