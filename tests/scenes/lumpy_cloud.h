// A lumpy cloud on a grid: 12 RBF blobs over the middle of [-1, 1]^3, injected into n^3 cells (the
// optical-depth tests and haze_propagation_accuracy, docs/PROPAGATION.md).
#pragma once

#include <haze/grids/grid.h>
#include <haze/grids/rbf.h>

#include <cmath>
#include <vector>

namespace haze::grids {

inline DenseGrid lumpy_cloud(int n) {
  DenseGrid g({n, n, n}, {Vec3(-1), Vec3(1)});
  std::vector<RbfBlob> blobs;
  for (int i = 0; i < 12; ++i) {
    double t = 0.5 * i;
    blobs.push_back({Vec3(0.5 * std::cos(t), 0.4 * std::sin(1.3 * t), 0.45 * std::cos(0.7 * t + 1)), 1.0 + 0.5 * std::sin(t), 3.0 + (i % 4)});
  }
  inject_rbf(blobs, g);
  return g;
}

}  // namespace haze::grids
