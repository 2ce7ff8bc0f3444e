// ParticleDensity, the particles' own density as core's DensityField: the same rho as the FLANN
// field, majorants that bound it, and the grid the grid methods sample from it.
#include <haze/core/majorant.h>
#include <haze/core/rng.h>
#include <haze/particles/field.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace haze::particles {
namespace {

ParticleSet cloud(int count) {
  ParticleSet set;
  Rng rng(4);
  while (static_cast<int>(set.positions.size()) < count) {
    const Vec3 x(2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
    if (glm::dot(x, x) < 1.0) set.positions.emplace_back(x), set.density.push_back(static_cast<float>(1.0 + x.x));
  }
  set.material.sigma_t = Rgb(2.0);
  return set;
}

TEST(ParticleDensity, MatchesTheFieldAndItsMajorantsBoundIt) {
  const ParticleSet set = cloud(2000);
  const ParticleField field(set.view());
  const ParticleDensity density(set);
  Rng rng(8);
  for (int i = 0; i < 200; ++i) {
    const Vec3 x = density.bounds().lo + Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * density.bounds().extent();
    EXPECT_NEAR(density.density(x), field.density(x), 1e-6 * (1.0 + field.density(x)));  // FLANN squares distances in float
    // A box around x: no point in it above the bound.
    const Aabb box{x - Vec3(0.1), x + Vec3(0.1)};
    const double bound = density.max_density(box);
    for (int s = 0; s < 8; ++s) {
      const Vec3 y = box.lo + Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * box.extent();
      EXPECT_LE(density.density(y), bound * (1.0 + 1e-12));
    }
  }
  // The grid methods' sampling: the field's rho (FLANN) at the centres of 24 cells along the
  // longest side of the bounds, to float rounding.
  const GridDensity sampled = sample_grid(density, 24, 2);
  const Aabb b = density.bounds();
  const double cell = std::max({b.extent().x, b.extent().y, b.extent().z}) / 24.0;
  for (int a = 0; a < 3; ++a) ASSERT_EQ(sampled.resolution[static_cast<size_t>(a)], std::max(2, static_cast<int>(std::ceil(b.extent()[a] / cell))));
  const Vec3 size = b.extent() / Vec3(sampled.resolution[0], sampled.resolution[1], sampled.resolution[2]);
  for (int k = 0, i = 0; k < sampled.resolution[2]; ++k)
    for (int j = 0; j < sampled.resolution[1]; ++j)
      for (int x = 0; x < sampled.resolution[0]; ++x, ++i) {
        const double rho = field.density(b.lo + (Vec3(x, j, k) + 0.5) * size);
        EXPECT_NEAR(sampled.values[static_cast<size_t>(i)], rho, 1e-5 * (1.0 + rho));
      }
  // And as a medium: the closed-form line integral.
  const MediumDesc medium = particle_medium(set, 24);
  const auto m = make_medium(medium);
  EXPECT_NEAR(m->density_integral(Vec3(-2.0, 0.1, 0.0), Vec3(2.0, 0.1, 0.0)),
              field.density_integral(Vec3(-2.0, 0.1, 0.0), Vec3(1.0, 0.0, 0.0), 4.0), 1e-5);
}

// Line integrals from the cell lists count each Gaussian once: they match the field's sum over
// every particle (to the truncation at 3 h, e^-9 of a term, and float32 storage) on segments that
// start and end inside the cloud, and the majorant segments bound the density along them.
TEST(ParticleDensity, LineIntegralsAndMajorantsAlongRandomSegments) {
  const ParticleSet set = cloud(1500);
  const ParticleField field(set.view());
  const ParticleDensity density(set);
  const MajorantGrid& majorants = *density.majorants();
  Rng rng(9);
  for (int i = 0; i < 300; ++i) {
    const Vec3 a = 1.5 * Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
    const Vec3 b = (i % 3 ? 1.5 : 6.0) * Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
    const double length = glm::length(b - a), expected = field.density_integral(a, (b - a) / length, length);
    ASSERT_NEAR(*density.density_integral(a, b), expected, 2e-4 * (1.0 + expected)) << "segment " << i;
    auto walk = majorants.walk({a, (b - a) / length}, 0.0, length);
    MajorantSegment seg;
    while (walk.next(seg))
      for (int s = 0; s < 4; ++s) {
        const double t = seg.t0 + rng.uniform() * (seg.t1 - seg.t0);
        ASSERT_LE(density.density(a + t * (b - a) / length), seg.density) << "segment " << i << " at t " << t;
      }
  }
}

}  // namespace
}  // namespace haze::particles
