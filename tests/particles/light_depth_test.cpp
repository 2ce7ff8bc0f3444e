// The lights' depth maps (light_depth.h) against the exact line integral of the particles'
// density (ParticleField::density_integral), for a directional light, a point light outside the
// cloud (one perspective face) and one inside it (a cube map).
#include <haze/core/error.h>
#include <haze/core/rng.h>
#include <haze/particles/light_depth.h>

#include <gtest/gtest.h>

namespace haze::particles {
namespace {

struct Cloud {
  std::vector<Vec3f> positions;
  std::vector<float> density;
  ParticleSet set;
  explicit Cloud(int count) {
    Rng rng(9);
    while (static_cast<int>(positions.size()) < count) {
      const Vec3 x(2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
      if (glm::dot(x, x) < 1.0) positions.emplace_back(x), density.push_back(static_cast<float>(1.0 + x.x));  // a gradient
    }
  }
  ParticleView view() const {
    ParticleView v;
    v.positions = positions, v.density = density;
    return v;
  }
};

// Over points inside the cloud: the mean |error| of the map's optical depth is within 2% of the
// mean depth (interpolation between texel rays half a particle width apart), with no bias over 1%.
void expect_matches(const ParticleField& field, const Light& light, const char* name) {
  const LightDepthMap map(field, light, 0);
  Rng rng(4);
  double abs_error = 0.0, signed_error = 0.0, total = 0.0;
  int count = 0;
  while (count < 400) {
    const Vec3 x(2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
    if (glm::dot(x, x) > 0.9) continue;
    LightArrival a;
    ASSERT_TRUE(arrival(light, x, a));
    const double exact = field.density_integral(x, a.to_light, a.distance), tabulated = map.depth(x);
    abs_error += std::abs(tabulated - exact), signed_error += tabulated - exact, total += exact;
    ++count;
  }
  std::printf("%s: %d x %d texels, %d nodes; mean depth %.3f, mean |error| %.2f%%, bias %+.2f%%\n", name, map.resolution(), map.resolution(),
              map.nodes(), total / count, 100 * abs_error / total, 100 * signed_error / total);
  EXPECT_LT(abs_error / total, 0.02) << name;
  EXPECT_LT(std::abs(signed_error / total), 0.01) << name;
}

TEST(LightDepthMap, MatchesTheLineIntegrals) {
  const Cloud cloud(3000);
  const ParticleField field(cloud.view());
  expect_matches(field, DirectionalLight{glm::normalize(Vec3(-0.5, -0.7, -0.5)), Rgb(1.0)}, "directional");
  expect_matches(field, PointLight{Vec3(1.6, -0.5, 1.2), Rgb(1.0)}, "point outside");
  expect_matches(field, PointLight{Vec3(0.1, 0.2, -0.1), Rgb(1.0)}, "point inside");
  expect_matches(field, SpotLight{Vec3(0.0, 3.0, 0.0), Vec3(0.0, -1.0, 0.0), Rgb(1.0), 1.0, 60.0}, "spot");
  EXPECT_THROW(LightDepthMap(field, SkyLight{}, 0), Error);
}

// Moving 100 of 3000 particles by up to 0.3 (their neighbours' sizes change with them): the map
// updated in place matches the new cloud's exact line integrals as a fresh map would (2% mean
// |error|), where the old map is off by more, and touched() holds wherever the depth changed.
// A Gaussian leaving the map's sphere is refused.
TEST(LightDepthMap, UpdateFollowsMovedParticles) {
  const Cloud cloud(3000);
  Cloud moved = cloud;
  Rng rng(11);
  for (size_t p = 0; p < moved.positions.size(); p += 30) {
    const Vec3 x = Vec3(moved.positions[p]) + 0.3 * Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
    if (glm::length(x) < 0.95) moved.positions[p] = Vec3f(x);
  }
  const ParticleField before(cloud.view()), after(moved.view());
  std::vector<Gaussian> old_gaussians, new_gaussians;
  for (size_t p = 0; p < before.size(); ++p) {
    const Gaussian a{before.position(p), before.h(p), before.weight(p)}, b{after.position(p), after.h(p), after.weight(p)};
    if (a.x != b.x || a.h != b.h) old_gaussians.push_back(a), new_gaussians.push_back(b);
  }
  for (const Light& light : {Light(DirectionalLight{glm::normalize(Vec3(-0.5, -0.7, -0.5)), Rgb(1.0)}), Light(PointLight{Vec3(0.1, 0.2, -0.1), Rgb(1.0)})}) {
    const LightDepthMap old_map(before, light, 0);
    LightDepthMap map = old_map;
    ASSERT_TRUE(map.update(old_gaussians, new_gaussians, 0));
    Rng points(4);
    double updated_error = 0.0, old_error = 0.0, total = 0.0;
    int count = 0, missed = 0;
    while (count < 400) {
      const Vec3 x(2.0 * points.uniform() - 1.0, 2.0 * points.uniform() - 1.0, 2.0 * points.uniform() - 1.0);
      if (glm::dot(x, x) > 0.9) continue;
      LightArrival a;
      ASSERT_TRUE(arrival(light, x, a));
      const double exact = after.density_integral(x, a.to_light, a.distance);
      updated_error += std::abs(map.depth(x) - exact), old_error += std::abs(old_map.depth(x) - exact), total += exact;
      if (map.depth(x) != old_map.depth(x) && !map.touched(x)) ++missed;
      ++count;
    }
    std::printf("%zu Gaussians changed: updated map |error| %.2f%%, old map %.2f%%\n", new_gaussians.size(), 100 * updated_error / total,
                100 * old_error / total);
    EXPECT_LT(updated_error / total, 0.02);
    EXPECT_GT(old_error, 1.5 * updated_error);
    EXPECT_EQ(missed, 0);
  }
  LightDepthMap map(before, PointLight{Vec3(0.1, 0.2, -0.1), Rgb(1.0)}, 0);
  const Gaussian far{Vec3(5.0, 0.0, 0.0), 0.1, 1.0};
  EXPECT_FALSE(map.update(std::vector<Gaussian>{far}, std::vector<Gaussian>{far}, 0));
}

}  // namespace
}  // namespace haze::particles
