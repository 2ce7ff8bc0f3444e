// Per-target airlight kernel (Highway: included once per target by foreach_target.h).
#if defined(HAZE_ANALYTIC_AIRLIGHT_BATCH_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_ANALYTIC_AIRLIGHT_BATCH_INL_H_
#undef HAZE_ANALYTIC_AIRLIGHT_BATCH_INL_H_
#else
#define HAZE_ANALYTIC_AIRLIGHT_BATCH_INL_H_
#endif

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

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
  auto index = hn::ConvertTo(di, hn::MulAdd(fj, hn::Set(d, static_cast<float>(na)), fi));
  V t00 = hn::GatherIndex(d, table, index), t10 = hn::GatherIndex(d, table + 1, index);
  V t01 = hn::GatherIndex(d, table + na, index), t11 = hn::GatherIndex(d, table + na + 1, index);
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

}  // namespace haze::analytic::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HAZE_ANALYTIC_AIRLIGHT_BATCH_INL_H_
