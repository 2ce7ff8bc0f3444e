// Per-target optical-depth sweep kernel (Highway: included once per target by foreach_target.h).
#if defined(HAZE_GRIDS_SWEEP_CELLS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_GRIDS_SWEEP_CELLS_INL_H_
#undef HAZE_GRIDS_SWEEP_CELLS_INL_H_
#else
#define HAZE_GRIDS_SWEEP_CELLS_INL_H_
#endif

#include <haze/grids/sweep_cells.h>

#include <hwy/highway.h>

#include <algorithm>
#include <cmath>

HWY_BEFORE_NAMESPACE();
namespace haze::grids::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// One vector of cells: lane m is cell (i, j, k) + min(m, last) e_axis. The formulas of
// sweep_cells_reference (sweep_cells.h), with the dominant axis chosen per lane.
template <class D>
HWY_INLINE void SweepVector(D d, const SweepVolume& v, int i, int j, int k, int axis, int last, float* HWY_RESTRICT depth,
                            float* HWY_RESTRICT mean) {
  using V = hn::Vec<D>;
  const hn::RebindToSigned<D> di;
  using VI = hn::Vec<decltype(di)>;
  const V zero = hn::Zero(d), half = hn::Set(d, 0.5f), inf = hn::Set(d, HUGE_VALF);
  const int start[3] = {i, j, k};
  const int stride[3] = {1, v.n[0], v.n[0] * v.n[1]};
  VI cell[3];
  for (int e = 0; e < 3; ++e) cell[e] = hn::Set(di, start[e]);
  cell[axis] = hn::Min(hn::Add(cell[axis], hn::Iota(di, 0)), hn::Set(di, start[axis] + last));
  V u[3], q[3], aq[3];
  for (int e = 0; e < 3; ++e) u[e] = hn::Add(hn::ConvertTo(d, cell[e]), half);
  V dist;
  if (v.directional) {
    for (int e = 0; e < 3; ++e) q[e] = hn::Set(d, v.light[e] / v.h[e]);
    dist = inf;
  } else {
    V w[3];
    for (int e = 0; e < 3; ++e) w[e] = hn::Sub(hn::Set(d, v.light[e]), hn::MulAdd(u[e], hn::Set(d, v.h[e]), hn::Set(d, v.lo[e])));
    dist = hn::Sqrt(hn::MulAdd(w[0], w[0], hn::MulAdd(w[1], w[1], hn::Mul(w[2], w[2]))));
    const auto at_light = hn::Eq(dist, zero);
    const V inv = hn::Div(hn::Set(d, 1.0f), hn::IfThenElse(at_light, hn::Set(d, 1.0f), dist));
    for (int e = 0; e < 3; ++e) q[e] = hn::Mul(hn::Mul(w[e], inv), hn::Set(d, 1.0f / v.h[e]));
    q[2] = hn::IfThenElse(at_light, hn::Set(d, 1.0f / v.h[2]), q[2]);
  }
  // Per axis, the path length across one cell layer.
  V t_delta[3];
  for (int e = 0; e < 3; ++e) {
    aq[e] = hn::Abs(q[e]);
    t_delta[e] = hn::IfThenElse(hn::Eq(q[e], zero), inf, hn::Div(hn::Set(d, 1.0f), aq[e]));
  }
  // Dominant axis per lane (ties to the lower axis) and the path length inside the grid.
  const auto is_x = hn::And(hn::Ge(aq[0], aq[1]), hn::Ge(aq[0], aq[2]));
  const auto is_y = hn::AndNot(is_x, hn::Ge(aq[1], aq[2]));
  const auto is_z = hn::Not(hn::Or(is_x, is_y));
  const V layers = hn::Set(d, static_cast<float>(v.layers));
  V s = hn::Mul(layers, hn::Min(hn::Min(t_delta[0], t_delta[1]), t_delta[2]));
  VI chebyshev = hn::Zero(di);
  for (int e = 0; e < 3; ++e) chebyshev = hn::Max(chebyshev, hn::Abs(hn::Sub(cell[e], hn::Set(di, v.light_cell[e]))));
  s = hn::IfThenElse(hn::RebindMask(d, hn::Lt(chebyshev, hn::Set(di, v.exact_radius + 1))), inf, s);
  V len = dist;
  for (int e = 0; e < 3; ++e) {
    const V to_face = hn::IfThenElse(hn::Gt(q[e], zero), hn::Sub(hn::Set(d, static_cast<float>(v.n[e])), u[e]), u[e]);
    len = hn::Min(len, hn::Mul(to_face, t_delta[e]));
  }
  // The first min(s, len) of the path walked cell by cell (Amanatides-Woo): per axis, the
  // distance to the next face crossed (half a cell from the centre) and between faces.
  const V seg = hn::Min(s, len);
  V t_next[3];
  VI step[3];
  for (int e = 0; e < 3; ++e) {
    t_next[e] = hn::Mul(half, t_delta[e]);
    step[e] = hn::IfThenElse(hn::RebindMask(di, hn::Gt(q[e], zero)), hn::Set(di, stride[e]), hn::Set(di, -stride[e]));
  }
  VI own = hn::Zero(di);
  for (int e = 0; e < 3; ++e) own = hn::Add(own, hn::Mul(cell[e], hn::Set(di, stride[e])));
  VI index = own;
  VI walk[3] = {cell[0], cell[1], cell[2]};  // the walk's cell coordinates
  const VI one_i = hn::Set(di, 1);
  V t = zero, result = zero;
  for (auto active = hn::Lt(t, seg); !hn::AllFalse(d, active); active = hn::Lt(t, seg)) {
    const auto cross_x = hn::And(hn::Le(t_next[0], t_next[1]), hn::Le(t_next[0], t_next[2]));
    const auto cross_y = hn::AndNot(cross_x, hn::Le(t_next[1], t_next[2]));
    const auto cross_z = hn::Not(hn::Or(cross_x, cross_y));
    const V t_end = hn::Min(hn::Min(hn::Min(t_next[0], t_next[1]), t_next[2]), seg);
    // Finished lanes read their own cell; active ones are inside the grid (see below).
    const V rho = hn::GatherIndex(d, v.density, hn::IfThenElse(hn::RebindMask(di, active), index, own));
    result = hn::Add(result, hn::IfThenElseZero(active, hn::Mul(rho, hn::Sub(t_end, t))));
    t = hn::IfThenElse(active, t_end, t);
    const decltype(cross_x) crossed[3] = {cross_x, cross_y, cross_z};
    for (int e = 0; e < 3; ++e) {
      const auto go = hn::And(active, crossed[e]);
      const auto go_i = hn::RebindMask(di, go);
      index = hn::Add(index, hn::IfThenElseZero(go_i, step[e]));
      walk[e] = hn::Add(walk[e], hn::IfThenElseZero(go_i, hn::IfThenElse(hn::RebindMask(di, hn::Gt(q[e], zero)), one_i, hn::Neg(one_i))));
      t_next[e] = hn::IfThenElse(go, hn::Add(t_next[e], t_delta[e]), t_next[e]);
      // Rounding can leave t a hair short of len when the walk crosses the grid's face: the
      // lane is done there (its next cell is outside, or a wrapped-around index).
      const auto out = hn::Or(hn::Gt(hn::Zero(di), walk[e]), hn::Gt(walk[e], hn::Set(di, v.n[e] - 1)));
      t = hn::IfThenElse(hn::And(go, hn::RebindMask(d, out)), seg, t);
    }
  }
  const auto lands = hn::Gt(len, s);
  if (!hn::AllFalse(d, lands)) {
    // The landing point, `layers` cell-centre planes toward the light along the dominant axis:
    // bilinear in that plane (lo/hi cells and weight per axis, the dominant axis pinned).
    VI lo[3], hi[3];
    V frac[3];
    for (int e = 0; e < 3; ++e) {
      const V f = hn::Sub(hn::MulAdd(s, q[e], u[e]), half);
      const V fl = hn::Floor(f);
      frac[e] = hn::Sub(f, fl);
      const VI c = hn::ConvertTo(di, fl), last_cell = hn::Set(di, v.n[e] - 1);
      lo[e] = hn::Min(hn::Max(c, hn::Zero(di)), last_cell);
      hi[e] = hn::Min(hn::Max(hn::Add(c, hn::Set(di, 1)), hn::Zero(di)), last_cell);
    }
    const auto mx = hn::RebindMask(di, is_x), my = hn::RebindMask(di, is_y), mz = hn::RebindMask(di, is_z);
    auto landing_plane = [&](int e, auto mask) {
      const VI step = hn::IfThenElse(hn::RebindMask(di, hn::Gt(q[e], zero)), hn::Set(di, v.layers), hn::Set(di, -v.layers));
      const VI c = hn::Min(hn::Max(hn::Add(cell[e], step), hn::Zero(di)), hn::Set(di, v.n[e] - 1));
      return hn::IfThenElseZero(mask, hn::Mul(c, hn::Set(di, stride[e])));
    };
    const VI plane = hn::Add(landing_plane(0, mx), hn::Add(landing_plane(1, my), landing_plane(2, mz)));
    // In-plane axes b < c: (y, z) for x, (x, z) for y, (x, y) for z.
    auto scaled = [&](const VI& c, int e) { return hn::Mul(c, hn::Set(di, stride[e])); };
    const VI b0 = hn::IfThenElse(mx, scaled(lo[1], 1), scaled(lo[0], 0)), b1 = hn::IfThenElse(mx, scaled(hi[1], 1), scaled(hi[0], 0));
    const VI c0 = hn::IfThenElse(mz, scaled(lo[1], 1), scaled(lo[2], 2)), c1 = hn::IfThenElse(mz, scaled(hi[1], 1), scaled(hi[2], 2));
    const V fb = hn::IfThenElse(is_x, frac[1], frac[0]), fc = hn::IfThenElse(is_z, frac[1], frac[2]);
    // Every index is in the grid (clamped); lanes that do not land discard what they read.
    const V m00 = hn::GatherIndex(d, v.mean, hn::Add(plane, hn::Add(b0, c0)));
    const V m10 = hn::GatherIndex(d, v.mean, hn::Add(plane, hn::Add(b1, c0)));
    const V m01 = hn::GatherIndex(d, v.mean, hn::Add(plane, hn::Add(b0, c1)));
    const V m11 = hn::GatherIndex(d, v.mean, hn::Add(plane, hn::Add(b1, c1)));
    const V m0 = hn::MulAdd(fb, hn::Sub(m10, m00), m00), m1 = hn::MulAdd(fb, hn::Sub(m11, m01), m01);
    const V landing = hn::MulAdd(fc, hn::Sub(m1, m0), m0);
    result = hn::IfThenElse(lands, hn::MulAdd(landing, hn::Sub(len, s), result), result);
  }
  hn::StoreU(result, d, depth);
  // mean = depth / len; a cell at the light (len 0) keeps its own density.
  const auto has_path = hn::Gt(len, zero);
  V mean_density = hn::Div(result, hn::IfThenElse(has_path, len, hn::Set(d, 1.0f)));
  if (!hn::AllTrue(d, has_path)) mean_density = hn::IfThenElse(has_path, mean_density, hn::GatherIndex(d, v.density, own));
  hn::StoreU(mean_density, d, mean);
}

HWY_NOINLINE void SweepCells(const SweepVolume& v, int i, int j, int k, int axis, int count, float* HWY_RESTRICT depth,
                             float* HWY_RESTRICT mean) {
  const hn::ScalableTag<float> d;
  const int lanes = static_cast<int>(hn::Lanes(d));
  int start[3] = {i, j, k};
  int m = 0;
  for (; m + lanes <= count; m += lanes) {
    SweepVector(d, v, start[0], start[1], start[2], axis, lanes - 1, depth + m, mean + m);
    start[axis] += lanes;
  }
  if (m < count) {
    // The last partial vector: lanes past the end repeat the last cell, into a local buffer.
    HWY_ALIGN float tail_depth[hn::MaxLanes(d)], tail_mean[hn::MaxLanes(d)];
    SweepVector(d, v, start[0], start[1], start[2], axis, count - m - 1, tail_depth, tail_mean);
    std::copy(tail_depth, tail_depth + (count - m), depth + m);
    std::copy(tail_mean, tail_mean + (count - m), mean + m);
  }
}

}  // namespace haze::grids::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HAZE_GRIDS_SWEEP_CELLS_INL_H_
