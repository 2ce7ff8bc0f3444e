// FLANN neighbourhoods against brute force.
#include <haze/core/error.h>
#include <haze/core/rng.h>
#include <haze/particles/neighbours.h>

#include <gtest/gtest.h>

#include <algorithm>

namespace haze::particles {
namespace {

TEST(Neighbours, MatchBruteForce) {
  Rng rng(11);
  std::vector<Vec3f> p(500);
  for (auto& x : p) x = Vec3f(static_cast<float>(rng.uniform()), static_cast<float>(rng.uniform()), static_cast<float>(rng.uniform()));
  const int k = 8;
  auto nb = nearest_neighbours(p, k);
  ASSERT_EQ(nb.indices.size(), p.size() * k);
  for (size_t i = 0; i < p.size(); ++i) {
    std::vector<std::pair<float, int>> all;
    for (size_t j = 0; j < p.size(); ++j)
      if (j != i) all.emplace_back(glm::dot(p[i] - p[j], p[i] - p[j]), static_cast<int>(j));
    std::partial_sort(all.begin(), all.begin() + k, all.end());
    for (int n = 0; n < k; ++n) {
      EXPECT_NEAR(nb.distances2[i * k + static_cast<size_t>(n)], all[static_cast<size_t>(n)].first, 1e-6f);
      EXPECT_NE(nb.of(i)[n], static_cast<int>(i));
    }
  }
}

TEST(Neighbours, RejectsBadInput) {
  std::vector<Vec3f> p(4, Vec3f(0.0f));
  EXPECT_THROW(nearest_neighbours(p, 0), Error);
  EXPECT_THROW(nearest_neighbours(p, 4), Error);
  p[2].y = std::nanf("");
  EXPECT_THROW(nearest_neighbours(p, 2), Error);
}

}  // namespace
}  // namespace haze::particles
