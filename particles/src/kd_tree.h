// Internal: one FLANN kd-tree over particle positions (the caller's memory, not copied), shared by
// nearest_neighbours and ParticleField.
#pragma once

#include <haze/particles/neighbours.h>

#include <flann/flann.hpp>

#include <span>

namespace haze::particles {

struct KdTree {
  flann::Matrix<float> data;
  flann::Index<flann::L2<float>> index;
  // FLANN reads rows of 3 floats; glm::vec3 is exactly that.
  explicit KdTree(std::span<const Vec3f> positions)
      : data(const_cast<float*>(&positions[0].x), positions.size(), 3), index(data, flann::KDTreeSingleIndexParams(12)) {
    static_assert(sizeof(Vec3f) == 3 * sizeof(float));
    index.buildIndex();
  }
};

// The k nearest neighbours of every particle in the tree; k in [1, particles - 1], unchecked.
Neighbourhoods nearest_neighbours(const KdTree& tree, int k);

}  // namespace haze::particles
