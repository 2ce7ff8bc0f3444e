#include <haze/core/grid_walk.h>

#include <algorithm>
#include <cmath>

namespace haze {

GridWalk::GridWalk(const Aabb& bounds, const std::array<int, 3>& n, const Ray& ray, double t_min, double t_max) {
  double t0 = t_min, t1 = t_max;
  if (!bounds.clip(ray, t0, t1) || !(t1 > t0)) return;
  t_ = t0, t_max_ = t1, done_ = false;
  for (int a = 0; a < 3; ++a) n_[a] = n[static_cast<size_t>(a)];
  if (n_[0] == 1 && n_[1] == 1 && n_[2] == 1) {
    for (int a = 0; a < 3; ++a) next_t_[a] = kInfinity;
    return;
  }
  const Vec3 extent = bounds.extent(), p = ray.at(t0);
  for (int a = 0; a < 3; ++a) {
    const double cell_size = extent[a] / n_[a];
    cell_[a] = std::clamp(static_cast<int>(std::floor((p[a] - bounds.lo[a]) / cell_size)), 0, n_[a] - 1);
    const double d = ray.direction[a];
    if (d == 0.0) {
      step_[a] = 0, next_t_[a] = kInfinity, delta_t_[a] = kInfinity;
      continue;
    }
    step_[a] = d > 0.0 ? 1 : -1;
    const double boundary = bounds.lo[a] + (cell_[a] + (d > 0.0 ? 1 : 0)) * cell_size;
    next_t_[a] = t0 + (boundary - p[a]) / d;
    delta_t_[a] = cell_size / std::abs(d);
  }
}

bool GridWalk::next(CellSegment& segment) {
  if (done_) return false;
  const int axis = next_t_[0] < next_t_[1] ? (next_t_[0] < next_t_[2] ? 0 : 2) : (next_t_[1] < next_t_[2] ? 1 : 2);
  const double end = std::min(next_t_[axis], t_max_);
  segment = {t_, end, (static_cast<size_t>(cell_[2]) * static_cast<size_t>(n_[1]) + static_cast<size_t>(cell_[1])) * static_cast<size_t>(n_[0]) + static_cast<size_t>(cell_[0])};
  t_ = end;
  if (end >= t_max_) {
    done_ = true;
  } else {
    cell_[axis] += step_[axis];
    next_t_[axis] += delta_t_[axis];
    if (cell_[axis] < 0 || cell_[axis] >= n_[axis]) done_ = true;
  }
  return true;
}

TrilinearStencil::TrilinearStencil(const Aabb& bounds, const std::array<int, 3>& n, const Vec3& p, bool extrapolate) {
  const Vec3 u = (p - bounds.lo) / (bounds.extent() / Vec3(n[0], n[1], n[2])) - 0.5;
  size_t i[2][3];
  double f[3];
  for (int a = 0; a < 3; ++a) {
    const double fl = std::floor(u[a]);
    const int last = n[static_cast<size_t>(a)] - 1;
    if (extrapolate && last > 0) {  // the cell pair within the grid, f beyond [0, 1] in the outer half cells
      const int i0 = std::clamp(static_cast<int>(fl), 0, last - 1);
      i[0][a] = static_cast<size_t>(i0), i[1][a] = static_cast<size_t>(i0 + 1);
      f[a] = std::clamp(u[a] - i0, -0.5, 1.5);
      continue;
    }
    f[a] = u[a] - fl;
    i[0][a] = static_cast<size_t>(std::clamp(static_cast<int>(fl), 0, last));
    i[1][a] = static_cast<size_t>(std::clamp(static_cast<int>(fl) + 1, 0, last));
  }
  const auto nx = static_cast<size_t>(n[0]), nxy = nx * static_cast<size_t>(n[1]);
  for (int m = 0; m < 8; ++m) {
    const int bi = m & 1, bj = (m >> 1) & 1, bk = (m >> 2) & 1;
    offset[m] = i[bk][2] * nxy + i[bj][1] * nx + i[bi][0];
    weight[m] = (bi ? f[0] : 1 - f[0]) * (bj ? f[1] : 1 - f[1]) * (bk ? f[2] : 1 - f[2]);
  }
}

}  // namespace haze
