// DirectionSet: D unit directions with quadrature weights summing to 4 pi.
#pragma once

#include <haze/core/math.h>

#include <cstdint>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

class DirectionSet {
 public:
  // Spherical Fibonacci points (Marques et al. 2013): deterministic, near-uniform, equal weights.
  static DirectionSet fibonacci(int count);
  // Independent uniform directions (seed 001's global directions), equal weights 4 pi / D.
  static DirectionSet uniform_random(int count, std::uint64_t seed);

  int size() const { return static_cast<int>(directions_.size()); }
  const Vec3& operator[](int i) const { return directions_[static_cast<size_t>(i)]; }
  double weight(int i) const { return weights_[static_cast<size_t>(i)]; }
  const std::vector<Vec3>& directions() const { return directions_; }
  const std::vector<double>& weights() const { return weights_; }
  // Index of the direction closest to w (largest dot product).
  int nearest(const Vec3& w) const;

 private:
  DirectionSet(std::vector<Vec3> directions, std::vector<double> weights);
  std::vector<Vec3> directions_;
  std::vector<double> weights_;
};

// The tangent of the half-angle of a cone of 4 pi / count steradians, one direction's share of a
// set of `count` (at least 3): 2 pi (1 - cos alpha) = 4 pi / count. A gather that stands each direction for its
// cone caps a point light's irradiance where the light is nearer the ray than the cone's radius.
double cone_tangent(int count);

}  // namespace haze

#pragma GCC visibility pop
