// Lights that reach nothing (core/light_culling.h): which are culled, and that culling changes no
// image.
#include <haze/core/error.h>
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

// For a single-scattering method, spot cones that miss the view are culled too: behind the
// camera, or beside the frustum of a pinhole or an orthographic camera; a cone that crosses the
// view from outside it is kept.
TEST(LightCulling, SingleScatteringCullsWhatIsOutOfView) {
  Scene scene = fog_box(true);
  scene.camera.position = Vec3(0, 0, 5), scene.camera.look_at = Vec3(0), scene.camera.fov_y_deg = 30;
  scene.lights = {spot(Vec3(0, 0, 6), Vec3(0, 0, 1), 20),        // 0: behind the camera, facing away
                  spot(Vec3(0, 0, 6), Vec3(0, 0, -1), 20),       // 1: behind the camera, facing the view
                  spot(Vec3(-2, 0, 2), Vec3(-1, 0, 0.3), 10),    // 2: left of the view, facing further left
                  spot(Vec3(-3, 0, 2), Vec3(1, 0, 0), 10)};      // 3: left of the view, shining across it
  EXPECT_EQ(indices(culled_lights(scene)), (std::vector<size_t>{}));  // all reach the box or the floor
  EXPECT_EQ(indices(culled_lights(scene, true)), (std::vector<size_t>{0, 2}));
  scene.camera.type = Camera::Type::orthographic, scene.camera.height = 1.0;
  EXPECT_EQ(indices(culled_lights(scene, true)), (std::vector<size_t>{0, 2}));
}

double largest_difference(const Image& a, const Image& b, double& peak) {
  double largest = 0.0;
  peak = 0.0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) {
      const Rgb p = a.at(x, y), q = b.at(x, y);
      largest = std::max({largest, std::abs(p.r - q.r), std::abs(p.g - q.g), std::abs(p.b - q.b)});
      peak = std::max({peak, p.r, p.g, p.b});
    }
  return largest;
}

// Rendering with the culled lights left out (haze::render) gives the image the method gives with
// every light (the method called directly), for the single-scattering methods whose view culls
// more, and the stats say which lights went and why. Analytic agrees to the bit; quadrature to its
// integration error (it splits each ray at every light's closest point: 6e-7 of the peak here).
TEST(LightCulling, ChangesNoImage) {
  Scene scene = fog_box(true);
  scene.camera.fov_y_deg = 10;  // the middle of the box
  scene.lights = {spot(Vec3(0, 5, 0), Vec3(0, 1, 0), 30), spot(Vec3(0, 4, 1), Vec3(0, -1, -0.2), 25), PointLight{Vec3(2, 2, 2), Rgb(0.0)},
                  PointLight{Vec3(-1.5, 0.5, 1.5), Rgb(2.0, 1.5, 1.0)},
                  spot(Vec3(-0.9, 0.9, 0.5), Vec3(-1, 0.3, 0), 15)};  // in the box, out of view, facing away from it
  for (const std::string method : {"quadrature", "analytic"}) {
    const RenderResult all = create_method(method)->prepare(scene, {})->render(View{scene.camera}, {});
    const RenderResult culled = render(scene, method);
    ASSERT_EQ(culled.stats["culled_lights"].size(), 3u) << method;
    EXPECT_EQ(culled.stats["culled_lights"][0]["index"], 0);
    EXPECT_EQ(culled.stats["culled_lights"][1]["why"], "point light of zero intensity");
    EXPECT_EQ(culled.stats["culled_lights"][2]["index"], 4);
    double peak = 0.0;
    const double largest = largest_difference(all.radiance, culled.radiance, peak);
    EXPECT_GT(peak, 0.0);
    EXPECT_LE(largest, (method == "analytic" ? 0.0 : 1e-5) * peak) << method;
  }
  // The reference sees multiple scattering: only the lights that reach nothing go.
  RenderOptions options;
  options.settings = {{"spp", 1}};
  EXPECT_EQ(render(scene, "reference", options).stats["culled_lights"].size(), 2u);
}

// An error about a light names it by its index in the caller's scene, culled lights counted.
TEST(LightCulling, ErrorsNameTheCallersLight) {
  Scene scene = fog_box(false);
  scene.lights = {PointLight{Vec3(0, 3, 0), Rgb(0.0)}, DirectionalLight{Vec3(0, -1, 0), Rgb(1.0)}};
  try {
    render(scene, "analytic");
    FAIL() << "analytic accepted a directional light";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "lights[1].type");
  }
}

}  // namespace
}  // namespace haze
