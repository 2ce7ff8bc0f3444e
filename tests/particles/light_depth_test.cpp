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

}  // namespace
}  // namespace haze::particles
