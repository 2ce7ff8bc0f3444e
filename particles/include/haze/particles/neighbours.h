// Particle positions and their k nearest neighbours, found with FLANN (seed 001 builds its
// illumination network over particle neighbourhoods).
#pragma once

#include <haze/core/math.h>

#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::particles {

struct Neighbourhoods {
  int k = 0;
  std::vector<int> indices;        // k per particle, nearest first, the particle itself excluded
  std::vector<float> distances2;   // squared distances, same layout
  const int* of(size_t particle) const { return indices.data() + particle * static_cast<size_t>(k); }
};

// Exact k-nearest-neighbour search (FLANN single kd-tree); ties resolve by FLANN's order.
// Throws haze::Error when k < 1 or k >= the number of particles, or a position is not finite.
Neighbourhoods nearest_neighbours(const std::vector<Vec3f>& positions, int k);

}  // namespace haze::particles

#pragma GCC visibility pop
