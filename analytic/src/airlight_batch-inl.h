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
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <vector>

HWY_BEFORE_NAMESPACE();
namespace haze::analytic::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The four corners of each lane's cell (row fi, column fj at index = fi ne + fj) in the paired
// table (AirlightTable::log_fine_pairs: t00, t10, t01, t11 in 16 bytes at float 2 index). Eight
// or four lanes: a 16-byte load per lane and a 4 x 4 transpose per block, about a quarter of the
// cost of four gathers on AVX2 (whose gathers take a cycle or more per lane).
template <class D, class V, class VI>
HWY_INLINE void Corners(D d, const float* HWY_RESTRICT table, VI index, V& t00, V& t10, V& t01, V& t11) {
#if HWY_TARGET != HWY_SCALAR
  constexpr size_t kLanes = hn::MaxLanes(D());
  if constexpr (kLanes == 4 || kLanes == 8) {
    const hn::RebindToSigned<D> di;
    const hn::Repartition<double, D> dd;
    HWY_ALIGN int32_t at[kLanes];
    hn::Store(hn::Add(index, index), di, at);
    V r[4];
    if constexpr (kLanes == 8) {
      const hn::FixedTag<float, 4> d4;
      for (int q = 0; q < 4; ++q) r[q] = hn::Combine(d, hn::LoadU(d4, table + at[q + 4]), hn::LoadU(d4, table + at[q]));
    } else {
      for (int q = 0; q < 4; ++q) r[q] = hn::LoadU(d, table + at[q]);
    }
    // Per 128-bit block: lanes q of r[q] -> t00 t10 t01 t11 of lanes 0..3.
    const V lo01 = hn::InterleaveLower(d, r[0], r[1]), lo23 = hn::InterleaveLower(d, r[2], r[3]);
    const V hi01 = hn::InterleaveUpper(d, r[0], r[1]), hi23 = hn::InterleaveUpper(d, r[2], r[3]);
    t00 = hn::BitCast(d, hn::InterleaveLower(dd, hn::BitCast(dd, lo01), hn::BitCast(dd, lo23)));
    t10 = hn::BitCast(d, hn::InterleaveUpper(dd, hn::BitCast(dd, lo01), hn::BitCast(dd, lo23)));
    t01 = hn::BitCast(d, hn::InterleaveLower(dd, hn::BitCast(dd, hi01), hn::BitCast(dd, hi23)));
    t11 = hn::BitCast(d, hn::InterleaveUpper(dd, hn::BitCast(dd, hi01), hn::BitCast(dd, hi23)));
    return;
  }
#endif
  {
    const VI at = hn::Add(index, index);
    t00 = hn::GatherIndex(d, table, at), t10 = hn::GatherIndex(d, table + 1, at);
    t01 = hn::GatherIndex(d, table + 2, at), t11 = hn::GatherIndex(d, table + 3, at);
  }
}

// log T(u, eta) for T = K (1 + w)(1 + a) / 2, bilinear in the fine log table
// (AirlightTable::log_fine_pairs); `scale` = 2 / ((1 + w)(1 + a)), so that K = scale e^(log T).
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
  V t00, t10, t01, t11;
  Corners(d, table, hn::ConvertTo(di, hn::MulAdd(fi, hn::Set(d, static_cast<float>(ne)), fj)), t00, t10, t01, t11);
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
// N vectors of rays at once, step by step across the N: N independent chains in program order,
// which the CPU overlaps (one chain alone is a long run of dependent latencies). The geometry
// (TailGeometry: d_sv, h, w and the eta coordinate) does not depend on sigma_t: a coloured
// medium's three channels of one light share it.
template <int N, class D, class V>
struct TailGeometry {
  V d_sv[N], h[N], w[N], y[N];
  hn::Vec<hn::RebindToSigned<D>> fj[N];
};
template <int N, class D, class V>
HWY_INLINE void TailGeometryN(D d, int ne, float eta_max, const V* t_c, const V* h_c, const V* at, TailGeometry<N, D, V>& g) {
  const hn::RebindToSigned<D> di;
  const V zero = hn::Zero(d);
  for (int n = 0; n < N; ++n) {
    const V t = hn::Sub(t_c[n], at[n]);
    g.d_sv[n] = hn::Sqrt(hn::MulAdd(t, t, hn::Mul(h_c[n], h_c[n])));
    g.h[n] = hn::Max(hn::Max(h_c[n], hn::Mul(hn::Set(d, 1e-6f), g.d_sv[n])), hn::Set(d, 1e-20f));
    // w = (xi + r) / h without cancellation (xi = -t), floored where the point sits on the light.
    const auto behind = hn::Le(t, zero);
    g.w[n] = hn::Max(hn::Div(hn::IfThenElse(behind, hn::Sub(g.d_sv[n], t), g.h[n]), hn::IfThenElse(behind, g.h[n], hn::Add(g.d_sv[n], t))),
                     hn::Set(d, 1e-30f));
    const V e = hn::Min(hn::Max(hn::Log(d, g.w[n]), hn::Set(d, -eta_max)), hn::Set(d, eta_max));
    const V fe = hn::Mul(hn::Add(e, hn::Set(d, eta_max)), hn::Set(d, static_cast<float>(ne - 1) / (2.0f * eta_max)));
    const V fj = hn::Min(hn::Floor(fe), hn::Set(d, static_cast<float>(ne - 2)));
    g.y[n] = hn::Sub(fe, fj), g.fj[n] = hn::ConvertTo(di, fj);
  }
}
// LogTail's lookup for sigma, N at a time, from the shared geometry.
template <int N, class D, class V>
HWY_INLINE void UnitTailsFrom(D d, const float* HWY_RESTRICT table, int na, int ne, const TailGeometry<N, D, V>& g, V sigma, V* out) {
  const hn::RebindToSigned<D> di;
  const V one = hn::Set(d, 1.0f);
  hn::Vec<decltype(di)> index[N];
  V x[N], a[N];
  for (int n = 0; n < N; ++n) {
    a[n] = hn::Min(hn::Mul(hn::Mul(sigma, g.h[n]), hn::Add(one, g.w[n])), hn::Set(d, 1e30f));
    const V fa = hn::Mul(hn::Sqrt(hn::Div(a[n], hn::Add(one, a[n]))), hn::Set(d, static_cast<float>(na - 1)));
    const V fi = hn::Min(hn::Floor(fa), hn::Set(d, static_cast<float>(na - 2)));
    x[n] = hn::Sub(fa, fi);
    index[n] = hn::Add(hn::Mul(hn::ConvertTo(di, fi), hn::Set(di, ne)), g.fj[n]);
  }
  for (int n = 0; n < N; ++n) {
    V t00, t10, t01, t11;
    Corners(d, table, index[n], t00, t10, t01, t11);
    const V t0 = hn::MulAdd(x[n], hn::Sub(t10, t00), t00), t1 = hn::MulAdd(x[n], hn::Sub(t11, t01), t01);
    const V log_tail = hn::MulAdd(g.y[n], hn::Sub(t1, t0), t0);
    const V scale = hn::Div(hn::Set(d, 2.0f), hn::Mul(hn::Mul(hn::Add(one, g.w[n]), hn::Add(one, a[n])), g.h[n]));
    out[n] = hn::Mul(hn::Exp(d, hn::NegMulAdd(sigma, g.d_sv[n], log_tail)), scale);
  }
}
// s[n][c] = sum over the row's lights of weight[c] g(at[n]), for the N vectors of rays at offsets i[n].
template <int N, class D, class V>
HWY_INLINE void SumTailsN(D d, const float* HWY_RESTRICT table, int na, int ne, float eta_max, const TailRow& row, const size_t* i, const V* at,
                          V (*s)[3]) {
  for (int n = 0; n < N; ++n) s[n][0] = s[n][1] = s[n][2] = hn::Zero(d);
  TailGeometry<N, D, V> geometry;
  const float *t = nullptr, *h = nullptr;  // whose geometry it holds
  for (size_t l = 0; l < row.light_count; ++l) {
    const TailLight& light = row.lights[l];
    if (light.t != t || light.h != h) {
      V t_c[N], h_c[N];
      for (int n = 0; n < N; ++n) t_c[n] = hn::LoadU(d, light.t + i[n]), h_c[n] = hn::LoadU(d, light.h + i[n]);
      TailGeometryN<N>(d, ne, eta_max, t_c, h_c, at, geometry);
      t = light.t, h = light.h;
    }
    V g[N];
    UnitTailsFrom<N>(d, table, na, ne, geometry, hn::Set(d, light.sigma_t), g);
    for (int n = 0; n < N; ++n) {
      if (light.share) g[n] = hn::Mul(g[n], hn::LoadU(d, light.share + i[n]));
      for (int c = 0; c < 3; ++c) s[n][c] = hn::MulAdd(hn::Set(d, light.weight[c]), g[n], s[n][c]);
    }
  }
}

// Chains UnitTailsFrom interleaves: four fill the out-of-order window on AVX-512 (1.3x over one).
constexpr int kChains = 4;
// AirlightSlices' lattice: its anchors every kTop-th slice (4, with a level between, was slower:
// few of those slices are smooth enough).
constexpr size_t kTop = 2;

HWY_NOINLINE void TailSums(const float* HWY_RESTRICT table, int na, int ne, float eta_max, const TailRow& row, const float* at,
                           float* const* sums) {
  const hn::ScalableTag<float> d;
  using V = hn::Vec<decltype(d)>;
  const size_t lanes = hn::Lanes(d);
  for (size_t i0 = 0; i0 < row.count; i0 += kChains * lanes) {
    size_t i[kChains];
    V at_i[kChains], s[kChains][3];
    for (int n = 0; n < kChains; ++n) {
      i[n] = std::min(i0 + n * lanes, i0 + (row.count - 1 - i0) / lanes * lanes);  // past the end: the last vector again
      at_i[n] = hn::LoadU(d, at + i[n]);
    }
    SumTailsN<kChains>(d, table, na, ne, eta_max, row, i, at_i, s);
    for (int n = 0; n < kChains && i0 + n * lanes < row.count; ++n)
      for (int c = 0; c < 3; ++c) hn::StoreU(s[n][c], d, sums[c] + i[n]);
  }
}

// Slices `distances` of the row, a vector of rays through every slice before the next vector:
// a ray's neighbouring slices look up neighbouring table values, still in cache. The tails of
// the even slices (and the last) are evaluated, four slices at a time; an odd slice k between
// them takes the cubic through slices k - 3, k - 1, k + 1 and k + 3 where, in every lane and
// channel, T(k) times that cubic's error estimated from the fourth differences about it is
// within kSliceTolerance of the whole ray's in-scatter (airlight_batch.h), else its own tails.
HWY_NOINLINE void AirlightSlices(const float* HWY_RESTRICT table, int na, int ne, float eta_max, const TailRow& row, const float* distances,
                                 size_t slices, float* HWY_RESTRICT inscatter, float* HWY_RESTRICT transmittance, size_t slice_stride) {
  const hn::ScalableTag<float> d;
  using V = hn::Vec<decltype(d)>;
  const size_t lanes = hn::Lanes(d);
  const bool grey = row.sigma_t[0] == row.sigma_t[1] && row.sigma_t[1] == row.sigma_t[2];
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0f);
  HWY_ALIGN float tail[3 * HWY_MAX_BYTES / sizeof(float)];
  // Per slice of the vector of rays: T and the tails' sums s per channel (kept: a frame allocates nothing).
  thread_local std::vector<float> kept;
  kept.resize(6 * slices * lanes + lanes);
  const size_t misaligned = reinterpret_cast<uintptr_t>(kept.data()) / sizeof(float) % lanes;
  float* const HWY_RESTRICT t_of = kept.data() + (misaligned ? lanes - misaligned : 0);
  float* const HWY_RESTRICT s_of = t_of + 3 * slices * lanes;
  const auto at_slice = [&](size_t k) { return hn::Set(d, distances[std::min(k, slices - 1)]); };
  // Slice k's channel c of T or s.
  const auto T_at = [&](size_t k, size_t c) { return t_of + (3 * k + c) * lanes; };
  const auto s_at = [&](size_t k, size_t c) { return s_of + (3 * k + c) * lanes; };
  constexpr int kN = kChains;
  size_t todo[kN + 1];  // slices whose tails are evaluated: a group of anchors (and the last slice), or up to kN
  for (size_t i = 0; i < row.count; i += lanes) {
    const V t0 = hn::LoadU(d, row.t0 + i), t1 = hn::LoadU(d, row.t1 + i);
    const V whole[3] = {hn::LoadU(d, row.whole[0] + i), hn::LoadU(d, row.whole[1] + i), hn::LoadU(d, row.whole[2] + i)};
    for (size_t k = 0; k < slices; ++k) {
      const V inside = hn::Sub(hn::Min(hn::Max(at_slice(k), t0), t1), t0);
      const V T0 = hn::Exp(d, hn::Mul(hn::Set(d, -row.sigma_t[0]), inside));
      hn::Store(T0, d, T_at(k, 0));
      hn::Store(grey ? T0 : hn::Exp(d, hn::Mul(hn::Set(d, -row.sigma_t[1]), inside)), d, T_at(k, 1));
      hn::Store(grey ? T0 : hn::Exp(d, hn::Mul(hn::Set(d, -row.sigma_t[2]), inside)), d, T_at(k, 2));
    }
    // The sums of slices todo[0, n), kN at a time (the last group padded with its last slice).
    const auto evaluate = [&](size_t n) {
      for (size_t g = 0; g < n; g += kN) {
        size_t same[kN], k[kN];
        V at[kN], s[kN][3];
        for (int m = 0; m < kN; ++m) {
          same[m] = i, k[m] = todo[std::min(g + m, n - 1)];
          at[m] = hn::Min(hn::Max(at_slice(k[m]), t0), t1);
        }
        SumTailsN<kN>(d, table, na, ne, eta_max, row, same, at, s);
        for (int m = 0; m < kN; ++m)
          for (size_t c = 0; c < 3; ++c) hn::Store(s[m][c], d, s_at(k[m], c));
      }
    };
    // The lattice's anchors, every kTop-th slice and the last, in groups; once T g is below 1e-6
    // of g(t0) in every lane and channel at a group's last slice, L_in is g(t0) to that from
    // there on and the further slices skip their tails (both factors only fall with distance): s
    // 0 from `spent`.
    size_t spent = slices;
    for (size_t k0 = 0; k0 < slices && spent == slices; k0 += kTop * kN) {
      size_t n = 0;
      for (size_t k = k0; k < std::min(k0 + kTop * kN, slices); k += kTop) todo[n++] = k;
      if (k0 + kTop * kN >= slices && (slices - 1) % kTop != 0) todo[n++] = slices - 1;
      evaluate(n);
      const size_t last = todo[n - 1];
      auto small = hn::Not(hn::FirstN(d, 0));
      for (size_t c = 0; c < 3; ++c)
        small = hn::And(small, hn::Le(hn::Mul(hn::Load(d, T_at(last, c)), hn::Load(d, s_at(last, c))), hn::Mul(hn::Set(d, 1e-6f), whole[c])));
      if (hn::AllTrue(d, small)) spent = last + 1;
    }
    for (size_t k = spent; k < slices; ++k)
      for (size_t c = 0; c < 3; ++c) hn::Store(zero, d, s_at(k, c));
    // Then the slices halfway between known ones, h = kTop / 2, ..., 1 apart from them: each the
    // cubic through k - 3h, k - h, k + h and k + 3h where sure, else its own tails.
    for (size_t h = kTop / 2; h >= 1; h /= 2) {
      size_t n = 0;
      for (size_t k = h; k + 1 < spent; k += 2 * h) {
        const bool before = k >= 5 * h, after = k + 5 * h < slices;
        bool sure = k >= 3 * h && k + 3 * h < slices && (before || after);
        if (sure) {  // no ray's entry or exit within the cubic's nodes: s bends there (it is constant outside)
          const V from = at_slice(k - 3 * h), to = at_slice(k + 3 * h);
          sure = hn::AllFalse(d, hn::Or(hn::And(hn::Lt(from, t0), hn::Lt(t0, to)), hn::And(hn::Lt(from, t1), hn::Lt(t1, to))));
        }
        V cubic[3];
        for (size_t c = 0; c < 3 && sure; ++c) {
          const V a = hn::Load(d, s_at(k - 3 * h, c)), b = hn::Load(d, s_at(k - h, c)), e = hn::Load(d, s_at(k + h, c));
          const V f = hn::Load(d, s_at(k + 3 * h, c));
          cubic[c] = hn::Mul(hn::Sub(hn::Mul(hn::Set(d, 9.0f), hn::Add(b, e)), hn::Add(a, f)), hn::Set(d, 1.0f / 16.0f));
          // The cubic's error from the fourth differences about it: 3/128 of one (the error is
          // 9/24 (2h)^4 s'''' at the middle of nodes 2h apart, the difference 16 (2h)^4 s''''), doubled.
          const V inner = hn::MulAdd(hn::Set(d, 6.0f), e, hn::NegMulAdd(hn::Set(d, 4.0f), hn::Add(b, f), a));       // a - 4 b + 6 e - 4 f
          const V inner_back = hn::MulAdd(hn::Set(d, 6.0f), b, hn::NegMulAdd(hn::Set(d, 4.0f), hn::Add(a, e), f));  // f - 4 e + 6 b - 4 a
          V fourth = zero;
          if (after) fourth = hn::Abs(hn::Add(inner, hn::Load(d, s_at(k + 5 * h, c))));
          if (before) fourth = hn::Max(fourth, hn::Abs(hn::Add(inner_back, hn::Load(d, s_at(k - 5 * h, c)))));
          const V error = hn::Mul(hn::Mul(hn::Load(d, T_at(k, c)), fourth), hn::Set(d, 6.0f / 128.0f));
          sure = hn::AllTrue(d, hn::Le(error, hn::Mul(hn::Set(d, kSliceTolerance), whole[c])));
        }
        if (sure) {
          for (size_t c = 0; c < 3; ++c) hn::Store(cubic[c], d, s_at(k, c));
        } else {
          todo[n++] = k;
          if (n == static_cast<size_t>(kN)) evaluate(n), n = 0;
        }
      }
      if (n > 0) evaluate(n);
    }
    for (size_t k = 0; k < slices; ++k) {
      const auto outside = hn::Or(hn::Le(at_slice(k), t0), hn::Le(t1, t0));
      V l[3], u[3];
      for (size_t c = 0; c < 3; ++c) {
        const V T = hn::Load(d, T_at(k, c));
        l[c] = hn::IfThenZeroElse(outside, hn::Max(zero, hn::NegMulAdd(T, hn::Load(d, s_at(k, c)), whole[c])));
        u[c] = hn::IfThenElse(outside, one, T);
      }
      float* const l_out = inscatter + k * slice_stride + 3 * i;
      float* const t_out = transmittance + k * slice_stride + 3 * i;
      if (i + lanes <= row.count) {
        hn::StoreInterleaved3(l[0], l[1], l[2], d, l_out);
        hn::StoreInterleaved3(u[0], u[1], u[2], d, t_out);
      } else {  // the row's last, partial vector
        const size_t m = 3 * (row.count - i);
        hn::StoreInterleaved3(l[0], l[1], l[2], d, tail);
        std::copy_n(tail, m, l_out);
        hn::StoreInterleaved3(u[0], u[1], u[2], d, tail);
        std::copy_n(tail, m, t_out);
      }
    }
  }
}

// layers_from_tails (airlight_batch.h).
HWY_NOINLINE void LayersFromTails(const TailRow& row, const float* HWY_RESTRICT ends, const float* const* sums, float* HWY_RESTRICT inscatter,
                                  float* HWY_RESTRICT transmittance, float* HWY_RESTRICT redo) {
  const hn::ScalableTag<float> d;
  using V = hn::Vec<decltype(d)>;
  const size_t lanes = hn::Lanes(d);
  const bool grey = row.sigma_t[0] == row.sigma_t[1] && row.sigma_t[1] == row.sigma_t[2];
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0f), cancel = hn::Set(d, kTailsCancel);
  for (size_t i = 0; i < row.count; i += lanes) {
    const V t0 = hn::LoadU(d, row.t0 + i), end = hn::LoadU(d, ends + i);
    const auto inside = hn::Gt(end, t0), finite = hn::Lt(end, hn::Set(d, 3e38f));
    const V length = hn::IfThenElseZero(finite, hn::Sub(end, t0));
    V l[3], t[3];
    auto cancels = hn::Lt(one, zero);
    for (int c = 0; c < 3; ++c) {
      t[c] = c > 0 && grey ? t[0] : hn::IfThenElseZero(finite, hn::Exp(d, hn::Mul(hn::Set(d, -row.sigma_t[c]), length)));
      const V whole = hn::LoadU(d, row.whole[c] + i), far = hn::Mul(t[c], hn::LoadU(d, sums[c] + i));
      cancels = hn::Or(cancels, hn::Gt(far, hn::Mul(cancel, whole)));
      l[c] = hn::IfThenElseZero(inside, hn::Max(zero, hn::Sub(whole, far)));
    }
    for (int c = 0; c < 3; ++c) t[c] = hn::IfThenElse(inside, t[c], one);
    hn::StoreInterleaved3(l[0], l[1], l[2], d, inscatter + 3 * i);
    hn::StoreInterleaved3(t[0], t[1], t[2], d, transmittance + 3 * i);
    hn::StoreU(hn::IfThenElseZero(hn::And(inside, cancels), one), d, redo + i);
  }
}

// row_geometry (airlight_batch.h) in float64 lanes, Aabb::clip's slabs (a NaN of 0 inf on a face
// leaves the stretch alone).
HWY_NOINLINE void RowGeometryKernel(const RowGeometry& g, const double* origin, const double* a, const double* b, double px0, size_t count) {
  const hn::ScalableTag<double> d;
  const hn::Rebind<float, decltype(d)> df;
  using V = hn::Vec<decltype(d)>;
  const size_t lanes = hn::Lanes(d);
  const V zero = hn::Zero(d), inf = hn::Set(d, HUGE_VAL);
  for (size_t x = 0; x < count; x += lanes) {
    const V px = hn::Iota(d, px0 + static_cast<double>(x));
    V v[3];
    for (int e = 0; e < 3; ++e) v[e] = hn::MulAdd(hn::Set(d, b[e]), px, hn::Set(d, a[e]));
    const V inv_norm = hn::Div(hn::Set(d, 1.0), hn::Sqrt(hn::MulAdd(v[0], v[0], hn::MulAdd(v[1], v[1], hn::Mul(v[2], v[2])))));
    for (int e = 0; e < 3; ++e) v[e] = hn::Mul(v[e], inv_norm);
    V t0 = zero, t1 = inf;
    for (int e = 0; e < 3; ++e) {
      if (std::isinf(g.lo[e]) && std::isinf(g.hi[e])) continue;  // an unbounded slab: -inf to +inf, never clipping
      const V inv = hn::Div(hn::Set(d, 1.0), v[e]);
      V near = hn::Mul(hn::Set(d, g.lo[e] - origin[e]), inv), far = hn::Mul(hn::Set(d, g.hi[e] - origin[e]), inv);
      const auto swap = hn::Gt(near, far);
      const V n = hn::IfThenElse(swap, far, near), f = hn::IfThenElse(swap, near, far);
      t0 = hn::IfThenElse(hn::Gt(n, t0), n, t0), t1 = hn::IfThenElse(hn::Lt(f, t1), f, t1);
    }
    const auto miss = hn::Not(hn::Gt(t1, t0));
    hn::StoreU(hn::DemoteTo(df, hn::IfThenZeroElse(miss, t0)), df, g.t0 + x);
    const auto t1_f = hn::DemoteTo(df, hn::IfThenZeroElse(miss, t1));  // some targets saturate infinity to the largest float
    hn::StoreU(hn::IfThenElse(hn::Ge(t1_f, hn::Set(df, FLT_MAX)), hn::Set(df, HUGE_VALF), t1_f), df, g.t1 + x);
    for (size_t l = 0; l < g.light_count; ++l) {
      V to[3];
      for (int e = 0; e < 3; ++e) to[e] = hn::Set(d, g.lights[3 * l + static_cast<size_t>(e)] - origin[e]);
      const V t = hn::MulAdd(to[0], v[0], hn::MulAdd(to[1], v[1], hn::Mul(to[2], v[2])));
      V h2 = zero;
      for (int e = 0; e < 3; ++e) {
        const V off = hn::NegMulAdd(t, v[e], to[e]);
        h2 = hn::MulAdd(off, off, h2);
      }
      hn::StoreU(hn::DemoteTo(df, t), df, g.t(l) + x);
      hn::StoreU(hn::Sqrt(hn::DemoteTo(df, h2)), df, g.h(l) + x);  // float's square root: within an ulp of float(sqrt(h2))
    }
  }
}

}  // namespace haze::analytic::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HAZE_ANALYTIC_AIRLIGHT_BATCH_INL_H_
