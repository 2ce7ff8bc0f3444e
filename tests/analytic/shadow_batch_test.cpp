// The batched shadow tests on every compiled target against LightShadows' own (their scalar
// references): view stretches past planes and spheres, lights outside and inside a sphere.
#include <haze/analytic/shadow_batch.h>
#include <haze/core/rng.h>

#include <gtest/gtest.h>
#include <hwy/tests/hwy_gtest.h>

#include <cmath>
#include <vector>

namespace haze::analytic {
namespace {

class ShadowBatchTargets : public hwy::TestWithParamTarget {};
HWY_TARGET_INSTANTIATE_TEST_SUITE_P(ShadowBatchTargets);

TEST_P(ShadowBatchTargets, ClassesAndVisibilityMatchLightShadows) {
  const std::vector<Surface> surfaces{Surface{Plane{Vec3(0.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0)}}, Surface{Sphere{Vec3(0.4, 0.6, 0.8), 0.6}},
                                      Surface{Sphere{Vec3(-1.0, 1.5, -0.5), 0.3}}};
  Rng rng(29, 4);
  const size_t n = 1003, padded = 1008;
  std::vector<double> columns(8 * padded, 0.0);
  const auto column = [&](size_t k) { return columns.data() + k * padded; };
  std::vector<Ray> rays(n);
  for (size_t i = 0; i < n; ++i) {
    rays[i] = {Vec3(8.0 * rng.uniform() - 4.0, 0.1 + 3.0 * rng.uniform(), 8.0 * rng.uniform() - 4.0),
               direction_around(Vec3(0, 1, 0), 2.0 * rng.uniform() - 1.0, 2.0 * kPi * rng.uniform())};
    double t_hit;
    Vec3 normal;
    nearest_surface(surfaces, rays[i], i % 7 == 0 ? kInfinity : 12.0, t_hit, normal);
    for (int k = 0; k < 3; ++k) column(static_cast<size_t>(k))[i] = rays[i].origin[k], column(3 + static_cast<size_t>(k))[i] = rays[i].direction[k];
    column(6)[i] = i % 5 == 0 ? 0.0 : 0.5 * rng.uniform() * std::min(t_hit, 12.0);
    column(7)[i] = t_hit;
  }
  const ShadowRays batch{{column(0), column(1), column(2)}, {column(3), column(4), column(5)}, column(6), column(7), n};
  for (const Vec3& light : {Vec3(-1.2, 1.8, 0.0), Vec3(0.3, 2.2, 1.4), Vec3(0.5, 0.7, 0.9)}) {
    const LightShadows shadows(surfaces, light);
    std::vector<float> classes(padded), visible(padded);
    classify_stretches(shadows, batch, classes.data());
    int seen[3] = {};
    for (size_t i = 0; i < n; ++i) {
      const auto want = shadows.classify(rays[i], column(6)[i], column(7)[i]);
      ASSERT_EQ(classes[i], static_cast<float>(static_cast<int>(want))) << "ray " << i << " light at " << light.x;
      ++seen[static_cast<int>(want)];
    }
    EXPECT_GT(seen[0] * seen[1] * seen[2], 0) << "every class tried, light at " << light.x;
    // Visibility from points along the rays (their stretches' middles and ends on the surfaces).
    std::vector<double> points(3 * padded, 0.0);
    for (size_t i = 0; i < n; ++i) {
      const Vec3 x = rays[i].at(i % 2 == 0 || !std::isfinite(column(7)[i]) ? column(6)[i] : column(7)[i]);
      for (size_t k = 0; k < 3; ++k) points[k * padded + i] = x[static_cast<int>(k)];
    }
    const double* const x[3] = {points.data(), points.data() + padded, points.data() + 2 * padded};
    for (const Surface* self : {static_cast<const Surface*>(nullptr), &surfaces[0]}) {
      light_visible(shadows, x, n, self, visible.data());
      for (size_t i = 0; i < n; ++i)
        ASSERT_EQ(visible[i], shadows.hidden(Vec3(x[0][i], x[1][i], x[2][i]), self) ? 0.0f : 1.0f) << "point " << i << " light at " << light.x;
    }
  }
}

// lit_pieces against lit_stretches: the same lit stretches, to 1e-9 of the stretch.
TEST(ShadowBatch, LitPiecesAreLitStretches) {
  const std::vector<Surface> surfaces{Surface{Plane{Vec3(0.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0)}}, Surface{Sphere{Vec3(0.4, 0.6, 0.8), 0.6}},
                                      Surface{Sphere{Vec3(-1.0, 1.5, -0.5), 0.3}}};
  Rng rng(31, 4);
  for (const Vec3& light : {Vec3(-1.2, 1.8, 0.0), Vec3(0.3, 2.2, 1.4), Vec3(0.5, 0.7, 0.9)}) {
    const LightShadows shadows(surfaces, light);
    size_t cut = 0;
    for (int i = 0; i < 2000; ++i) {
      const Ray ray{Vec3(8.0 * rng.uniform() - 4.0, 0.1 + 3.0 * rng.uniform(), 8.0 * rng.uniform() - 4.0),
                    direction_around(Vec3(0, 1, 0), 2.0 * rng.uniform() - 1.0, 2.0 * kPi * rng.uniform())};
      double t1;
      Vec3 normal;
      nearest_surface(surfaces, ray, i % 9 == 0 ? kInfinity : 12.0, t1, normal);
      const double t0 = 0.3 * rng.uniform() * std::min(t1, 12.0);
      std::vector<std::pair<double, double>> want, got;
      lit_stretches(surfaces, ray, t0, t1, light, want);
      lit_pieces(shadows, ray, t0, t1, got);
      ASSERT_EQ(got.size(), want.size()) << "ray " << i;
      for (size_t k = 0; k < got.size(); ++k) {
        const double tolerance = 1e-9 * (std::isfinite(t1) ? t1 : 1.0 + t0);
        EXPECT_NEAR(got[k].first, want[k].first, tolerance) << "ray " << i;
        if (std::isfinite(want[k].second)) EXPECT_NEAR(got[k].second, want[k].second, tolerance) << "ray " << i;
        else EXPECT_EQ(got[k].second, want[k].second) << "ray " << i;
      }
      cut += want.size() > 1 || (want.size() == 1 && (want[0].first > t0 || want[0].second < t1));
    }
    EXPECT_GT(cut, 0u) << "light at " << light.x;
  }
}

}  // namespace
}  // namespace haze::analytic
