// Optical-depth volumes (seed 003 sec. 4.3): the DDA ground truth against closed forms, the sweep
// against the DDA (the 2% on a 64^3 heterogeneous medium), and the paper's gathering
// overestimating diagonals by the ratio of grid-path to straight length.
#include <haze/core/error.h>
#include <haze/grids/optical_depth.h>
#include <haze/grids/rbf.h>

#include <gtest/gtest.h>
#include <hwy/tests/hwy_gtest.h>

#include "scenes/lumpy_cloud.h"

namespace haze::grids {
namespace {

DenseGrid constant_grid(int n, float rho) {
  DenseGrid g({n, n, n}, {Vec3(-1), Vec3(1)});
  std::fill(g.values().begin(), g.values().end(), rho);
  return g;
}

struct ErrorStats {
  double mean = 0.0, max = 0.0;  // relative, over cells whose exact depth is at least the floor
  double mean_abs_over_mean = 0.0;  // mean |error| over all cells / mean exact depth
};

ErrorStats compare(const DenseGrid& approx, const DenseGrid& exact, double floor) {
  ErrorStats s;
  int count = 0;
  double sum_abs = 0.0, sum = 0.0;
  for (size_t c = 0; c < exact.values().size(); ++c) {
    double e = exact.values()[c], err = std::abs(static_cast<double>(approx.values()[c]) - e);
    sum_abs += err, sum += e;
    if (e < floor) continue;
    s.mean += err / e, s.max = std::max(s.max, err / e), ++count;
  }
  s.mean /= std::max(count, 1);
  s.mean_abs_over_mean = sum_abs / sum;
  return s;
}

TEST(OpticalDepth, DdaIsExactInAHomogeneousGrid) {
  DenseGrid g = constant_grid(16, 0.7f);
  // Inside: density times length; crossing the boundary: only the part inside counts.
  EXPECT_NEAR(density_integral_dda(g, Vec3(-0.3, 0.2, 0.1), Vec3(0.5, -0.4, 0.8)), 0.7 * glm::length(Vec3(0.8, -0.6, 0.7)), 1e-6);
  EXPECT_NEAR(density_integral_dda(g, Vec3(0.0), Vec3(3.0, 0.0, 0.0)), 0.7, 1e-6);
  EXPECT_NEAR(density_integral_dda(g, Vec3(-5, 0.3, 0.3), Vec3(5, 0.3, 0.3)), 1.4, 1e-6);
}

TEST(OpticalDepth, SweepAndExactAgreeInAHomogeneousGrid) {
  DenseGrid g = constant_grid(24, 0.5f);
  for (const Light& light : {Light{PointLight{Vec3(0.13, -0.21, 0.05)}}, Light{PointLight{Vec3(2.5, 1.2, -1.7)}},
                             Light{DirectionalLight{glm::normalize(Vec3(-0.3, -1.0, 0.45))}}}) {
    DenseGrid exact = optical_depth(g, light, {DepthScheme::exact});
    DenseGrid sweep = optical_depth(g, light, {DepthScheme::sweep});
    ErrorStats e = compare(sweep, exact, 1e-3);
    EXPECT_LT(e.max, 1e-4) << light.index();
  }
}

// The criterion: sweep (default 4 layers per step) within 2% of exact on average over
// every cell of a 64^3 heterogeneous medium, for lights inside and outside and a directional
// light: the mean error over the mean depth, and the mean relative error where the depth is at
// least 0.1 (below that relative errors of tiny depths say little about transmittance).
TEST(OpticalDepth, SweepIsWithinTwoPercentOfExactInAHeterogeneousMedium) {
  DenseGrid g = lumpy_cloud(64);
  for (const Light& light : {Light{PointLight{Vec3(0.05, 0.1, -0.02)}}, Light{PointLight{Vec3(1.8, 1.1, 0.6)}},
                             Light{DirectionalLight{glm::normalize(Vec3(0.4, -1.0, 0.3))}}}) {
    DenseGrid exact = optical_depth(g, light, {DepthScheme::exact});
    DenseGrid sweep = optical_depth(g, light, {DepthScheme::sweep});
    ErrorStats e = compare(sweep, exact, 0.1);
    std::printf("sweep vs exact, light %zu: mean |error| / mean depth %.2e; where depth >= 0.1: mean %.2e, max %.2e\n",
                light.index(), e.mean_abs_over_mean, e.mean, e.max);
    EXPECT_LT(e.mean_abs_over_mean, 0.02) << light.index();
    EXPECT_LT(e.mean, 0.02) << light.index();
  }
}

// Seed 003's gathering follows grid paths: along an axis it is exact, along the body diagonal it
// adds a cell per step of each axis, sqrt(3) times the straight length.
// The sweep's SIMD kernel on every compiled Highway target against its scalar reference (the same
// float32 formulas; FMA contraction differs between them), on lights inside, outside, at a cell
// centre and directional, with 1 and 4 layers, on a grid of uneven sides so runs end mid-vector.
class SweepTargets : public hwy::TestWithParamTarget {};
HWY_TARGET_INSTANTIATE_TEST_SUITE_P(SweepTargets);

TEST_P(SweepTargets, MatchesTheScalarKernel) {
  DenseGrid g({37, 29, 23}, {Vec3(-1), Vec3(1)});
  inject_rbf({{Vec3(0.2, -0.1, 0.3), 1.5, 3.0}, {Vec3(-0.4, 0.3, -0.2), 2.0, 4.0}}, g);
  const Vec3 centre = g.cell_center(11, 7, 5);
  for (const Light& light : {Light{PointLight{Vec3(0.13, -0.21, 0.05)}}, Light{PointLight{Vec3(2.5, 1.2, -1.7)}}, Light{PointLight{centre}},
                             Light{DirectionalLight{glm::normalize(Vec3(-0.3, -1.0, 0.45))}}}) {
    for (int layers : {1, 4}) {
      DepthOptions options;
      options.sweep_layers = layers;
      DenseGrid simd = optical_depth(g, light, options);
      options.scalar_kernel = true;
      DenseGrid scalar = optical_depth(g, light, options);
      for (size_t c = 0; c < g.cell_count(); ++c)
        ASSERT_NEAR(simd.values()[c], scalar.values()[c], 1e-5f * (1.0f + scalar.values()[c]))
            << "cell " << c << " light " << light.index() << " layers " << layers << " target " << hwy::TargetName(GetParam());
    }
  }
}

TEST(OpticalDepth, PaperGatheringOverestimatesDiagonals) {
  const int n = 32;
  DenseGrid g({n, n, n}, {Vec3(0), Vec3(n)});
  std::fill(g.values().begin(), g.values().end(), 1.0f);
  DepthStats stats;
  DenseGrid paper = optical_depth(g, PointLight{Vec3(0.5)}, {DepthScheme::paper}, &stats);
  DenseGrid exact = optical_depth(g, PointLight{Vec3(0.5)}, {DepthScheme::exact});
  EXPECT_GT(stats.iterations, 1);
  EXPECT_NEAR(paper.at(n - 1, 0, 0) / exact.at(n - 1, 0, 0), 1.0, 1e-4);
  EXPECT_NEAR(paper.at(n - 1, n - 1, 0) / exact.at(n - 1, n - 1, 0), std::sqrt(2.0), 0.02);
  EXPECT_NEAR(paper.at(n - 1, n - 1, n - 1) / exact.at(n - 1, n - 1, n - 1), std::sqrt(3.0), 0.02);
}

TEST(OpticalDepth, LightAtACellCentreAndBadLights) {
  DenseGrid g = constant_grid(8, 1.0f);
  for (auto scheme : {DepthScheme::exact, DepthScheme::paper, DepthScheme::sweep}) {
    DenseGrid t = optical_depth(g, PointLight{g.cell_center(3, 4, 5)}, {scheme});
    EXPECT_EQ(t.at(3, 4, 5), 0.0f) << name(scheme);
    for (float v : t.values()) EXPECT_TRUE(std::isfinite(v)) << name(scheme);
  }
  EXPECT_THROW(optical_depth(g, SkyLight{}), Error);
  EXPECT_THROW(optical_depth(g, PointLight{Vec3(std::nan(""))}), Error);
  EXPECT_THROW(depth_scheme_from_name("fast"), Error);
}

}  // namespace
}  // namespace haze::grids

namespace haze::grids {
namespace {

// A walk that reaches the grid's face a rounding error short of its length must stop there, not
// read the cell after the face (the next row's first cell, or past the array). Only the x = 0
// layer is dense; a light toward +x sees none of it from x >= 1, so every other depth is 0.
TEST(OpticalDepth, SweepWalksStopAtTheGridFace) {
  DenseGrid g({32, 28, 32}, {Vec3(-1), Vec3(1)});
  for (int k = 0; k < 32; ++k)
    for (int j = 0; j < 28; ++j) g.at(0, j, k) = 1e30f;
  for (bool scalar : {true, false}) {
    for (const Vec3& to_light : {Vec3(1.0, 0.3, 0.2), Vec3(0.9, -0.35, 0.3), Vec3(1.0, 0.1, -0.45)}) {
      DepthOptions options;
      options.scalar_kernel = scalar;
      const DenseGrid depth = optical_depth(g, DirectionalLight{-glm::normalize(to_light), Rgb(1.0)}, options);
      float worst = 0.0f;
      for (int k = 0; k < 32; ++k)
        for (int j = 0; j < 28; ++j)
          for (int i = 1; i < 32; ++i) worst = std::max(worst, depth.at(i, j, k));
      EXPECT_EQ(worst, 0.0f) << (scalar ? "scalar" : "simd") << " toward " << to_light.x << " " << to_light.y << " " << to_light.z;
    }
  }
}

}  // namespace
}  // namespace haze::grids
