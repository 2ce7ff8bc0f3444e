#include <haze/core/directions.h>
#include <haze/core/error.h>
#include <haze/core/rng.h>

#include <cmath>

namespace haze {

DirectionSet::DirectionSet(std::vector<Vec3> directions, std::vector<double> weights)
    : directions_(std::move(directions)), weights_(std::move(weights)) {}

static void check_count(int count) {
  if (count < 1 || count > 1 << 20) throw Error("directions", to_text(count), "an integer in [1, 1048576]");
}

DirectionSet DirectionSet::fibonacci(int count) {
  check_count(count);
  const double golden = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> dirs(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    // z at the centres of D equal-area bands, azimuth advancing by the golden angle.
    double z = 1.0 - (2.0 * i + 1.0) / count;
    double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    double phi = 2.0 * kPi * (i / golden - std::floor(i / golden));
    dirs[static_cast<size_t>(i)] = Vec3(r * std::cos(phi), r * std::sin(phi), z);
  }
  return {std::move(dirs), std::vector<double>(static_cast<size_t>(count), 4.0 * kPi / count)};
}

DirectionSet DirectionSet::uniform_random(int count, std::uint64_t seed) {
  check_count(count);
  Rng rng(seed, 0x5eed);
  std::vector<Vec3> dirs(static_cast<size_t>(count));
  for (auto& d : dirs) {
    double z = 1.0 - 2.0 * rng.uniform();
    double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    double phi = 2.0 * kPi * rng.uniform();
    d = Vec3(r * std::cos(phi), r * std::sin(phi), z);
  }
  return {std::move(dirs), std::vector<double>(static_cast<size_t>(count), 4.0 * kPi / count)};
}

int DirectionSet::nearest(const Vec3& w) const {
  int best = 0;
  double best_dot = -kInfinity;
  for (int i = 0; i < size(); ++i) {
    double d = glm::dot(w, (*this)[i]);
    if (d > best_dot) best_dot = d, best = i;
  }
  return best;
}

double cone_tangent(int count) {
  const double cos_alpha = 1.0 - 2.0 / count;
  return std::sqrt(1.0 - cos_alpha * cos_alpha) / cos_alpha;
}

}  // namespace haze
