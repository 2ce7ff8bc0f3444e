// haze::prepare and haze::Solution: one solution renders any camera as a fresh render would,
// updates give what preparing the changed scene gives, and misuse gets a clear haze::Error.
#include <haze/core/error.h>
#include <haze/core/method.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace haze {
namespace {

Scene lamp_fog() {
  Scene scene;
  scene.camera.position = Vec3(0.5, 0.5, 5.0);
  scene.camera.width_px = 16, scene.camera.height_px = 12;
  MediumDesc medium;
  medium.bounds = {Vec3(-1.0), Vec3(1.0)};
  medium.sigma_t = Rgb(0.8);
  medium.albedo = Rgb(0.9);
  scene.medium = medium;
  scene.lights = {PointLight{Vec3(0.2, 1.5, 0.3), Rgb(4.0)}, PointLight{Vec3(-1.5, 0.5, 1.0), Rgb(2.0, 1.5, 1.0)}};
  scene.surfaces.push_back({Plane{Vec3(0.0, -1.0, 0.0), Vec3(0.0, 1.0, 0.0)}, Rgb(0.5), Rgb(0.0), 1.0});
  return scene;
}

const nlohmann::json kSteps = {{"steps", 64}};

RenderOptions with(const nlohmann::json& settings) {
  RenderOptions options;
  options.settings = settings;
  return options;
}

// Deterministic quadrature: a second camera from the same solution is bit for bit the render of
// the scene seen from it.
TEST(Solution, RendersAnyCameraAsAFreshRenderWould) {
  Scene scene = lamp_fog();
  const Solution solution = prepare(scene, "quadrature", with(kSteps));
  EXPECT_EQ(solution.method(), "quadrature");
  EXPECT_EQ(solution.render().radiance.data(), render(scene, "quadrature", with(kSteps)).radiance.data());
  Camera side = scene.camera;
  side.position = Vec3(4.0, 1.0, 0.5), side.width_px = 10, side.height_px = 14;
  const RenderResult seen = solution.render(View{side});
  EXPECT_EQ(seen.radiance.width(), 10);
  scene.camera = side;
  EXPECT_EQ(seen.radiance.data(), render(scene, "quadrature", with(kSteps)).radiance.data());
  EXPECT_EQ(seen.stats["steps"], 64);  // prepare's figures come with every render
}

TEST(Solution, UpdateGivesWhatPreparingTheChangedSceneGives) {
  Scene scene = lamp_fog();
  Solution solution = prepare(scene, "quadrature", with(kSteps));
  scene.lights[1] = PointLight{Vec3(1.5, 0.0, 1.0), Rgb(1.0)};
  scene.medium->albedo = Rgb(0.5);
  const UpdateReport report = solution.update({.medium = scene.medium, .lights = scene.lights});
  EXPECT_TRUE(report.rebuilt);  // quadrature keeps nothing worth reusing
  ASSERT_FALSE(report.redone.empty());
  EXPECT_EQ(solution.scene().lights.size(), 2u);
  EXPECT_EQ(solution.render().radiance.data(), render(scene, "quadrature", with(kSteps)).radiance.data());
}

TEST(Solution, MisuseIsAClearError) {
  Scene scene = lamp_fog();
  Solution solution = prepare(scene, "quadrature", with(kSteps));
  auto field_of = [](auto f) {
    try {
      f();
    } catch (const Error& e) {
      return e.field() + ": " + e.value();
    }
    return std::string("no error");
  };
  RenderOptions settings = with({{"steps", 32}});
  EXPECT_EQ(field_of([&] { solution.render(settings); }).substr(0, 9), "settings:");
  EXPECT_EQ(field_of([&] { solution.update({.region = Aabb{Vec3(0.0), Vec3(1.0)}}); }), "change.region: given without a medium");
  EXPECT_EQ(field_of([&] { solution.fluence(Vec3(0.0)); }), "fluence: method quadrature");
  EXPECT_EQ(field_of([&] { solution.transmittance(7, Vec3(0.0)); }), "light: 7");
  // A bad change leaves the solution as it was.
  Scene bad = scene;
  bad.lights[0] = DirectionalLight{};
  EXPECT_EQ(field_of([&] { prepare(bad, "analytic"); }), "lights[0].type: a directional or sky light");
  Solution analytic = prepare(scene, "analytic");
  EXPECT_EQ(field_of([&] { analytic.update({.lights = bad.lights}); }), "lights[0].type: a directional or sky light");
  EXPECT_EQ(analytic.render().radiance.data(), render(scene, "analytic").radiance.data());
  // haze::render's solutions may leave out lights its camera cannot see, so they render no other.
  RenderOptions single;
  single.single_view = true;
  const Solution one = prepare(scene, "analytic", single);
  Camera other = scene.camera;
  other.position.x += 1.0;
  EXPECT_EQ(field_of([&] { one.render(View{other}); }), "view.camera: another camera than the scene's");
}

// A light that reaches nothing is culled; errors about the kept lights name the caller's index.
TEST(Solution, ErrorsNameTheCallersLight) {
  Scene scene = lamp_fog();
  scene.lights.insert(scene.lights.begin(), PointLight{Vec3(0.0), Rgb(0.0)});
  scene.lights.push_back(DirectionalLight{});
  try {
    prepare(scene, "analytic");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "lights[3].type");
  }
}

// Memory handed over in code is checked (a wrong size or a bad value is a haze::Error naming it,
// never a crash) and a view of it is not copied: a quadrature solution sees the caller's changes.
TEST(Solution, CallerGridsAreCheckedAndViewed) {
  Scene scene = lamp_fog();
  scene.surfaces.clear();
  auto message = [&](const GridDensity& grid) {
    scene.medium->density = grid;
    try {
      prepare(scene, "quadrature", with(kSteps));
    } catch (const Error& e) {
      return e.field() + ": " + e.value() + "; expected " + e.expected();
    }
    return std::string("no error");
  };
  EXPECT_EQ(message({{8, 8, 8}, std::vector<float>(100, 1.0f)}), "medium.density.values: 100 values; expected 512 (resolution 8 x 8 x 8)");
  std::vector<float> samples(4 * 4 * 4, 0.5f);
  samples[17] = -1.0f;
  EXPECT_EQ(message(GridDensity::viewing({4, 4, 4}, samples)), "medium.density.view[17]: -1 at cell (1, 0, 1); expected a finite density >= 0");
  samples[17] = std::nanf("");
  EXPECT_EQ(message(GridDensity::viewing({4, 4, 4}, samples)), "medium.density.view[17]: nan at cell (1, 0, 1); expected a finite density >= 0");
  EXPECT_EQ(message(GridDensity::viewing({4, 4, 0}, samples)), "medium.density.resolution[2]: 0; expected at least 1 cell");

  samples[17] = 0.5f;
  scene.medium->density = GridDensity::viewing({4, 4, 4}, samples);
  const Solution viewed = prepare(scene, "quadrature", with(kSteps));
  scene.medium->density = GridDensity{{4, 4, 4}, samples};
  EXPECT_EQ(viewed.render().radiance.data(), render(scene, "quadrature", with(kSteps)).radiance.data());
  std::fill(samples.begin(), samples.end(), 2.0f);  // the caller's simulation moves on
  scene.medium->density = GridDensity{{4, 4, 4}, samples};
  EXPECT_EQ(viewed.render().radiance.data(), render(scene, "quadrature", with(kSteps)).radiance.data());
}

}  // namespace
}  // namespace haze
