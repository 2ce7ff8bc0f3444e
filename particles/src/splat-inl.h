// Per-target splat of particles onto camera rays (haze/particles/splat.h; Highway: included once per
// target by foreach_target.h). Rays in lanes, the particles broadcast one by one, L and T kept in
// registers from the first particle to the last.
#if defined(HAZE_PARTICLES_SPLAT_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_PARTICLES_SPLAT_INL_H_
#undef HAZE_PARTICLES_SPLAT_INL_H_
#else
#define HAZE_PARTICLES_SPLAT_INL_H_
#endif

#include <haze/particles/field.h>
#include <haze/particles/splat.h>

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include <limits>

HWY_BEFORE_NAMESPACE();
namespace haze::particles::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// erf(x), Abramowitz and Stegun 7.1.26 (absolute error under 1.5e-7 in exact arithmetic).
template <class D, class V>
HWY_INLINE V Erf(D d, V x) {
  const V a = hn::Abs(x);
  const V t = hn::Div(hn::Set(d, 1.0f), hn::MulAdd(hn::Set(d, 0.3275911f), a, hn::Set(d, 1.0f)));
  V poly = hn::MulAdd(hn::Set(d, 1.061405429f), t, hn::Set(d, -1.453152027f));
  poly = hn::MulAdd(poly, t, hn::Set(d, 1.421413741f));
  poly = hn::MulAdd(poly, t, hn::Set(d, -0.284496736f));
  poly = hn::MulAdd(poly, t, hn::Set(d, 0.254829592f));
  const V y = hn::NegMulAdd(hn::Mul(poly, t), hn::Exp(d, hn::Neg(hn::Mul(a, a))), hn::Set(d, 1.0f));
  return hn::CopySign(y, x);
}

template <int C>
HWY_INLINE void SplatVectors(const SplatParticles& p, const float sigma_t[3], const SplatRays& r) {
  const hn::ScalableTag<float> d;
  using V = hn::Vec<decltype(d)>;
  const size_t lanes = hn::Lanes(d);
  const V cut2 = hn::Set(d, static_cast<float>(kCut * kCut)), zero = hn::Zero(d), one = hn::Set(d, 1.0f), half = hn::Set(d, 0.5f), opaque = hn::Set(d, kSplatOpaque);
  V sigma[3];
  for (int c = 0; c < 3; ++c) sigma[c] = hn::Set(d, -sigma_t[c]);
  for (size_t first = 0; first < r.count; first += lanes) {
    const V ox = hn::LoadU(d, r.ox + first), oy = hn::LoadU(d, r.oy + first), oz = hn::LoadU(d, r.oz + first);
    const V dx = hn::LoadU(d, r.dx + first), dy = hn::LoadU(d, r.dy + first), dz = hn::LoadU(d, r.dz + first);
    const V t_end = r.t_end ? hn::LoadU(d, r.t_end + first) : hn::Set(d, std::numeric_limits<float>::infinity());
    V radiance[3] = {zero, zero, zero}, transmittance[C];
    for (int c = 0; c < C; ++c) transmittance[c] = one;
    for (size_t k = 0; k < p.count; ++k) {
      if (k % 8 == 0) {  // every lane opaque: what lies behind adds at most kSplatOpaque of its light
        V most = transmittance[0];
        for (int c = 1; c < C; ++c) most = hn::Max(most, transmittance[c]);
        if (hn::AllTrue(d, hn::Lt(most, opaque))) break;
      }
      const uint32_t i = p.order[k];
      const V px = hn::Sub(hn::Set(d, p.x[i]), ox), py = hn::Sub(hn::Set(d, p.y[i]), oy), pz = hn::Sub(hn::Set(d, p.z[i]), oz);
      const V tc = hn::MulAdd(px, dx, hn::MulAdd(py, dy, hn::Mul(pz, dz)));
      // The ray's offset from the centre at its closest approach (|p|^2 - tc^2 would cancel).
      const V rx = hn::NegMulAdd(tc, dx, px), ry = hn::NegMulAdd(tc, dy, py), rz = hn::NegMulAdd(tc, dz, pz);
      const float h = p.h[i];
      const V q = hn::Mul(hn::MulAdd(rx, rx, hn::MulAdd(ry, ry, hn::Mul(rz, rz))), hn::Set(d, 1.0f / (h * h)));  // (r / h)^2
      const auto inside = hn::Lt(q, cut2);
      if (hn::AllFalse(d, inside)) continue;
      V tau = hn::IfThenElseZero(inside, hn::Mul(hn::Set(d, p.amplitude[i]), hn::Exp(d, hn::Neg(hn::Min(q, cut2)))));
      // The share of the Gaussian inside [0, t_end], where [tc - kCut h, tc + kCut h] is not.
      const V reach = hn::Set(d, static_cast<float>(kCut) * h), lo = hn::Sub(tc, reach), hi = hn::Add(tc, reach);
      const auto clipped = hn::And(inside, hn::Or(hn::Lt(lo, zero), hn::Gt(hi, t_end)));
      if (!hn::AllFalse(d, clipped)) {
        const V inv_h = hn::Set(d, 1.0f / h);
        const V a = hn::Mul(hn::Sub(hn::Max(lo, zero), tc), inv_h), b = hn::Mul(hn::Sub(hn::Min(hi, t_end), tc), inv_h);
        const V share = hn::Max(zero, hn::Mul(half, hn::Sub(Erf(d, b), Erf(d, a))));
        tau = hn::IfThenElse(clipped, hn::Mul(tau, share), tau);
      }
      // The direct light's factor: exp(g . D + u k^2), D = o + (tc + m) d - c, k = g . d (splat.h).
      const V gx = hn::Set(d, p.gx[i]), gy = hn::Set(d, p.gy[i]), gz = hn::Set(d, p.gz[i]), m = hn::Set(d, p.shift[i]);
      const V slope = hn::MulAdd(gx, dx, hn::MulAdd(gy, dy, hn::Mul(gz, dz)));
      const V across = hn::Neg(hn::MulAdd(gx, rx, hn::MulAdd(gy, ry, hn::Mul(gz, rz))));
      const V log_direct = hn::MulAdd(hn::MulAdd(hn::Set(d, p.spread[i]), slope, m), slope, across);
      const V direct = hn::Exp(d, hn::Min(log_direct, hn::Set(d, p.max_log[i])));
      if constexpr (C == 1) {
        const V e = hn::Exp(d, hn::Mul(sigma[0], tau)), weight = hn::NegMulAdd(transmittance[0], e, transmittance[0]);
        for (int c = 0; c < 3; ++c) radiance[c] = hn::MulAdd(weight, hn::MulAdd(direct, hn::Set(d, p.direct[c][i]), hn::Set(d, p.source[c][i])), radiance[c]);
        transmittance[0] = hn::Mul(transmittance[0], e);
      } else {
        for (int c = 0; c < 3; ++c) {
          const V e = hn::Exp(d, hn::Mul(sigma[c], tau));
          const V source = hn::MulAdd(direct, hn::Set(d, p.direct[c][i]), hn::Set(d, p.source[c][i]));
          radiance[c] = hn::MulAdd(hn::NegMulAdd(transmittance[c], e, transmittance[c]), source, radiance[c]);
          transmittance[c] = hn::Mul(transmittance[c], e);
        }
      }
    }
    for (int c = 0; c < 3; ++c) {
      hn::StoreU(radiance[c], d, r.radiance[c] + first);
      hn::StoreU(transmittance[C == 1 ? 0 : c], d, r.transmittance[c] + first);
    }
  }
}

inline HWY_NOINLINE void SplatRaysKernel(const SplatParticles& p, const float* sigma_t, int channels, const SplatRays& r) {
  if (channels == 1) SplatVectors<1>(p, sigma_t, r);
  else SplatVectors<3>(p, sigma_t, r);
}

}  // namespace haze::particles::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // include guard
