// Per-target discrete-ordinate row sweep (Highway: included once per target by foreach_target.h).
#if defined(HAZE_SIMD_DOM_SWEEP_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_SIMD_DOM_SWEEP_INL_H_
#undef HAZE_SIMD_DOM_SWEEP_INL_H_
#else
#define HAZE_SIMD_DOM_SWEEP_INL_H_
#endif

#include <haze/simd/dom_sweep.h>

#include <hwy/highway.h>

#include <algorithm>

HWY_BEFORE_NAMESPACE();
namespace haze::simd::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The diamond scheme on one vector of directions (dom_sweep.h; the scalar reference's diamond_g,
// lane by lane): the cell's mean radiance, and the leaving values stored into the faces x, y, z in
// place of the entering ones. `sum`: a_x + a_y + a_z.
template <class D, class V = hn::Vec<D>>
HWY_INLINE V Diamond(D d, V sigma_t, V sigma_s_times_s, V pad, const V a[3], V sum, float* HWY_RESTRICT x, float* HWY_RESTRICT y,
                     float* HWY_RESTRICT z) {
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0f), tiny = hn::Set(d, kDiamondTiny), two = hn::Set(d, 2.0f), three = hn::Set(d, 3.0f),
          six = hn::Set(d, 6.0f);
  const V sigma2 = hn::Mul(sigma_t, sigma_t), two_sigma = hn::Mul(two, sigma_t), three_sigma = hn::Mul(three, sigma_t);
  const V around = hn::MulAdd(two, sum, sigma_t);  // sigma + 2 sum
  float* HWY_RESTRICT face[3] = {x, y, z};
  V in[3], g[3];
  V num = sigma_s_times_s, den = hn::Add(sigma_t, pad);
  for (int e = 0; e < 3; ++e) {
    in[e] = hn::LoadU(d, face[e]);
    const V g_tau = hn::Div(hn::MulAdd(a[e], hn::MulAdd(six, a[e], three_sigma), sigma2),
                            hn::Max(hn::MulAdd(a[e], hn::MulAdd(three, a[e], two_sigma), sigma2), tiny));
    const V q = hn::NegMulAdd(three, a[e], around), bound = hn::Div(hn::NegMulAdd(two, a[e], around), hn::Max(q, tiny));
    g[e] = hn::IfThenElse(hn::Gt(q, zero), hn::Min(g_tau, bound), g_tau);
    const V b = hn::Mul(a[e], g[e]);
    num = hn::MulAdd(b, in[e], num);
    den = hn::Add(den, b);
  }
  const V l = hn::Div(num, hn::Max(den, tiny));
  for (int e = 0; e < 3; ++e) hn::StoreU(hn::NegMulAdd(hn::Sub(g[e], one), in[e], hn::Mul(g[e], l)), d, face[e]);
  return l;
}

// Lanes over directions (at most 8, the padding unit), then over terms for the moments. Up to four
// vectors accumulate side by side in registers: independent FMA chains, no store-load round trips.
void DomSweepRow(const DomOctant& o, const DomRow& r) {
  const hn::CappedTag<float, 8> d;
  using V = hn::Vec<decltype(d)>;
  const hn::Rebind<hwy::float16_t, decltype(d)> dh;
  const size_t lanes = hn::Lanes(d);
  const auto p = static_cast<size_t>(o.directions), n = static_cast<size_t>(o.terms), np = static_cast<size_t>(o.terms_padded);
  float* HWY_RESTRICT light = r.scratch;
  float* HWY_RESTRICT moments = r.scratch + p;
  const float* HWY_RESTRICT ax = o.a;
  const float* HWY_RESTRICT ay = o.a + p;
  const float* HWY_RESTRICT az = o.a + 2 * p;
  const float* HWY_RESTRICT asum = o.a + 3 * p;
  const float* HWY_RESTRICT pad = o.a + 4 * p;
  for (int m = 0; m < r.count; ++m) {
    const size_t c = r.cell0 + static_cast<size_t>(static_cast<long>(m) * r.step);
    const auto x = static_cast<size_t>(r.x0 + m * r.step);
    const float sigma_t_value = r.sigma_t_scale * r.density[c];
    const V sigma_t = hn::Set(d, sigma_t_value), sigma_s = hn::Set(d, r.albedo * sigma_t_value);
    float* HWY_RESTRICT y = r.y_row + x * p;
    float* HWY_RESTRICT z = r.z_row + x * p;
    // An empty cell scatters nothing (sigma_s = 0): its source is not needed.
    const bool empty = sigma_t_value == 0.0f;
    const float* HWY_RESTRICT m_in = r.m_in && !empty ? r.m_in + c * n : nullptr;
    const float* HWY_RESTRICT first = r.first && !empty ? r.first + c * r.first_stride : nullptr;
    const Half* HWY_RESTRICT first_half = !r.first && r.first_half && !empty ? r.first_half + c * r.first_stride : nullptr;
    for (size_t i = 0; i < p; i += 4 * lanes) {
      const size_t count = std::min<size_t>(4, (p - i) / lanes);
      // Source: the first-collision term plus lambda Q m_in, one term (a broadcast) at a time.
      V s[4];
      for (size_t v = 0; v < 4; ++v) s[v] = first && v < count ? hn::LoadU(d, first + i + v * lanes) : hn::Zero(d);
      if (first_half)
        for (size_t v = 0; v < count; ++v)
          s[v] = hn::Mul(hn::Set(d, r.first_scale[c]), hn::PromoteTo(d, hn::LoadU(dh, reinterpret_cast<const hwy::float16_t*>(first_half + i + v * lanes))));
      if (m_in) {
        for (size_t k = 0; k < n; ++k) {
          const V mk = hn::Set(d, m_in[k]);
          const float* HWY_RESTRICT lq = o.lq + k * p + i;
          s[0] = hn::MulAdd(hn::LoadU(d, lq), mk, s[0]);
          if (count > 1) s[1] = hn::MulAdd(hn::LoadU(d, lq + lanes), mk, s[1]);
          if (count > 2) s[2] = hn::MulAdd(hn::LoadU(d, lq + 2 * lanes), mk, s[2]);
          if (count > 3) s[3] = hn::MulAdd(hn::LoadU(d, lq + 3 * lanes), mk, s[3]);
        }
      }
      for (size_t v = 0; o.diamond && v < count; ++v) {
        const size_t e = i + v * lanes;
        const V a[3] = {hn::LoadU(d, ax + e), hn::LoadU(d, ay + e), hn::LoadU(d, az + e)};
        const V sum = hn::Add(hn::Add(a[0], a[1]), a[2]);
        hn::StoreU(Diamond(d, sigma_t, hn::Mul(sigma_s, s[v]), hn::LoadU(d, pad + e), a, sum, r.x_run + e, y + e, z + e), d, light + e);
      }
      for (size_t v = 0; !o.diamond && v < count; ++v) {
        const size_t e = i + v * lanes;
        V in = hn::Mul(hn::LoadU(d, ax + e), hn::LoadU(d, r.x_run + e));
        in = hn::MulAdd(hn::LoadU(d, ay + e), hn::LoadU(d, y + e), in);
        in = hn::MulAdd(hn::LoadU(d, az + e), hn::LoadU(d, z + e), in);
        const V l = hn::Div(hn::MulAdd(sigma_s, s[v], in), hn::Add(sigma_t, hn::LoadU(d, asum + e)));
        hn::StoreU(l, d, r.x_run + e);
        hn::StoreU(l, d, y + e);
        hn::StoreU(l, d, z + e);
        hn::StoreU(l, d, light + e);
      }
    }
    // Moments: lanes over terms, one direction (a broadcast) at a time.
    for (size_t k = 0; k < np; k += 4 * lanes) {
      const size_t count = std::min<size_t>(4, (np - k) / lanes);
      V sum[4] = {hn::Zero(d), hn::Zero(d), hn::Zero(d), hn::Zero(d)};
      for (size_t i = 0; i < p; ++i) {
        const V li = hn::Set(d, light[i]);
        const float* HWY_RESTRICT q = o.q + i * np + k;
        sum[0] = hn::MulAdd(hn::LoadU(d, q), li, sum[0]);
        if (count > 1) sum[1] = hn::MulAdd(hn::LoadU(d, q + lanes), li, sum[1]);
        if (count > 2) sum[2] = hn::MulAdd(hn::LoadU(d, q + 2 * lanes), li, sum[2]);
        if (count > 3) sum[3] = hn::MulAdd(hn::LoadU(d, q + 3 * lanes), li, sum[3]);
      }
      for (size_t v = 0; v < count; ++v) hn::StoreU(sum[v], d, moments + k + v * lanes);
    }
    float* HWY_RESTRICT out = r.m_out + c * n;
    for (size_t k = 0; k < n; ++k) out[k] += moments[k];
  }
}

}  // namespace haze::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // include guard
