// Medium::majorants, the majorant iterator every medium offers: along any ray its segments are in
// order, cover the ray's stretch through the bounds, and bound the density everywhere on them.
#include <haze/core/majorant.h>
#include <haze/core/medium.h>
#include <haze/core/rng.h>

#include <gtest/gtest.h>

namespace haze {
namespace {

void expect_bounds_density(const MediumDesc& desc) {
  const auto medium = make_medium(desc);
  Rng rng(3);
  for (int i = 0; i < 200; ++i) {
    const Vec3 origin(4.0 * rng.uniform() - 2.0, 4.0 * rng.uniform() - 2.0, 4.0 * rng.uniform() - 2.0);
    const Vec3 direction = glm::normalize(Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5));
    auto walk = medium->majorants().walk({origin, direction}, 0.0, 6.0);
    MajorantSegment segment;
    double last = 0.0;
    while (walk.next(segment)) {
      EXPECT_GE(segment.t0, last - 1e-12);
      EXPECT_GT(segment.t1, segment.t0);
      last = segment.t1;
      for (int s = 0; s < 16; ++s) {
        const double t = segment.t0 + (s + rng.uniform()) / 16.0 * (segment.t1 - segment.t0);
        EXPECT_LE(medium->density(origin + t * direction), segment.density * (1.0 + 1e-12));
      }
    }
  }
}

TEST(Majorants, BoundTheDensityOfEveryMediumAlongRays) {
  MediumDesc rbf;
  rbf.bounds = {Vec3(-1.0), Vec3(1.0)};
  rbf.density = RbfDensity{{{Vec3(0.3, 0.0, 0.1), 1.0, 4.0}, {Vec3(-0.4, 0.2, 0.0), 0.5, 2.0}}};
  expect_bounds_density(rbf);
  MediumDesc grid = rbf;
  std::vector<float> values(5 * 4 * 3);
  for (size_t i = 0; i < values.size(); ++i) values[i] = static_cast<float>((i * 7) % 5);
  grid.density = GridDensity{{5, 4, 3}, values};
  expect_bounds_density(grid);
  MediumDesc constant = rbf;
  constant.density = ConstantDensity{2.0};
  expect_bounds_density(constant);
}

}  // namespace
}  // namespace haze
