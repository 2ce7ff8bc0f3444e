// Direction sets, the discrete phase matrix and its separable factorization (seed 000).
#include <haze/core/error.h>
#include <haze/core/phase_matrix.h>

#include <gtest/gtest.h>

namespace haze {
namespace {

TEST(DirectionSet, UnitVectorsWithWeightsSummingTo4Pi) {
  for (const auto& set : {DirectionSet::fibonacci(128), DirectionSet::uniform_random(300, 5)}) {
    double sum = 0.0;
    Vec3 mean(0.0);
    for (int i = 0; i < set.size(); ++i) {
      EXPECT_NEAR(glm::length(set[i]), 1.0, 1e-12);
      sum += set.weight(i);
      mean += set[i] / static_cast<double>(set.size());
    }
    EXPECT_NEAR(sum, 4.0 * kPi, 1e-12);
    EXPECT_LT(glm::length(mean), 0.1);  // no preferred direction
  }
  // Fibonacci points integrate low-order polynomials well: <z^2> = 1/3.
  auto fib = DirectionSet::fibonacci(512);
  double z2 = 0.0;
  for (int i = 0; i < fib.size(); ++i) z2 += fib.weight(i) * fib[i].z * fib[i].z / (4.0 * kPi);
  EXPECT_NEAR(z2, 1.0 / 3.0, 1e-4);
  EXPECT_EQ(fib.nearest(fib[17]), 17);
  EXPECT_THROW(DirectionSet::fibonacci(0), Error);
}

TEST(PhaseMatrix, RowsSumToOneAndMatrixIsSymmetric) {
  for (double g : {0.0, 0.5, 0.9}) {
    PhaseMatrix m(PhaseFunction::henyey_greenstein(g), DirectionSet::fibonacci(128));
    EXPECT_LT((m.matrix().rowwise().sum().array() - 1.0).abs().maxCoeff(), 1e-12) << g;
    EXPECT_LT((m.matrix() - m.matrix().transpose()).cwiseAbs().maxCoeff(), 1e-15) << g;
    EXPECT_TRUE((m.renormalization_factors().array() > 0.0).all());
    // Row sums of the unscaled matrix are the quadrature of integral p = 1: the discrete set misses
    // more of the forward peak as g grows.
    double worst = (m.raw_row_sums().array() - 1.0).abs().maxCoeff();
    if (g == 0.0) {
      EXPECT_LT(worst, 1e-12);
    } else if (g == 0.5) {
      EXPECT_LT(worst, 0.05);
    } else {
      EXPECT_GT(worst, 0.05);
    }
  }
}

TEST(SeparablePhase, MatchesSeedFigure3AndDirectProduct) {
  PhaseMatrix m(PhaseFunction::henyey_greenstein(0.5), DirectionSet::fibonacci(128));
  SeparablePhase s(m, 24);
  // Seed 000 fig. 3: about 10% relative error with 24 terms at g = 0.5.
  EXPECT_GT(s.relative_error(), 0.06);
  EXPECT_LT(s.relative_error(), 0.14);
  // The error reported from dropped eigenvalues equals the error of the reconstructed matrix.
  Eigen::MatrixXd diff = m.matrix() - s.reconstruct();
  EXPECT_NEAR(s.relative_error(), diff.norm() / m.matrix().norm(), 1e-12);
  EXPECT_NEAR(s.rmse(), std::sqrt(diff.squaredNorm() / diff.size()), 1e-14);
  // The O(D N) moment path equals the O(D^2) product with the truncated matrix.
  Eigen::VectorXd radiance = Eigen::VectorXd::Random(128).cwiseAbs();
  EXPECT_LT((s.apply(radiance) - s.reconstruct() * radiance).cwiseAbs().maxCoeff(), 1e-12);
  // And approximates the full product within the matrix error.
  double rel = (s.apply(radiance) - m.apply(radiance)).norm() / m.apply(radiance).norm();
  EXPECT_LT(rel, s.relative_error());
  // A row-stochastic symmetric matrix has eigenvalue 1 (vector of ones); the next three (l = 1)
  // are close to b_1 = g.
  EXPECT_NEAR(s.eigenvalues()(0), 1.0, 1e-10);
  for (int k = 1; k < 4; ++k) EXPECT_NEAR(s.eigenvalues()(k), 0.5, 0.03);
}

TEST(SeparablePhase, AllTermsReproduceTheMatrix) {
  PhaseMatrix m(PhaseFunction::cornette_shanks(0.7), DirectionSet::fibonacci(64));
  SeparablePhase s(m, 64);
  EXPECT_LT(s.relative_error(), 1e-12);
  EXPECT_LT((s.reconstruct() - m.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  // Error falls as terms are added.
  double previous = 1.0;
  for (int n : {1, 4, 9, 16, 36}) {
    double e = SeparablePhase(m, n).relative_error();
    EXPECT_LT(e, previous);
    previous = e;
  }
  EXPECT_THROW(SeparablePhase(m, 0), Error);
  EXPECT_THROW(SeparablePhase(m, 65), Error);
}

}  // namespace
}  // namespace haze
