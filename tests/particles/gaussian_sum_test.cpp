// Sums of truncated Gaussians on every compiled Highway target: one term is w exp(-r^2 / h^2),
// terms at or past the cut are left out, and random lists agree with the scalar reference.
#include <haze/core/rng.h>
#include <haze/particles/gaussian_sum.h>

#include <gtest/gtest.h>
#include <hwy/tests/hwy_gtest.h>

#include <cmath>
#include <vector>

namespace haze::particles {
namespace {

class GaussianSum : public hwy::TestWithParamTarget {};
HWY_TARGET_INSTANTIATE_TEST_SUITE_P(GaussianSum);

struct Terms {
  std::vector<float> x, y, z, inv_h2, w;
  void add(float px, float py, float pz, float h, float weight) {
    x.push_back(px), y.push_back(py), z.push_back(pz), inv_h2.push_back(1.0f / (h * h)), w.push_back(weight);
  }
  GaussianList list() {
    while (x.size() % kGaussianPad) x.push_back(0), y.push_back(0), z.push_back(0), inv_h2.push_back(0), w.push_back(0);
    return {x.data(), y.data(), z.data(), inv_h2.data(), w.data(), x.size()};
  }
};

TEST_P(GaussianSum, OneTermIsItsGaussianAndTheCutLeavesTermsOut) {
  Terms t;
  t.add(1.0f, 2.0f, 3.0f, 0.5f, 2.0f);    // r = 0.6 from the point: 2 exp(-1.44)
  t.add(1.0f, 2.0f, 0.7f, 0.5f, 100.0f);  // r = 1.7 = 3.4 h: past a cut of 3 h
  const GaussianList g = t.list();
  EXPECT_NEAR(gaussian_sum(g, 1.0f, 2.0f, 2.4f, 9.0f), 2.0 * std::exp(-1.44), 2e-6);
  EXPECT_NEAR(gaussian_sum(g, 1.0f, 2.0f, 2.4f, 16.0f), 2.0 * std::exp(-1.44) + 100.0 * std::exp(-1.7 * 1.7 / 0.25), 1e-5);
  EXPECT_EQ(gaussian_sum(g, 50.0f, 2.0f, 2.4f, 9.0f), 0.0f);
}

TEST_P(GaussianSum, AgreesWithTheScalarReference) {
  Rng rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    Terms t;
    const int n = 1 + static_cast<int>(rng.uniform() * 300);
    for (int i = 0; i < n; ++i)
      t.add(static_cast<float>(rng.uniform()), static_cast<float>(rng.uniform()), static_cast<float>(rng.uniform()),
            static_cast<float>(0.05 + 0.3 * rng.uniform()), static_cast<float>(rng.uniform()));
    const GaussianList g = t.list();
    const auto px = static_cast<float>(rng.uniform()), py = static_cast<float>(rng.uniform()), pz = static_cast<float>(rng.uniform());
    const float expected = gaussian_sum_reference(g, px, py, pz, 9.0f), got = gaussian_sum(g, px, py, pz, 9.0f);
    ASSERT_NEAR(got, expected, 1e-5f * (1.0f + expected)) << "trial " << trial << " target " << hwy::TargetName(GetParam());
  }
}

}  // namespace
}  // namespace haze::particles
