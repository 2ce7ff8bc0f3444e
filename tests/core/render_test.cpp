// The method registry and core's "quadrature" method, checked against closed forms.
#include <haze/core/error.h>
#include <haze/core/method.h>

#include <gtest/gtest.h>

namespace haze {
namespace {

// One orthographic pixel looking down +z from the origin, through an unbounded medium, stopped by a
// black plane at z = d_vp.
Scene single_ray_scene(double sigma_t, double albedo, double d_vp) {
  Scene scene;
  scene.camera.type = Camera::Type::orthographic;
  scene.camera.position = Vec3(0);
  scene.camera.look_at = Vec3(0, 0, 1);
  scene.camera.height = 1e-9;
  scene.camera.width_px = scene.camera.height_px = 1;
  MediumDesc medium;
  medium.sigma_t = Rgb(sigma_t);
  medium.albedo = Rgb(albedo);
  scene.medium = medium;
  scene.surfaces.push_back({Plane{Vec3(0, 0, d_vp), Vec3(0, 0, -1)}, Rgb(0.0), Rgb(0.0), 1.0});
  return scene;
}

// BEYOND.md: Sun et al. 2005 closed form, 0.0132328536 for sigma_t = 0.5, albedo 1, I = 1,
// d_sv = 2, gamma = 0.7, d_vp = 5.
TEST(Quadrature, MatchesSunEtAlAirlight) {
  Scene scene = single_ray_scene(0.5, 1.0, 5.0);
  scene.lights.push_back(PointLight{Vec3(2.0 * std::sin(0.7), 0.0, 2.0 * std::cos(0.7)), Rgb(1.0)});
  auto result = render(scene, "quadrature");
  EXPECT_NEAR(result.radiance.at(0, 0).r, 0.0132328536, 1e-9);
}

// Seed 004 / BEYOND.md: without extinction, L = sigma_s I / (4 pi h) [atan((t1 - tc)/h) - atan((t0 - tc)/h)].
TEST(Quadrature, MatchesNoExtinctionClosedForm) {
  const double sigma = 1e-7, h = 0.3, tc = 1.2, t1 = 4.0;
  Scene scene = single_ray_scene(sigma, 1.0, t1);
  scene.lights.push_back(PointLight{Vec3(h, 0.0, tc), Rgb(2.0)});
  double expected = sigma * 2.0 / (4.0 * kPi * h) * (std::atan((t1 - tc) / h) - std::atan((0.0 - tc) / h));
  auto result = render(scene, "quadrature");
  EXPECT_NEAR(result.radiance.at(0, 0).g / expected, 1.0, 1e-5);
}

Scene small_scene() {
  Scene scene;
  scene.camera.position = Vec3(0, 0, 4);
  scene.camera.width_px = 12, scene.camera.height_px = 9;
  MediumDesc medium;
  medium.bounds = {Vec3(-1), Vec3(1)};
  medium.density = RbfDensity{{RbfBlob{Vec3(0.2, 0, 0), 2.0, 1.5}, RbfBlob{Vec3(-0.3, 0.2, 0.1), 1.0, 3.0}}};
  medium.sigma_t = Rgb(1.0, 1.5, 2.0);
  medium.albedo = Rgb(0.9);
  medium.phase = PhaseFunction::henyey_greenstein(0.4);
  scene.medium = medium;
  scene.lights.push_back(PointLight{Vec3(1.5, 1.5, 1.0), Rgb(5.0)});
  scene.lights.push_back(SkyLight{Rgb(0.1, 0.2, 0.3)});
  scene.surfaces.push_back({Plane{Vec3(0, -1, 0), Vec3(0, 1, 0)}, Rgb(0.5), Rgb(0.2), 20.0});
  scene.method = {{"name", "quadrature"}, {"steps", 64}, {"sky_directions", 32}};
  return scene;
}

TEST(Quadrature, ResultsDoNotDependOnThreadCount) {
  Scene scene = small_scene();
  RenderOptions one, two;
  one.threads = 1;
  two.threads = 2;
  auto a = render(scene, "", one), b = render(scene, "", two);
  EXPECT_EQ(a.radiance.data(), b.radiance.data());
  EXPECT_GT(a.radiance.mean().r, 0.0);
  EXPECT_EQ(a.stats["steps"], 64);  // the scene's settings applied
}

TEST(Methods, UnknownNamesAndSettingsAreClearErrors) {
  Scene scene = small_scene();
  try {
    render(scene, "no_such_method");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "method.name");
    EXPECT_NE(std::string(e.what()).find("quadrature"), std::string::npos) << e.what();
  }
  RenderOptions bad;
  bad.settings = {{"stepz", 3}};
  try {
    render(scene, "quadrature", bad);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "method.stepz");
  }
  bad.settings = {{"steps", -3}};
  EXPECT_THROW(render(scene, "quadrature", bad), Error);
  scene.method = nlohmann::json::object();
  EXPECT_THROW(render(scene, ""), Error);
}

TEST(Methods, ProgressReachesOneAndCancellationStops) {
  Scene scene = small_scene();
  RenderOptions options;
  double last = 0.0;
  options.progress = [&](double f) {
    EXPECT_GE(f, last);
    last = f;
    return true;
  };
  render(scene, "", options);
  EXPECT_DOUBLE_EQ(last, 1.0);
  options.progress = [](double) { return false; };
  EXPECT_THROW(render(scene, "", options), Cancelled);
}

}  // namespace
}  // namespace haze

namespace haze {
namespace {

Scene analytic_scene() {
  Scene scene;
  scene.camera.position = Vec3(0, 1.5, 6);
  scene.camera.look_at = Vec3(0, 1, 0);
  scene.camera.width_px = 24, scene.camera.height_px = 16;
  MediumDesc m;
  m.sigma_t = Rgb(0.25, 0.3, 0.35);
  m.albedo = Rgb(0.9);
  m.phase = PhaseFunction::henyey_greenstein(0.5);
  scene.medium = m;
  scene.lights.push_back(PointLight{Vec3(-0.6, 1.6, 0.4), Rgb(12, 10, 7)});
  scene.lights.push_back(PointLight{Vec3(1.5, 0.8, -1.0), Rgb(3, 5, 9)});
  scene.surfaces.push_back({Plane{Vec3(0), Vec3(0, 1, 0)}, Rgb(0.6), Rgb(0.2), 10.0});
  return scene;
}

// The analytic method against quadrature where both model the same light: airlight from point
// lights and unshadowed direct surface light (no surface blocks a light here).
TEST(Analytic, MatchesQuadratureOnUnboundedAndBoundedFog) {
  for (bool bounded : {false, true}) {
    Scene scene = analytic_scene();
    if (bounded) scene.medium->bounds = {Vec3(-3, 0, -3), Vec3(3, 3, 3)};
    RenderOptions quad;
    quad.settings = {{"steps", 4096}};
    auto exact = render(scene, "quadrature", quad);
    RenderOptions no_surface_airlight;
    no_surface_airlight.settings = {{"surface_airlight", 0}};  // quadrature lights surfaces directly only
    auto fast = render(scene, "analytic", no_surface_airlight);
    EXPECT_LT(relative_rmse(fast.radiance, exact.radiance), 5e-4) << "bounded " << bounded;
    // Airlight onto the surfaces only adds light.
    auto full = render(scene, "analytic");
    EXPECT_GT(full.radiance.mean().r, fast.radiance.mean().r);
  }
}

// Spot lights (I0 cos^n inside the cone) against quadrature: issue 4 asks for 1%; both cut the
// view ray at the cone's crossings and agree to about 1e-7.
TEST(Analytic, SpotLightsMatchQuadrature) {
  Scene scene = analytic_scene();
  scene.lights = {SpotLight{Vec3(-1.0, 2.5, 0.0), glm::normalize(Vec3(0.3, -1.0, 0.1)), Rgb(20, 15, 10), 3.0, 25.0},
                  SpotLight{Vec3(1.2, 0.6, 1.0), glm::normalize(Vec3(-1.0, 0.2, -0.3)), Rgb(4, 6, 12), 1.0, 60.0}};
  auto exact = render(scene, "quadrature");
  RenderOptions options;
  options.settings = {{"surface_airlight", 0}};
  auto fast = render(scene, "analytic", options);
  double rel = relative_rmse(fast.radiance, exact.radiance);
  std::printf("spot lights: analytic against quadrature, relative RMSE %.2e\n", rel);
  EXPECT_LT(rel, 1e-3);
}

// Issue 4: surface radiance (direct light plus airlight scattered onto the surface, seen through
// the medium) against the reference restricted to the same light paths (one medium scattering,
// one surface reflection, no scattering on the camera ray), on a plane and a Phong sphere lit by 4
// lights placed near the camera so shadows fall out of view. Within 2%: the image means, and the
// per-pixel difference once the reference's own noise is taken out.
TEST(Analytic, SurfaceRadianceMatchesReference) {
  Scene scene;
  scene.camera.position = Vec3(0, 1.5, 6);
  scene.camera.look_at = Vec3(0, 0.6, 0);
  scene.camera.width_px = 24, scene.camera.height_px = 16;
  MediumDesc m;
  m.sigma_t = Rgb(0.2, 0.25, 0.3);
  m.albedo = Rgb(0.9);
  m.phase = PhaseFunction::henyey_greenstein(0.5);
  scene.medium = m;
  scene.lights = {PointLight{Vec3(-0.8, 2.2, 5.0), Rgb(12, 10, 7)}, PointLight{Vec3(0.9, 1.9, 5.2), Rgb(3, 5, 9)},
                  PointLight{Vec3(0.2, 2.6, 4.6), Rgb(6, 6, 6)}, PointLight{Vec3(-0.1, 1.2, 5.5), Rgb(2, 2, 3)}};
  scene.surfaces = {{Plane{Vec3(0), Vec3(0, 1, 0)}, Rgb(0.6), Rgb(0.0), 1.0},
                    {Sphere{Vec3(0.3, 0.7, 0.0), 0.7}, Rgb(0.6, 0.3, 0.2), Rgb(0.3), 20.0}};
  RenderOptions analytic;
  analytic.settings = {{"airlight", 0}};
  auto fast = render(scene, "analytic", analytic);
  RenderOptions reference;
  reference.settings = {{"spp", 1 << 14}, {"max_scattering", 1}, {"max_bounces", 1}, {"view_scattering", 0}};
  auto ref = render(scene, "reference", reference);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(fast.radiance.mean()[c] / ref.radiance.mean()[c], 1.0, 0.02) << c;
  double error = rmse(fast.radiance, ref.radiance), noise = rms(*ref.std_error);
  double bias = std::sqrt(std::max(0.0, error * error - noise * noise)) / rms(ref.radiance);
  std::printf("surface radiance: means %.4f %.4f %.4f (analytic / reference), relative RMSE %.4f, reference noise %.4f, "
              "relative bias after noise %.4f\n",
              fast.radiance.mean().r / ref.radiance.mean().r, fast.radiance.mean().g / ref.radiance.mean().g,
              fast.radiance.mean().b / ref.radiance.mean().b, error / rms(ref.radiance), noise / rms(ref.radiance), bias);
  EXPECT_LT(bias, 0.02);
}

// A grey medium takes the one-evaluation-per-light path; it must agree with the per-channel one.
TEST(Analytic, GreyShortcutMatchesPerChannelPath) {
  Scene scene = analytic_scene();
  scene.medium->sigma_t = Rgb(0.3);
  scene.surfaces.push_back({Sphere{Vec3(0.4, 0.6, 0.8), 0.6}, Rgb(0.6, 0.25, 0.0), Rgb(0.4), 24.0});
  auto grey = render(scene, "analytic");
  scene.medium->sigma_t = Rgb(0.3, 0.3, 0.3 * (1.0 + 1e-12));  // not grey: per-channel path
  auto per_channel = render(scene, "analytic");
  EXPECT_LT(relative_rmse(grey.radiance, per_channel.radiance), 1e-6);
}

// Dynamic g: Legendre tables summed for the scene's g stay within the requested tolerance of the
// exact-phase table, and report the orders used and their bound.
TEST(Analytic, DynamicGStaysWithinItsTolerance) {
  Scene scene = analytic_scene();
  scene.medium->phase = PhaseFunction::henyey_greenstein(0.3);
  scene.surfaces[0].ks = Rgb(0.0);  // per-order Phong tables take tens of seconds to build
  RenderOptions exact, dynamic;
  exact.settings = {{"table_a", 128}, {"table_eta", 256}};
  dynamic.settings = {{"table_a", 128}, {"table_eta", 256}, {"dynamic_g_tolerance", 1e-2}};
  auto a = render(scene, "analytic", exact), b = render(scene, "analytic", dynamic);
  double rel = relative_rmse(b.radiance, a.radiance);
  std::printf("dynamic g: %d Legendre orders (bound %.1e), relative RMSE against the exact-phase table %.1e\n",
              b.stats["legendre_terms"].get<int>(), b.stats["truncation_bound"].get<double>(), rel);
  EXPECT_GT(b.stats["legendre_terms"].get<int>(), 3);
  EXPECT_LE(b.stats["truncation_bound"].get<double>(), 1e-2);
  EXPECT_LT(rel, 1e-2);
  scene.medium->phase = PhaseFunction::rayleigh();
  EXPECT_THROW(render(scene, "analytic", dynamic), Error);
}

// A solution keeps its method's tables: a new g on the next frame (an update that prepares again)
// reuses the Legendre tables and gives exactly what a fresh solution computes.
TEST(Analytic, UpdatedSolutionKeepsTablesAcrossFrames) {
  Scene scene = analytic_scene();
  scene.medium->phase = PhaseFunction::henyey_greenstein(0.3);
  scene.surfaces[0].ks = Rgb(0.0);
  RenderOptions options;
  options.settings = {{"table_a", 64}, {"table_eta", 128}, {"dynamic_g_tolerance", 1e-2}};
  Solution solution = prepare(scene, "analytic", options);
  EXPECT_FALSE(solution.stats()["tables_reused"].get<bool>());
  scene.medium->phase = PhaseFunction::henyey_greenstein(0.35);
  const UpdateReport report = solution.update({.medium = scene.medium});
  EXPECT_TRUE(report.rebuilt);
  EXPECT_TRUE(solution.stats()["tables_reused"].get<bool>());
  EXPECT_EQ(solution.render().radiance.data(), render(scene, "analytic", options).radiance.data());
}

TEST(Analytic, RejectsWhatItDoesNotModel) {
  Scene scene = analytic_scene();
  scene.lights.push_back(DirectionalLight{});
  try {
    render(scene, "analytic");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "lights[2].type");
  }
  scene = analytic_scene();
  scene.medium->density = RbfDensity{{RbfBlob{}}};
  EXPECT_THROW(render(scene, "analytic"), Error);
  scene.medium.reset();
  EXPECT_THROW(render(scene, "analytic"), Error);
}

}  // namespace
}  // namespace haze
