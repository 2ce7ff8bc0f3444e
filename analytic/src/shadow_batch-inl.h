// Per-target shadow tests in float64 lanes (Highway: included once per target by foreach_target.h).
#if defined(HAZE_ANALYTIC_SHADOW_BATCH_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_ANALYTIC_SHADOW_BATCH_INL_H_
#undef HAZE_ANALYTIC_SHADOW_BATCH_INL_H_
#else
#define HAZE_ANALYTIC_SHADOW_BATCH_INL_H_
#endif

#include <haze/analytic/shadow_batch.h>

#include <hwy/highway.h>

#include <cmath>

HWY_BEFORE_NAMESPACE();
namespace haze::analytic::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

template <class D, class V>
HWY_INLINE V Dot(D, const V a[3], const Vec3& b) {
  return hn::MulAdd(a[0], hn::Set(D(), b.x), hn::MulAdd(a[1], hn::Set(D(), b.y), hn::Mul(a[2], hn::Set(D(), b.z))));
}
template <class V>
HWY_INLINE V Dot(const V a[3], const V b[3]) {
  return hn::MulAdd(a[0], b[0], hn::MulAdd(a[1], b[1], hn::Mul(a[2], b[2])));
}

// LightShadows::hidden(x, self) per lane.
template <class D, class V>
HWY_INLINE hn::Mask<D> HiddenLanes(D d, const LightShadows& shadows, const V x[3], const Surface* self) {
  const V zero = hn::Zero(d);
  V e[3];
  for (int k = 0; k < 3; ++k) e[k] = hn::Sub(hn::Set(d, shadows.light()[k]), x[k]);
  const V length2 = Dot(e, e), length = hn::Sqrt(length2);
  const V s_min = hn::Div(hn::Set(d, kSurfaceOffset), length), s_max = hn::Set(d, 1.0 - 1e-9);
  const auto within = [&](V s) { return hn::And(hn::Gt(s, s_min), hn::Lt(s, s_max)); };
  auto hidden = hn::Lt(zero, zero);
  for (const LightShadows::Face& p : shadows.planes()) {
    if (p.surface == self) continue;
    const V denom = Dot(d, e, p.normal);
    V to[3];
    for (int k = 0; k < 3; ++k) to[k] = hn::Sub(hn::Set(d, p.point[k]), x[k]);
    const V s = hn::Div(Dot(d, to, p.normal), denom);
    hidden = hn::Or(hidden, hn::And(hn::Ge(hn::Abs(denom), hn::Mul(hn::Set(d, 1e-12), length)), within(s)));
  }
  for (const LightShadows::Cone& c : shadows.spheres()) {
    if (c.surface == self) continue;
    V oc[3];
    for (int k = 0; k < 3; ++k) oc[k] = hn::Sub(x[k], hn::Set(d, c.center[k]));
    const V b = Dot(oc, e), cc = hn::Sub(Dot(oc, oc), hn::Set(d, c.r2));
    const V disc = hn::NegMulAdd(length2, cc, hn::Mul(b, b));
    const V root = hn::Sqrt(hn::Max(disc, zero));
    const V s1 = hn::Div(hn::Sub(hn::Neg(b), root), length2), s2 = hn::Div(hn::Sub(root, b), length2);
    hidden = hn::Or(hidden, hn::And(hn::Ge(disc, zero), hn::Or(within(s1), within(s2))));
  }
  return hn::And(hidden, hn::Gt(length2, zero));
}

// Whether a t^2 + b t + c = 0 has a root in (lo, hi) that keep takes (LightShadows::classify's
// roots, a near 0 leaving the linear root).
template <class D, class V, class Keep>
HWY_INLINE hn::Mask<D> RootWithin(D d, V a, V b, V c, V lo, V hi, const Keep& keep) {
  const V zero = hn::Zero(d);
  const auto in = [&](V r) { return hn::And(hn::And(hn::Gt(r, lo), hn::Lt(r, hi)), keep(r)); };
  const auto linear = hn::Lt(hn::Abs(a), hn::Set(d, 1e-300));
  const auto line = hn::And(linear, hn::And(hn::Ne(b, zero), in(hn::Div(hn::Neg(c), b))));
  const V disc = hn::NegMulAdd(hn::Mul(hn::Set(d, 4.0), a), c, hn::Mul(b, b));
  const V q = hn::Mul(hn::Set(d, -0.5), hn::Add(b, hn::CopySign(hn::Sqrt(hn::Max(disc, zero)), b)));
  const auto quadratic = hn::And(hn::Not(linear), hn::Ge(disc, zero));
  const auto two = hn::Or(in(hn::Div(q, a)), hn::And(hn::Ne(q, zero), in(hn::Div(c, q))));
  return hn::Or(line, hn::And(quadratic, two));
}

HWY_NOINLINE void ClassifyStretches(const LightShadows& shadows, const ShadowRays& rays, float* HWY_RESTRICT out) {
  const hn::ScalableTag<double> d;
  const hn::Rebind<float, decltype(d)> df;
  using V = hn::Vec<decltype(d)>;
  const size_t lanes = hn::Lanes(d);
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), inf = hn::Set(d, HUGE_VAL);
  const auto any = [&](V) { return hn::Eq(zero, zero); };
  for (size_t i = 0; i < rays.count; i += lanes) {
    V o[3], v[3];
    for (int k = 0; k < 3; ++k) o[k] = hn::LoadU(d, rays.o[k] + i), v[k] = hn::LoadU(d, rays.d[k] + i);
    const V t0 = hn::LoadU(d, rays.t0 + i), t1 = hn::LoadU(d, rays.t1 + i);
    const auto finite = hn::Lt(t1, inf);
    // Edges within 1e-6 of the stretch of its ends are decided with the rest (classify's margin).
    const V margin = hn::Mul(hn::Set(d, 1e-6), hn::IfThenElse(finite, hn::Sub(t1, t0), hn::Add(one, hn::Abs(t0))));
    const V lo = hn::Add(t0, margin), hi = hn::Sub(t1, margin);
    const V dd = Dot(v, v);
    auto partial = hn::Lt(zero, zero);
    for (const LightShadows::Face& p : shadows.planes()) {
      V op[3];
      for (int k = 0; k < 3; ++k) op[k] = hn::Sub(o[k], hn::Set(d, p.point[k]));
      partial = hn::Or(partial, RootWithin(d, zero, Dot(d, v, p.normal), Dot(d, op, p.normal), lo, hi, any));
    }
    V w[3];
    for (int k = 0; k < 3; ++k) w[k] = hn::Sub(o[k], hn::Set(d, shadows.light()[k]));
    for (const LightShadows::Cone& c : shadows.spheres()) {
      V oc[3];
      for (int k = 0; k < 3; ++k) oc[k] = hn::Sub(o[k], hn::Set(d, c.center[k]));
      partial = hn::Or(partial, RootWithin(d, dd, hn::Add(Dot(oc, v), Dot(oc, v)), hn::Sub(Dot(oc, oc), hn::Set(d, c.r2)), lo, hi, any));
      if (c.cos2 == 0.0) continue;  // the light inside: the sphere's surface is the only edge
      const V dv = Dot(d, v, c.axis), wv = Dot(d, w, c.axis), cos2 = hn::Set(d, c.cos2);
      const V circle = hn::Set(d, std::sqrt(c.r2 / (1.0 - c.cos2)) * c.cos2);  // past the tangent circle
      const auto beyond = [&](V t) { return hn::Gt(hn::MulAdd(t, dv, wv), circle); };
      partial = hn::Or(partial, RootWithin(d, hn::NegMulAdd(cos2, dd, hn::Mul(dv, dv)),
                                           hn::Mul(hn::Set(d, 2.0), hn::NegMulAdd(cos2, Dot(w, v), hn::Mul(wv, dv))),
                                           hn::NegMulAdd(cos2, Dot(w, w), hn::Mul(wv, wv)), lo, hi, beyond));
    }
    const V mid = hn::IfThenElse(finite, hn::Mul(hn::Set(d, 0.5), hn::Add(t0, t1)), hn::Add(t0, hn::Add(one, hn::Abs(t0))));
    V x[3];
    for (int k = 0; k < 3; ++k) x[k] = hn::MulAdd(mid, v[k], o[k]);
    const auto dark = HiddenLanes(d, shadows, x, nullptr);
    const V stretch = hn::IfThenElseZero(hn::Gt(t1, t0), hn::IfThenElse(partial, hn::Set(d, 2.0), hn::IfThenElseZero(dark, one)));
    hn::StoreU(hn::DemoteTo(df, stretch), df, out + i);
  }
}

HWY_NOINLINE void LightVisible(const LightShadows& shadows, const double* const* x, size_t count, const Surface* self, float* HWY_RESTRICT out) {
  const hn::ScalableTag<double> d;
  const hn::Rebind<float, decltype(d)> df;
  using V = hn::Vec<decltype(d)>;
  const size_t lanes = hn::Lanes(d);
  for (size_t i = 0; i < count; i += lanes) {
    V p[3];
    for (int k = 0; k < 3; ++k) p[k] = hn::LoadU(d, x[k] + i);
    const V seen = hn::IfThenZeroElse(HiddenLanes(d, shadows, p, self), hn::Set(d, 1.0));
    hn::StoreU(hn::DemoteTo(df, seen), df, out + i);
  }
}

}  // namespace haze::analytic::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HAZE_ANALYTIC_SHADOW_BATCH_INL_H_
