// Per-target airlight kernel (Highway: included once per target by foreach_target.h).
#if defined(HAZE_ANALYTIC_AIRLIGHT_BATCH_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_ANALYTIC_AIRLIGHT_BATCH_INL_H_
#undef HAZE_ANALYTIC_AIRLIGHT_BATCH_INL_H_
#else
#define HAZE_ANALYTIC_AIRLIGHT_BATCH_INL_H_
#endif

#include <haze/analytic/airlight_batch.h>

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include <algorithm>

HWY_BEFORE_NAMESPACE();
namespace haze::analytic::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// log T(u, eta) for T = K (1 + w)(1 + a) / 2, bilinear in the fine log table
// (AirlightTable::log_fine_values); `scale` = 2 / ((1 + w)(1 + a)), so that K = scale e^(log T).
template <class D, class V>
HWY_INLINE V LogTail(D d, const float* HWY_RESTRICT table, int na, int ne, float eta_max, V u, V eta, V w, V& scale) {
  const hn::RebindToSigned<D> di;
  const V one = hn::Set(d, 1.0f);
  V a = hn::Min(hn::Mul(u, hn::Add(one, w)), hn::Set(d, 1e30f));
  V m = hn::Sqrt(hn::Div(a, hn::Add(one, a)));
  V fa = hn::Mul(m, hn::Set(d, static_cast<float>(na - 1)));
  V e = hn::Min(hn::Max(eta, hn::Set(d, -eta_max)), hn::Set(d, eta_max));
  V fe = hn::Mul(hn::Add(e, hn::Set(d, eta_max)), hn::Set(d, static_cast<float>(ne - 1) / (2.0f * eta_max)));
  V fi = hn::Min(hn::Floor(fa), hn::Set(d, static_cast<float>(na - 2)));
  V fj = hn::Min(hn::Floor(fe), hn::Set(d, static_cast<float>(ne - 2)));
  V x = hn::Sub(fa, fi), y = hn::Sub(fe, fj);
  // The table is eta fastest: the next a is ne values on, the next eta the next value.
  auto index = hn::ConvertTo(di, hn::MulAdd(fi, hn::Set(d, static_cast<float>(ne)), fj));
  V t00 = hn::GatherIndex(d, table, index), t10 = hn::GatherIndex(d, table + ne, index);
  V t01 = hn::GatherIndex(d, table + 1, index), t11 = hn::GatherIndex(d, table + ne + 1, index);
  V t0 = hn::MulAdd(x, hn::Sub(t10, t00), t00), t1 = hn::MulAdd(x, hn::Sub(t11, t01), t01);
  scale = hn::Div(hn::Set(d, 2.0f), hn::Mul(hn::Add(one, w), hn::Add(one, a)));
  return hn::MulAdd(y, hn::Sub(t1, t0), t0);
}

// Processes whole vectors of segments; returns how many. result[i] is the airlight, fallback[i] is
// 1 where the float64 path must redo it.
HWY_NOINLINE size_t AirlightBatch(const float* HWY_RESTRICT table, int na, int ne, float eta_max, const float* light,
                                  const float* HWY_RESTRICT ox, const float* HWY_RESTRICT oy, const float* HWY_RESTRICT oz,
                                  const float* HWY_RESTRICT dx, const float* HWY_RESTRICT dy, const float* HWY_RESTRICT dz,
                                  const float* HWY_RESTRICT length, size_t count, float* HWY_RESTRICT result,
                                  float* HWY_RESTRICT fallback) {
  const hn::ScalableTag<float> d;
  using V = hn::Vec<decltype(d)>;
  const size_t lanes = hn::Lanes(d);
  const V lx = hn::Set(d, light[0]), ly = hn::Set(d, light[1]), lz = hn::Set(d, light[2]);
  const V sigma_t = hn::Set(d, light[3]), scale = hn::Set(d, light[4] * light[5]);
  const V zero = hn::Zero(d), half = hn::Set(d, 0.5f);
  size_t i = 0;
  for (; i + lanes <= count; i += lanes) {
    V tx = hn::Sub(lx, hn::LoadU(d, ox + i)), ty = hn::Sub(ly, hn::LoadU(d, oy + i)), tz = hn::Sub(lz, hn::LoadU(d, oz + i));
    V vx = hn::LoadU(d, dx + i), vy = hn::LoadU(d, dy + i), vz = hn::LoadU(d, dz + i);
    V d2 = hn::MulAdd(tx, tx, hn::MulAdd(ty, ty, hn::Mul(tz, tz)));
    V d_sv = hn::Sqrt(d2);
    V t = hn::MulAdd(tx, vx, hn::MulAdd(ty, vy, hn::Mul(tz, vz)));
    V floor_h = hn::Mul(hn::Set(d, 1e-6f), d_sv);
    V h2 = hn::Max(hn::NegMulAdd(t, t, d2), hn::Mul(floor_h, floor_h));
    V h = hn::Sqrt(h2);
    V u = hn::Mul(sigma_t, h);
    // w = (xi + r) / h without cancellation (xi = -t at the start).
    V w0 = hn::IfThenElse(hn::Le(t, zero), hn::Div(hn::Sub(d_sv, t), h), hn::Div(h, hn::Add(d_sv, t)));
    V scale_near, scale_far;
    V log_near = LogTail(d, table, na, ne, eta_max, u, hn::Log(d, w0), w0, scale_near);
    V near = hn::Mul(hn::Exp(d, hn::NegMulAdd(sigma_t, d_sv, log_near)), scale_near);
    V len = hn::LoadU(d, length + i);
    auto finite = hn::Lt(len, hn::Set(d, 3e38f));
    V len_f = hn::IfThenElseZero(finite, len);
    V xi = hn::Sub(len_f, t);
    V d_sp = hn::Sqrt(hn::MulAdd(xi, xi, h2));
    V wd = hn::IfThenElse(hn::Ge(xi, zero), hn::Div(hn::Add(xi, d_sp), h), hn::Div(h, hn::Sub(d_sp, xi)));
    V log_far = LogTail(d, table, na, ne, eta_max, u, hn::Log(d, wd), wd, scale_far);
    V far = hn::Mul(hn::Exp(d, hn::NegMulAdd(sigma_t, hn::Add(len_f, d_sp), log_far)), scale_far);
    far = hn::IfThenElseZero(finite, far);
    hn::StoreU(hn::Div(hn::Mul(scale, hn::Sub(near, far)), h), d, result + i);
    auto redo = hn::Or(hn::Ge(far, hn::Mul(half, near)), hn::Lt(h, hn::Mul(hn::Set(d, 1e-3f), d_sv)));
    hn::StoreU(hn::IfThenElseZero(redo, hn::Set(d, 1.0f)), d, fallback + i);
  }
  return i;
}

// The unit tail g(d) = G(d) / (sigma_s I) of rays whose light projects to t_c along them at
// distance h_c from their lines, at distances `at` (airlight_batch.h, TailRow).
template <class D, class V>
HWY_INLINE V UnitTail(D d, const float* HWY_RESTRICT table, int na, int ne, float eta_max, V t_c, V h_c, V sigma, V at) {
  const V zero = hn::Zero(d);
  const V t = hn::Sub(t_c, at);
  const V d_sv = hn::Sqrt(hn::MulAdd(t, t, hn::Mul(h_c, h_c)));
  const V h = hn::Max(hn::Max(h_c, hn::Mul(hn::Set(d, 1e-6f), d_sv)), hn::Set(d, 1e-20f));
  // w = (xi + r) / h without cancellation (xi = -t), floored where the point sits on the light.
  const auto behind = hn::Le(t, zero);
  const V w0 = hn::Max(hn::Div(hn::IfThenElse(behind, hn::Sub(d_sv, t), h), hn::IfThenElse(behind, h, hn::Add(d_sv, t))), hn::Set(d, 1e-30f));
  V scale;
  const V log_tail = LogTail(d, table, na, ne, eta_max, hn::Mul(sigma, h), hn::Log(d, w0), w0, scale);
  return hn::Div(hn::Mul(hn::Exp(d, hn::NegMulAdd(sigma, d_sv, log_tail)), scale), h);
}

// s_c = sum over the row's lights of weight[c] g(at), for the vector of rays at i.
template <class D, class V>
HWY_INLINE void SumTails(D d, const float* HWY_RESTRICT table, int na, int ne, float eta_max, const TailRow& row, size_t i, V at,
                         V& s0, V& s1, V& s2) {
  s0 = s1 = s2 = hn::Zero(d);
  for (size_t l = 0; l < row.light_count; ++l) {
    const TailLight& light = row.lights[l];
    V g = UnitTail(d, table, na, ne, eta_max, hn::LoadU(d, light.t + i), hn::LoadU(d, light.h + i), hn::Set(d, light.sigma_t), at);
    if (light.share) g = hn::Mul(g, hn::LoadU(d, light.share + i));
    s0 = hn::MulAdd(hn::Set(d, light.weight[0]), g, s0);
    s1 = hn::MulAdd(hn::Set(d, light.weight[1]), g, s1);
    s2 = hn::MulAdd(hn::Set(d, light.weight[2]), g, s2);
  }
}

HWY_NOINLINE void TailSums(const float* HWY_RESTRICT table, int na, int ne, float eta_max, const TailRow& row, const float* at,
                           float* const* sums) {
  const hn::ScalableTag<float> d;
  for (size_t i = 0; i < row.count; i += hn::Lanes(d)) {
    hn::Vec<decltype(d)> s0, s1, s2;
    SumTails(d, table, na, ne, eta_max, row, i, hn::LoadU(d, at + i), s0, s1, s2);
    hn::StoreU(s0, d, sums[0] + i), hn::StoreU(s1, d, sums[1] + i), hn::StoreU(s2, d, sums[2] + i);
  }
}

// Slices `distances` of the row, a vector of rays through every slice before the next vector:
// a ray's neighbouring slices look up neighbouring table values, still in cache.
HWY_NOINLINE void AirlightSlices(const float* HWY_RESTRICT table, int na, int ne, float eta_max, const TailRow& row, const float* distances,
                                 size_t slices, float* HWY_RESTRICT inscatter, float* HWY_RESTRICT transmittance, size_t slice_stride) {
  const hn::ScalableTag<float> d;
  using V = hn::Vec<decltype(d)>;
  const size_t lanes = hn::Lanes(d);
  const bool grey = row.sigma_t[0] == row.sigma_t[1] && row.sigma_t[1] == row.sigma_t[2];
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0f);
  HWY_ALIGN float tail[3 * HWY_MAX_BYTES / sizeof(float)];
  for (size_t i = 0; i < row.count; i += lanes) {
    const V t0 = hn::LoadU(d, row.t0 + i), t1 = hn::LoadU(d, row.t1 + i);
    const V whole0 = hn::LoadU(d, row.whole[0] + i), whole1 = hn::LoadU(d, row.whole[1] + i), whole2 = hn::LoadU(d, row.whole[2] + i);
    for (size_t k = 0; k < slices; ++k) {
      const V at_slice = hn::Set(d, distances[k]);
      const auto outside = hn::Or(hn::Le(at_slice, t0), hn::Le(t1, t0));
      const V at = hn::Min(hn::Max(at_slice, t0), t1), inside = hn::Sub(at, t0);
      V s0, s1, s2;
      SumTails(d, table, na, ne, eta_max, row, i, at, s0, s1, s2);
      const V T0 = hn::Exp(d, hn::Mul(hn::Set(d, -row.sigma_t[0]), inside));
      const V T1 = grey ? T0 : hn::Exp(d, hn::Mul(hn::Set(d, -row.sigma_t[1]), inside));
      const V T2 = grey ? T0 : hn::Exp(d, hn::Mul(hn::Set(d, -row.sigma_t[2]), inside));
      const V l0 = hn::IfThenZeroElse(outside, hn::Max(zero, hn::NegMulAdd(T0, s0, whole0)));
      const V l1 = hn::IfThenZeroElse(outside, hn::Max(zero, hn::NegMulAdd(T1, s1, whole1)));
      const V l2 = hn::IfThenZeroElse(outside, hn::Max(zero, hn::NegMulAdd(T2, s2, whole2)));
      const V u0 = hn::IfThenElse(outside, one, T0), u1 = hn::IfThenElse(outside, one, T1), u2 = hn::IfThenElse(outside, one, T2);
      float* const l_out = inscatter + k * slice_stride + 3 * i;
      float* const t_out = transmittance + k * slice_stride + 3 * i;
      if (i + lanes <= row.count) {
        hn::StoreInterleaved3(l0, l1, l2, d, l_out);
        hn::StoreInterleaved3(u0, u1, u2, d, t_out);
      } else {  // the row's last, partial vector
        const size_t n = 3 * (row.count - i);
        hn::StoreInterleaved3(l0, l1, l2, d, tail);
        std::copy_n(tail, n, l_out);
        hn::StoreInterleaved3(u0, u1, u2, d, tail);
        std::copy_n(tail, n, t_out);
      }
    }
  }
}

}  // namespace haze::analytic::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HAZE_ANALYTIC_AIRLIGHT_BATCH_INL_H_
