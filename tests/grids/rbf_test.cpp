// RBF injection (seed 003 eq. 2): against the direct sum, thread-independent, incremental updates
// equal to full ones, and bad blobs rejected with the field named.
#include <haze/core/error.h>
#include <haze/core/rng.h>
#include <haze/grids/rbf.h>

#include <gtest/gtest.h>

namespace haze::grids {
namespace {

std::vector<RbfBlob> random_blobs(int count, uint64_t seed) {
  Rng rng(seed);
  std::vector<RbfBlob> blobs;
  for (int i = 0; i < count; ++i)
    blobs.push_back({Vec3(rng.uniform() * 2 - 1, rng.uniform() * 2 - 1, rng.uniform() * 2 - 1), 0.2 + rng.uniform(), 2.0 + 6.0 * rng.uniform()});
  return blobs;
}

double direct_sum(const std::vector<RbfBlob>& blobs, const Vec3& x) {
  double rho = 0.0;
  for (const auto& b : blobs) rho += b.weight * std::exp(-b.sharpness * b.sharpness * glm::dot(x - b.center, x - b.center));
  return rho;
}

TEST(Rbf, InjectionMatchesTheDirectSumWithinTheReportedBound) {
  const auto blobs = random_blobs(40, 3);
  DenseGrid grid({24, 20, 28}, {Vec3(-1.2), Vec3(1.2)});
  InjectionReport report = inject_rbf(blobs, grid, 1e-4);
  double worst = 0.0;
  for (int k = 0; k < 28; ++k)
    for (int j = 0; j < 20; ++j)
      for (int i = 0; i < 24; ++i)
        worst = std::max(worst, std::abs(direct_sum(blobs, grid.cell_center(i, j, k)) - static_cast<double>(grid.at(i, j, k))));
  // float32 accumulation adds ~1e-6 on densities of order 1.
  EXPECT_LE(worst, report.truncation_bound + 1e-5);
  EXPECT_LE(report.truncation_bound, 4e-3);
  EXPECT_GT(report.cell_updates, 0u);
  EXPECT_LT(report.cell_updates, 40u * grid.cell_count());  // blobs touch only their support
}

TEST(Rbf, InjectionDoesNotDependOnTheThreadCount) {
  const auto blobs = random_blobs(200, 5);
  DenseGrid one({32, 32, 32}, {Vec3(-1.5), Vec3(1.5)}), two = one;
  inject_rbf(blobs, one, 0.0, 1);
  inject_rbf(blobs, two, 0.0, 2);
  EXPECT_EQ(one.values(), two.values());
}

// Seed 003 table 1: when one blob moves, re-injecting the bricks of its old and new support
// gives the same volume as injecting everything again.
TEST(Rbf, ReinjectingTheMovedBlobsBricksEqualsAFullInjection) {
  auto blobs = random_blobs(60, 7);
  const double cutoff = 1e-4;
  DenseGrid grid({40, 40, 40}, {Vec3(-1.5), Vec3(1.5)});
  inject_rbf(blobs, grid, cutoff);
  Aabb old_support = blob_support(blobs[17], cutoff);
  blobs[17].center += Vec3(0.3, -0.2, 0.1);
  Aabb new_support = blob_support(blobs[17], cutoff);
  Aabb region{glm::min(old_support.lo, new_support.lo), glm::max(old_support.hi, new_support.hi)};
  size_t cells = reinject_region(blobs, grid, region, cutoff);
  EXPECT_GT(cells, 0u);
  EXPECT_LT(cells, grid.cell_count());
  DenseGrid full({40, 40, 40}, {Vec3(-1.5), Vec3(1.5)});
  inject_rbf(blobs, full, cutoff);
  EXPECT_EQ(grid.values(), full.values());
}

TEST(Rbf, BadBlobsAreRejectedWithTheFieldNamed) {
  DenseGrid grid({4, 4, 4}, {Vec3(-1), Vec3(1)});
  auto expect_error = [&](std::vector<RbfBlob> blobs, const std::string& field) {
    try {
      inject_rbf(blobs, grid);
      ADD_FAILURE() << "no error for " << field;
    } catch (const Error& e) {
      EXPECT_EQ(e.field(), field);
    }
  };
  expect_error({}, "blobs");
  expect_error({{Vec3(0), std::nan(""), 1.0}}, "blobs[0].weight");
  expect_error({{Vec3(0), 1.0, 1.0}, {Vec3(0), -0.5, 1.0}}, "blobs[1].weight");
  expect_error({{Vec3(0), 1.0, 0.0}}, "blobs[0].sharpness");
  expect_error({{Vec3(0, kInfinity, 0), 1.0, 1.0}}, "blobs[0].center");
  // A zero-weight blob is valid and adds nothing.
  inject_rbf({{Vec3(0), 0.0, 1.0}}, grid);
  for (float v : grid.values()) EXPECT_EQ(v, 0.0f);
}

}  // namespace
}  // namespace haze::grids
