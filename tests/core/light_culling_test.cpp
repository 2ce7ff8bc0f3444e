// Lights that reach nothing (core/light_culling.h): which are culled, and that culling changes no
// image.
#include <haze/core/light_culling.h>
#include <haze/core/method.h>

#include <gtest/gtest.h>

namespace haze {
namespace {

// A fog box [-1, 1]^3, a sphere beside it and, with `floor`, the plane y = -2; a camera in front.
Scene fog_box(bool floor) {
  Scene scene;
  scene.camera.position = Vec3(0.5, 0.5, 5.0);
  scene.camera.look_at = Vec3(0.0);
  scene.camera.width_px = 24, scene.camera.height_px = 18;
  MediumDesc medium;
  medium.bounds = {Vec3(-1.0), Vec3(1.0)};
  medium.sigma_t = Rgb(0.8);
  medium.albedo = Rgb(0.9);
  scene.medium = medium;
  scene.surfaces.push_back({Sphere{Vec3(6.0, 0.0, 0.0), 0.5}, Rgb(0.7), Rgb(0.0), 1.0});
  if (floor) scene.surfaces.push_back({Plane{Vec3(0.0, -2.0, 0.0), Vec3(0.0, 1.0, 0.0)}, Rgb(0.5), Rgb(0.0), 1.0});
  return scene;
}

SpotLight spot(const Vec3& position, const Vec3& direction, double cone_deg) {
  SpotLight s;
  s.position = position, s.direction = glm::normalize(direction), s.cone_deg = cone_deg, s.intensity = Rgb(4.0);
  return s;
}

std::vector<size_t> indices(const std::vector<CulledLight>& culled) {
  std::vector<size_t> i;
  for (const CulledLight& c : culled) i.push_back(c.index);
  return i;
}

// Zero power, and spot cones that miss the box's bounding sphere (radius sqrt 3), the sphere and
// the floor, are culled; cones that reach any of them, however far away, are kept. The box is
// tested through its bounding sphere, so a cone that passes near it is kept too.
TEST(LightCulling, CullsWhatReachesNothing) {
  Scene scene = fog_box(false);
  scene.lights = {spot(Vec3(0, 5, 0), Vec3(0, 1, 0), 30),       // 0: up, away from everything
                  spot(Vec3(0, 5, 0), Vec3(0, -1, 0), 10),      // 1: down onto the box
                  spot(Vec3(6, 4, 0), Vec3(0, -1, 0), 5),       // 2: down onto the sphere only
                  PointLight{Vec3(0, 3, 0), Rgb(0.0)},          // 3: dark
                  spot(Vec3(0, 5, 0), Vec3(0.662, -1, 0), 10),  // 4: between box and sphere: misses both
                  spot(Vec3(0, 5, 0), Vec3(0.554, -1, 0), 10),  // 5: misses the box, meets its bounding sphere: kept
                  PointLight{Vec3(0, 30, 0), Rgb(1.0)}};        // 6: a point light reaches everything
  EXPECT_EQ(indices(culled_lights(scene)), (std::vector<size_t>{0, 3, 4}));
  // A floor catches the cones that point below the horizon, however shallow.
  scene.surfaces.push_back({Plane{Vec3(0.0, -2.0, 0.0), Vec3(0.0, 1.0, 0.0)}, Rgb(0.5), Rgb(0.0), 1.0});
  scene.lights.push_back(spot(Vec3(0, 5, 0), Vec3(1, -0.01, 0), 0.1));  // 7: almost level, toward the floor
  scene.lights.push_back(spot(Vec3(0, 5, 0), Vec3(1, 0.3, 0), 10));     // 8: above the horizon
  EXPECT_EQ(indices(culled_lights(scene)), (std::vector<size_t>{0, 3, 8}));
  // An unbounded medium is reached by every cone.
  scene.medium->bounds = Aabb{};
  EXPECT_EQ(indices(culled_lights(scene)), (std::vector<size_t>{3}));
}

// Rendering with the culled lights left out (haze::render) gives the image the method gives with
// every light (the method called directly), and the stats say which lights went and why.
TEST(LightCulling, ChangesNoImage) {
  Scene scene = fog_box(true);
  scene.lights = {spot(Vec3(0, 5, 0), Vec3(0, 1, 0), 30), spot(Vec3(0, 4, 1), Vec3(0, -1, -0.2), 25), PointLight{Vec3(2, 2, 2), Rgb(0.0)},
                  PointLight{Vec3(-1.5, 0.5, 1.5), Rgb(2.0, 1.5, 1.0)}};
  const RenderResult all = create_method("quadrature")->render(scene, {});
  const RenderResult culled = render(scene, "quadrature");
  ASSERT_EQ(culled.stats["culled_lights"].size(), 2u);
  EXPECT_EQ(culled.stats["culled_lights"][0]["index"], 0);
  EXPECT_EQ(culled.stats["culled_lights"][1]["why"], "point light of zero intensity");
  double largest = 0.0, peak = 0.0;
  for (int y = 0; y < scene.camera.height_px; ++y)
    for (int x = 0; x < scene.camera.width_px; ++x) {
      const Rgb a = all.radiance.at(x, y), b = culled.radiance.at(x, y);
      largest = std::max({largest, std::abs(a.r - b.r), std::abs(a.g - b.g), std::abs(a.b - b.b)});
      peak = std::max({peak, a.r, a.g, a.b});
    }
  EXPECT_GT(peak, 0.0);
  EXPECT_LE(largest, 1e-12 * peak);
}

}  // namespace
}  // namespace haze
