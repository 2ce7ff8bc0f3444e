// The batched airlight on every compiled target against its scalar reference, and the reference
// against the float64 table path.
#include <haze/core/rng.h>
#include <haze/analytic/airlight_batch.h>

#include <gtest/gtest.h>
#include <algorithm>
#include <cstdio>
#include <hwy/tests/hwy_gtest.h>

namespace haze::analytic {
namespace {

struct Segments {
  std::vector<float> ox, oy, oz, dx, dy, dz, length;
  SegmentBatch batch() const {
    return {ox.data(), oy.data(), oz.data(), dx.data(), dy.data(), dz.data(), length.data(), ox.size()};
  }
};

// Camera-like segments: starts in a 4-unit box, random directions, lengths 0.01 to 20 or infinite.
Segments random_segments(size_t n, std::uint64_t seed) {
  Rng rng(seed, 5);
  Segments s;
  for (size_t i = 0; i < n; ++i) {
    s.ox.push_back(static_cast<float>(4.0 * rng.uniform() - 2.0));
    s.oy.push_back(static_cast<float>(4.0 * rng.uniform() - 2.0));
    s.oz.push_back(static_cast<float>(4.0 * rng.uniform() - 2.0));
    Vec3 d = direction_around(Vec3(0, 0, 1), 1.0 - 2.0 * rng.uniform(), 2.0 * kPi * rng.uniform());
    s.dx.push_back(static_cast<float>(d.x));
    s.dy.push_back(static_cast<float>(d.y));
    s.dz.push_back(static_cast<float>(d.z));
    s.length.push_back(i % 5 == 0 ? INFINITY : static_cast<float>(0.01 * std::pow(2000.0, rng.uniform())));
  }
  return s;
}

const AirlightTable& table() {
  static const AirlightTable t(PhaseFunction::henyey_greenstein(0.5));
  return t;
}

class AirlightBatchTargets : public hwy::TestWithParamTarget {};
HWY_TARGET_INSTANTIATE_TEST_SUITE_P(AirlightBatchTargets);

TEST_P(AirlightBatchTargets, MatchesScalarReference) {
  for (size_t n : {size_t(1), size_t(37), size_t(1000)}) {
    Segments s = random_segments(n, 3 + n);
    for (float sigma : {0.01f, 0.3f, 2.0f}) {
      AirlightChannel light{0.3f, -0.4f, 0.5f, sigma, 0.8f * sigma, 5.0f};
      std::vector<float> fast(n, 0.0f), reference(n, 0.0f);
      add_airlight(table(), light, s.batch(), fast.data());
      add_airlight_reference(table(), light, s.batch(), reference.data());
      for (size_t i = 0; i < n; ++i)
        ASSERT_NEAR(fast[i], reference[i], 2e-5f * reference[i] + 1e-30f) << "segment " << i << " sigma " << sigma;
    }
  }
}

// The shipped float32 path (and its scalar reference) against adaptive quadrature, including thick
// forward-scattering fog: the table's own 1e-3 (float64, bicubic: 5.8e-4 worst) is kept. Bilinear
// lookups in T itself were 1.2e-2 off at g 0.9, sigma_t 5.
TEST(AirlightBatch, FloatPathAgreesWithQuadrature) {
  const Segments s = random_segments(500, 9);
  for (double g : {-0.3, 0.5, 0.9}) {
    const PhaseFunction phase = PhaseFunction::henyey_greenstein(g);
    const AirlightTable table(phase);
    for (float sigma : {0.01f, 0.3f, 2.0f, 5.0f}) {
      const AirlightChannel light{0.3f, -0.4f, 0.5f, sigma, 0.8f * sigma, 5.0f};
      std::vector<float> fast(s.ox.size(), 0.0f), reference(s.ox.size(), 0.0f);
      add_airlight(table, light, s.batch(), fast.data());
      add_airlight_reference(table, light, s.batch(), reference.data());
      double worst = 0.0;
      for (size_t i = 0; i < fast.size(); ++i) {
        const Vec3 o(s.ox[i], s.oy[i], s.oz[i]), d(s.dx[i], s.dy[i], s.dz[i]);
        const double length = std::isfinite(s.length[i]) ? static_cast<double>(s.length[i]) : kInfinity;
        const double exact = airlight_quadrature(phase, {static_cast<double>(sigma), 0.8 * static_cast<double>(sigma), 5.0},
                                                 AirlightSegment::from_points(o, glm::normalize(d), Vec3(0.3f, -0.4f, 0.5f), length), 1e-9);
        if (!(exact > 1e-30)) continue;  // underflows in float32
        for (float v : {fast[i], reference[i]}) worst = std::max(worst, std::abs(static_cast<double>(v) - exact) / exact);
      }
      std::printf("g %.1f sigma_t %.2f: float32 airlight against quadrature, worst relative error %.2e\n", g, double(sigma), worst);
      EXPECT_LT(worst, 1e-3) << "g " << g << " sigma_t " << sigma;
    }
  }
}

}  // namespace
}  // namespace haze::analytic
