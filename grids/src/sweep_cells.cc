// Dispatch and scalar reference for the optical-depth sweep kernel (Highway skeleton layout).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "sweep_cells.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include "sweep_cells-inl.h"

#include <hwy/highway.h>

#if HWY_ONCE
#include <algorithm>
#include <cmath>

namespace haze::grids {

HWY_EXPORT(SweepCells);

namespace {

void sweep_cell(const SweepVolume& v, const int cell[3], float& depth, float& mean) {
  const int stride[3] = {1, v.n[0], v.n[0] * v.n[1]};
  float u[3], q[3];
  for (int e = 0; e < 3; ++e) u[e] = static_cast<float>(cell[e]) + 0.5f;
  float dist = HUGE_VALF;
  if (v.directional) {
    for (int e = 0; e < 3; ++e) q[e] = v.light[e] / v.h[e];
  } else {
    float w[3];
    for (int e = 0; e < 3; ++e) w[e] = v.light[e] - (u[e] * v.h[e] + v.lo[e]);
    dist = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    const float inv = 1.0f / (dist == 0.0f ? 1.0f : dist);
    for (int e = 0; e < 3; ++e) q[e] = w[e] * inv * (1.0f / v.h[e]);
    if (dist == 0.0f) q[2] = 1.0f / v.h[2];
  }
  const float aq[3] = {std::abs(q[0]), std::abs(q[1]), std::abs(q[2])};
  const int a = aq[0] >= aq[1] && aq[0] >= aq[2] ? 0 : (aq[1] >= aq[2] ? 1 : 2);
  float t_delta[3];  // per axis, the path length across one cell layer
  for (int e = 0; e < 3; ++e) t_delta[e] = q[e] == 0.0f ? HUGE_VALF : 1.0f / aq[e];
  const auto layers = static_cast<float>(v.layers);
  int chebyshev = 0;
  for (int e = 0; e < 3; ++e) chebyshev = std::max(chebyshev, std::abs(cell[e] - v.light_cell[e]));
  const float s = chebyshev <= v.exact_radius ? HUGE_VALF : layers * t_delta[a];
  float len = dist;
  for (int e = 0; e < 3; ++e) len = std::min(len, (q[e] > 0.0f ? static_cast<float>(v.n[e]) - u[e] : u[e]) * t_delta[e]);
  // The first min(s, len) of the path walked cell by cell (Amanatides-Woo).
  const float seg = std::min(s, len);
  float t_next[3];
  for (int e = 0; e < 3; ++e) t_next[e] = 0.5f * t_delta[e];
  int index = cell[0] * stride[0] + cell[1] * stride[1] + cell[2] * stride[2];
  int walk[3] = {cell[0], cell[1], cell[2]};
  float t = 0.0f;
  depth = 0.0f;
  while (t < seg) {
    const int e = t_next[0] <= t_next[1] && t_next[0] <= t_next[2] ? 0 : (t_next[1] <= t_next[2] ? 1 : 2);
    const float t_end = std::min(std::min(std::min(t_next[0], t_next[1]), t_next[2]), seg);
    depth += v.density[index] * (t_end - t);
    t = t_end;
    index += q[e] > 0.0f ? stride[e] : -stride[e];
    walk[e] += q[e] > 0.0f ? 1 : -1;
    t_next[e] += t_delta[e];
    // Rounding can leave t a hair short of len when the walk crosses the grid's face: stop there.
    if (walk[e] < 0 || walk[e] >= v.n[e]) break;
  }
  if (len > s) {
    const int b = a == 0 ? 1 : 0, c = a == 2 ? 1 : 2;
    int lo[3], hi[3];
    float frac[3];
    for (int e : {b, c}) {
      const float f = s * q[e] + u[e] - 0.5f, fl = std::floor(f);
      frac[e] = f - fl;
      lo[e] = std::clamp(static_cast<int>(fl), 0, v.n[e] - 1), hi[e] = std::clamp(static_cast<int>(fl) + 1, 0, v.n[e] - 1);
    }
    const int plane = std::clamp(cell[a] + (q[a] > 0.0f ? v.layers : -v.layers), 0, v.n[a] - 1) * stride[a];
    auto at = [&](int ib, int ic) { return v.mean[plane + ib * stride[b] + ic * stride[c]]; };
    const float m0 = at(lo[b], lo[c]) + frac[b] * (at(hi[b], lo[c]) - at(lo[b], lo[c]));
    const float m1 = at(lo[b], hi[c]) + frac[b] * (at(hi[b], hi[c]) - at(lo[b], hi[c]));
    depth += (m0 + frac[c] * (m1 - m0)) * (len - s);
  }
  mean = len > 0.0f ? depth / len : v.density[cell[0] * stride[0] + cell[1] * stride[1] + cell[2] * stride[2]];
}

}  // namespace

void sweep_cells_reference(const SweepVolume& volume, int i, int j, int k, int axis, int count, float* depth, float* mean) {
  int cell[3] = {i, j, k};
  for (int m = 0; m < count; ++m, ++cell[axis]) sweep_cell(volume, cell, depth[m], mean[m]);
}

void sweep_cells(const SweepVolume& volume, int i, int j, int k, int axis, int count, float* depth, float* mean) {
  HWY_DYNAMIC_DISPATCH(SweepCells)(volume, i, j, k, axis, count, depth, mean);
}

}  // namespace haze::grids
#endif  // HWY_ONCE
