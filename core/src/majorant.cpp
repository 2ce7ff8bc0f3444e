#include <haze/core/majorant.h>
#include <haze/core/medium.h>

#include <algorithm>

namespace haze {

MajorantGrid::MajorantGrid(const Medium& medium, int cells) : bounds_(medium.bounds()) {
  if (medium.homogeneous() || !bounds_.bounded()) {
    density_.assign(1, medium.max_density(bounds_));
    return;
  }
  n_[0] = n_[1] = n_[2] = cells;
  density_.resize(static_cast<size_t>(cells) * static_cast<size_t>(cells) * static_cast<size_t>(cells));
  Vec3 size = bounds_.extent() / static_cast<double>(cells);
  for (int z = 0; z < cells; ++z)
    for (int y = 0; y < cells; ++y)
      for (int x = 0; x < cells; ++x) {
        Vec3 lo = bounds_.lo + Vec3(x, y, z) * size;
        const int c[3] = {x, y, z};
        density_[(static_cast<size_t>(c[2]) * static_cast<size_t>(n_[1]) + static_cast<size_t>(c[1])) * static_cast<size_t>(n_[0]) + static_cast<size_t>(c[0])] =
            medium.max_density({lo, lo + size});
      }
}

MajorantGrid::Iterator::Iterator(const MajorantGrid* grid, const Ray& ray, double t_min, double t_max) : grid_(grid) {
  double t0 = t_min, t1 = t_max;
  if (!grid->bounds_.clip(ray, t0, t1) || !(t1 > t0)) return;
  t_ = t0, t_max_ = t1, done_ = false;
  if (grid->density_.size() == 1) {
    for (int a = 0; a < 3; ++a) next_t_[a] = kInfinity;
    return;
  }
  Vec3 extent = grid->bounds_.extent();
  Vec3 p = ray.at(t0);
  for (int a = 0; a < 3; ++a) {
    double cell_size = extent[a] / grid->n_[a];
    double u = (p[a] - grid->bounds_.lo[a]) / cell_size;
    cell_[a] = std::clamp(static_cast<int>(u), 0, grid->n_[a] - 1);
    double d = ray.direction[a];
    if (d == 0.0) {
      step_[a] = 0, next_t_[a] = kInfinity, delta_t_[a] = kInfinity;
      continue;
    }
    step_[a] = d > 0.0 ? 1 : -1;
    double boundary = grid->bounds_.lo[a] + (cell_[a] + (d > 0.0 ? 1 : 0)) * cell_size;
    next_t_[a] = t0 + (boundary - p[a]) / d;
    delta_t_[a] = cell_size / std::abs(d);
  }
}

bool MajorantGrid::Iterator::next(MajorantSegment& segment) {
  if (done_) return false;
  int axis = next_t_[0] < next_t_[1] ? (next_t_[0] < next_t_[2] ? 0 : 2) : (next_t_[1] < next_t_[2] ? 1 : 2);
  double end = std::min(next_t_[axis], t_max_);
  segment = {t_, end, grid_->at(cell_)};
  t_ = end;
  if (end >= t_max_) {
    done_ = true;
  } else {
    cell_[axis] += step_[axis];
    next_t_[axis] += delta_t_[axis];
    if (cell_[axis] < 0 || cell_[axis] >= grid_->n_[axis]) done_ = true;
  }
  return true;
}

}  // namespace haze
