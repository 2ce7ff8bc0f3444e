// A coarse grid of density majorants over a medium's bounds and a DDA that walks a ray through it,
// in the spirit of pbrt-v4's DDAMajorantIterator: the majorant iterator of every haze::Medium
// (Medium::majorants), which the reference path tracer walks.
#pragma once

#include <haze/core/math.h>

#include <vector>

namespace haze {

struct MajorantSegment {
  double t0, t1;
  double density;  // an upper bound of the density on [t0, t1)
};

class Medium;

class MajorantGrid {
 public:
  // One cell for homogeneous media; `cells` per axis for heterogeneous ones.
  MajorantGrid(const Medium& medium, int cells = 16);

  // Walks the ray's [t_min, t_max] through the grid, segment by segment, in order.
  class Iterator {
   public:
    Iterator() = default;
    Iterator(const MajorantGrid* grid, const Ray& ray, double t_min, double t_max);
    bool next(MajorantSegment& segment);

   private:
    const MajorantGrid* grid_ = nullptr;
    double t_ = 0.0, t_max_ = 0.0;
    int cell_[3] = {0, 0, 0}, step_[3] = {0, 0, 0};
    double next_t_[3] = {0, 0, 0}, delta_t_[3] = {0, 0, 0};
    bool done_ = true;
  };
  Iterator walk(const Ray& ray, double t_min, double t_max) const { return Iterator(this, ray, t_min, t_max); }

 private:
  Aabb bounds_;
  int n_[3] = {1, 1, 1};
  std::vector<double> density_;
  double at(const int c[3]) const {
    return density_[(static_cast<size_t>(c[2]) * static_cast<size_t>(n_[1]) + static_cast<size_t>(c[1])) * static_cast<size_t>(n_[0]) + static_cast<size_t>(c[0])];
  }
};

}  // namespace haze
