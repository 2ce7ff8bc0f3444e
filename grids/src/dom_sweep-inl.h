// Per-target discrete-ordinate row sweep (Highway: included once per target by foreach_target.h).
#if defined(HAZE_GRIDS_DOM_SWEEP_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_GRIDS_DOM_SWEEP_INL_H_
#undef HAZE_GRIDS_DOM_SWEEP_INL_H_
#else
#define HAZE_GRIDS_DOM_SWEEP_INL_H_
#endif

#include <haze/grids/dom_sweep.h>

#include <hwy/highway.h>

#include <algorithm>

HWY_BEFORE_NAMESPACE();
namespace haze::grids::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// 1 / x to about float precision for finite x > 0: the approximate reciprocal and one Newton step,
// a few cycles where a division takes ten or more.
template <class D, class V = hn::Vec<D>>
HWY_INLINE V Reciprocal(D d, V x) {
  const V r = hn::ApproximateReciprocal(x);
  return hn::Mul(r, hn::NegMulAdd(x, r, hn::Set(d, 2.0f)));
}

// The diamond scheme on one vector of directions (dom_sweep.h; the scalar reference's diamond_g,
// lane by lane): the cell's mean radiance, and the leaving values stored into the faces x, y, z in
// place of the entering ones. `sum`: a_x + a_y + a_z.
// With kLinear, the first-collision source `first` is linear over the cell (dom_sweep.h):
// `ts[e]` is sigma_s t_e; without, the shifts are not computed (the sweeps with no such source).
// `bound`: with the positivity bound (dom_sweep.h); `lowest`, if given, takes the smallest leaving
// value plus kFixUpSlack times the sum of the entering ones and the mean in size.
template <bool kLinear, class D, class V = hn::Vec<D>>
HWY_INLINE V Diamond(D d, V sigma_t, V sigma_s_times_s, V pad, const V a[3], V sum, float* HWY_RESTRICT x, float* HWY_RESTRICT y,
                     float* HWY_RESTRICT z, V first, const V ts[3], bool bound, V* lowest) {
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0f), tiny = hn::Set(d, kDiamondTiny), two = hn::Set(d, 2.0f), three = hn::Set(d, 3.0f),
          six = hn::Set(d, 6.0f);
  const V sigma2 = hn::Mul(sigma_t, sigma_t), two_sigma = hn::Mul(two, sigma_t), three_sigma = hn::Mul(three, sigma_t);
  const V around = hn::MulAdd(two, sum, sigma_t);  // sigma + 2 sum
  float* HWY_RESTRICT face[3] = {x, y, z};
  V in[3], g[3], shift[3];
  V num = sigma_s_times_s, den = hn::Add(sigma_t, pad);
  V stay = zero;
  if constexpr (kLinear) stay = hn::Mul(first, Reciprocal(d, hn::Add(hn::MulAdd(hn::Set(d, 12.0f), sum, two_sigma), tiny)));
  for (int e = 0; e < 3; ++e) {
    in[e] = hn::LoadU(d, face[e]);
    shift[e] = kLinear ? hn::Mul(ts[e], stay) : zero;
    const V g_tau = hn::Mul(hn::MulAdd(a[e], hn::MulAdd(six, a[e], three_sigma), sigma2),
                            Reciprocal(d, hn::Max(hn::MulAdd(a[e], hn::MulAdd(three, a[e], two_sigma), sigma2), tiny)));
    g[e] = g_tau;
    if (bound) {
      const V q = hn::NegMulAdd(three, a[e], around), limit = hn::Mul(hn::NegMulAdd(two, a[e], around), Reciprocal(d, hn::Max(q, tiny)));
      g[e] = hn::IfThenElse(hn::Gt(q, zero), hn::Min(g_tau, limit), g_tau);
    }
    const V b = hn::Mul(a[e], g[e]);
    num = hn::MulAdd(b, kLinear ? hn::Sub(in[e], shift[e]) : in[e], num);
    den = hn::Add(den, b);
  }
  const V l = hn::Mul(num, Reciprocal(d, hn::Max(den, tiny)));
  const V slack =
      lowest ? hn::Mul(hn::Set(d, kFixUpSlack), hn::Add(hn::Add(hn::Abs(in[0]), hn::Abs(in[1])), hn::Add(hn::Abs(in[2]), hn::Abs(l)))) : zero;
  for (int e = 0; e < 3; ++e) {
    const V out = hn::NegMulAdd(hn::Sub(g[e], one), in[e], hn::Mul(g[e], kLinear ? hn::Add(l, shift[e]) : l));
    hn::StoreU(out, d, face[e]);
    if (lowest) *lowest = hn::Min(*lowest, hn::Add(out, slack));
  }
  return l;
}

// acc[v] += sum_r rows[r * stride + v * lanes ...] w[r] for r < count_rows and kV vectors: the
// rows split over 8 / kV interleaved accumulators per vector: about 8 independent FMA chains
// where there was one per vector (with the reciprocals, about 12% per row).
template <size_t kV, class D, class V = hn::Vec<D>>
HWY_INLINE void DotRows(D d, const float* HWY_RESTRICT rows, size_t stride, const float* HWY_RESTRICT w, size_t count_rows, V* acc) {
  constexpr size_t kJ = 8 / kV;
  const size_t lanes = hn::Lanes(d);
  V part[kJ][kV];
  for (size_t j = 0; j < kJ; ++j)
    for (size_t v = 0; v < kV; ++v) part[j][v] = hn::Zero(d);
  size_t r = 0;
  for (; r + kJ <= count_rows; r += kJ)
    for (size_t j = 0; j < kJ; ++j) {
      const V wr = hn::Set(d, w[r + j]);
      for (size_t v = 0; v < kV; ++v) part[j][v] = hn::MulAdd(hn::LoadU(d, rows + (r + j) * stride + v * lanes), wr, part[j][v]);
    }
  for (; r < count_rows; ++r) {
    const V wr = hn::Set(d, w[r]);
    for (size_t v = 0; v < kV; ++v) part[0][v] = hn::MulAdd(hn::LoadU(d, rows + r * stride + v * lanes), wr, part[0][v]);
  }
  for (size_t v = 0; v < kV; ++v) {
    for (size_t j = 1; j < kJ; ++j) part[0][v] = hn::Add(part[0][v], part[j][v]);
    acc[v] = hn::Add(acc[v], part[0][v]);
  }
}

// Lanes over directions (at most 8, the padding unit), then over terms for the moments, each a
// DotRows over up to four vectors.
void DomSweepRow(const DomOctant& o, const DomRow& r) {
  const hn::CappedTag<float, 8> d;
  using V = hn::Vec<decltype(d)>;
  const hn::Rebind<hwy::float16_t, decltype(d)> dh;
  const size_t lanes = hn::Lanes(d);
  const auto p = static_cast<size_t>(o.directions), n = static_cast<size_t>(o.terms), np = static_cast<size_t>(o.terms_padded);
  float* HWY_RESTRICT light = r.scratch;
  float* HWY_RESTRICT moments = r.scratch + p;
  float* HWY_RESTRICT saved = r.scratch + p + np;  // the entering faces, 3 P, where marking
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
    const simd::Half* HWY_RESTRICT first_half = !r.first && r.first_half && !empty ? r.first_half + c * r.first_stride : nullptr;
    const float* HWY_RESTRICT factor = r.first_rows && !empty ? r.first_factor + c * static_cast<size_t>(r.first_lights) : nullptr;
    const bool linear = r.first_slope && (first || first_half || factor) && o.diamond;
    V ts[3];
    for (int e = 0; e < 3; ++e)
      ts[e] = hn::Set(d, linear ? r.albedo * sigma_t_value * r.first_slope[c * 3 + static_cast<size_t>(e)] * o.sign[e] : 0.0f);
    // Where the cell may still take the bound (r.bounded, r.mark), its entering faces are kept and,
    // if a leaving value comes out below 0, put back and the cell swept again with the bound.
    bool bound = !r.bounded || r.bounded[c * 8] != 0;
    const bool mark = o.diamond && r.mark && !bound;
    if (mark) {
      std::copy(r.x_run, r.x_run + p, saved);
      std::copy(y, y + p, saved + p);
      std::copy(z, z + p, saved + 2 * p);
    }
    for (bool again = true; again;) {
      V lowest = hn::Zero(d);
      V* HWY_RESTRICT low = mark && !bound ? &lowest : nullptr;
      for (size_t i = 0; i < p; i += 4 * lanes) {
        const size_t count = std::min<size_t>(4, (p - i) / lanes);
        // Source: the first-collision term plus lambda Q m_in, one term (a broadcast) at a time.
        V s[4];
        for (size_t v = 0; v < 4; ++v) s[v] = first && v < count ? hn::LoadU(d, first + i + v * lanes) : hn::Zero(d);
        if (first_half)
          for (size_t v = 0; v < count; ++v)
            s[v] = hn::Mul(hn::Set(d, r.first_scale[c]),
                           hn::PromoteTo(d, hn::LoadU(dh, reinterpret_cast<const hwy::float16_t*>(first_half + i + v * lanes))));
        if (factor)
          for (size_t l = 0; l < static_cast<size_t>(r.first_lights); ++l) {
            const V f = hn::Set(d, factor[l]);
            const float* HWY_RESTRICT row = r.first_rows + l * r.first_stride + i;
            for (size_t v = 0; v < count; ++v) s[v] = hn::MulAdd(f, hn::LoadU(d, row + v * lanes), s[v]);
          }
        const V fc[4] = {s[0], s[1], s[2], s[3]};  // the first-collision source alone
        if (m_in) {
          const float* HWY_RESTRICT lq = o.lq + i;
          switch (count) {
            case 1: DotRows<1>(d, lq, p, m_in, n, s); break;
            case 2: DotRows<2>(d, lq, p, m_in, n, s); break;
            case 3: DotRows<3>(d, lq, p, m_in, n, s); break;
            default: DotRows<4>(d, lq, p, m_in, n, s); break;
          }
        }
        for (size_t v = 0; o.diamond && v < count; ++v) {
          const size_t e = i + v * lanes;
          const V a[3] = {hn::LoadU(d, ax + e), hn::LoadU(d, ay + e), hn::LoadU(d, az + e)};
          const V sum = hn::Add(hn::Add(a[0], a[1]), a[2]);
          const V ss = hn::Mul(sigma_s, s[v]), pe = hn::LoadU(d, pad + e);
          const V l = linear ? Diamond<true>(d, sigma_t, ss, pe, a, sum, r.x_run + e, y + e, z + e, fc[v], ts, bound, low)
                             : Diamond<false>(d, sigma_t, ss, pe, a, sum, r.x_run + e, y + e, z + e, fc[v], ts, bound, low);
          hn::StoreU(l, d, light + e);
        }
        for (size_t v = 0; !o.diamond && v < count; ++v) {
          const size_t e = i + v * lanes;
          V in = hn::Mul(hn::LoadU(d, ax + e), hn::LoadU(d, r.x_run + e));
          in = hn::MulAdd(hn::LoadU(d, ay + e), hn::LoadU(d, y + e), in);
          in = hn::MulAdd(hn::LoadU(d, az + e), hn::LoadU(d, z + e), in);
          const V l = hn::Mul(hn::MulAdd(sigma_s, s[v], in), Reciprocal(d, hn::Add(sigma_t, hn::LoadU(d, asum + e))));
          hn::StoreU(l, d, r.x_run + e);
          hn::StoreU(l, d, y + e);
          hn::StoreU(l, d, z + e);
          hn::StoreU(l, d, light + e);
        }
      }
      again = low && !hn::AllFalse(d, hn::Lt(lowest, hn::Zero(d)));
      if (again) {
        std::copy(saved, saved + p, r.x_run);
        std::copy(saved + p, saved + 2 * p, y);
        std::copy(saved + 2 * p, saved + 3 * p, z);
        bound = true;
        r.bounded[c * 8] = 1;
      }
    }
    // Moments: lanes over terms, one direction (a broadcast) at a time, added to m_out in registers
    // where a whole vector fits in the cell's N terms (a vector stored to the scratch and read
    // back at another width stalls store-to-load forwarding), through the scratch for the rest.
    float* HWY_RESTRICT out = r.m_out + c * n;
    for (size_t k = 0; k < np; k += 4 * lanes) {
      V sum[4] = {hn::Zero(d), hn::Zero(d), hn::Zero(d), hn::Zero(d)};
      const size_t count = std::min<size_t>(4, (np - k) / lanes);
      switch (count) {
        case 1: DotRows<1>(d, o.q + k, np, light, p, sum); break;
        case 2: DotRows<2>(d, o.q + k, np, light, p, sum); break;
        case 3: DotRows<3>(d, o.q + k, np, light, p, sum); break;
        default: DotRows<4>(d, o.q + k, np, light, p, sum); break;
      }
      for (size_t v = 0; v < count; ++v) {
        const size_t at = k + v * lanes;
        if (at + lanes <= n) {
          hn::StoreU(hn::Add(hn::LoadU(d, out + at), sum[v]), d, out + at);
        } else if (at < n) {
          hn::StoreU(sum[v], d, moments + at);
          for (size_t t = at; t < n; ++t) out[t] += moments[t];
        }
      }
    }
  }
}

}  // namespace haze::grids::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // include guard
