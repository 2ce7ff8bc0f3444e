// A small heterogeneous volume (16 x 12 x 10 cells) with a point light inside and a sun, for the
// DOM's solver-level tests (tests/grids/dom_test.cpp, tests/mpi/dom_mpi_test.cpp), and the
// relative L2 difference of two moment vectors.
#pragma once

#include <haze/core/light.h>
#include <haze/grids/optical_depth.h>
#include <haze/grids/propagation.h>

#include <cmath>
#include <vector>

namespace haze::grids {

struct SmallCloud {
  ExtinctionVolume volume;
  std::vector<Light> lights{PointLight{Vec3(0.2, 0.1, 0.05), Rgb(2.0)}, DirectionalLight{glm::normalize(Vec3(0.3, -1.0, 0.2)), Rgb(1.0)}};
  std::vector<DenseGrid> depths;
  explicit SmallCloud(const Rgb& sigma_t = Rgb(3.0))
      : volume{DenseGrid({16, 12, 10}, {Vec3(-1.0, -0.75, -0.6), Vec3(1.0, 0.75, 0.6)}), sigma_t, Rgb(0.9), PhaseFunction::henyey_greenstein(0.5)} {
    DenseGrid& d = volume.density;
    for (int k = 0; k < 10; ++k)
      for (int j = 0; j < 12; ++j)
        for (int i = 0; i < 16; ++i) {
          const Vec3 x = d.cell_center(i, j, k);
          d.at(i, j, k) = static_cast<float>(std::exp(-2.0 * glm::dot(x, x)) + 0.3 * (i % 3 == 0));
        }
    for (const Light& l : lights) depths.push_back(optical_depth(d, l, {DepthScheme::exact}));
  }
};

// |a - b| / |b| over every value.
inline double relative_difference(const std::vector<float>& a, const std::vector<float>& b) {
  double diff = 0.0, ref = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    diff += std::pow(static_cast<double>(a[i]) - static_cast<double>(b[i]), 2);
    ref += std::pow(static_cast<double>(b[i]), 2);
  }
  return std::sqrt(diff / ref);
}

}  // namespace haze::grids
