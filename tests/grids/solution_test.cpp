// The grid methods' solutions: updates redo only what a change reaches and give what preparing the
// changed scene gives; the DOM's warm start advances; the fields agree with their definitions.
#include <haze/core/error.h>
#include <haze/core/majorant.h>
#include <haze/core/method.h>
#include <haze/core/rng.h>
#include <haze/grids/optical_depth.h>
#include <haze/grids/propagation.h>
#include <haze/grids/methods.h>

#include "scenes/cloud_scene.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace haze::grids {
namespace {

RenderOptions with(const nlohmann::json& settings) {
  RenderOptions options;
  options.settings = settings;
  return options;
}

double relative_difference(const Image& a, const Image& b) {
  double diff = 0.0, sum = 0.0;
  for (size_t i = 0; i < a.data().size(); ++i) {
    diff += std::abs(static_cast<double>(a.data()[i]) - static_cast<double>(b.data()[i]));
    sum += std::abs(static_cast<double>(b.data()[i]));
  }
  return diff / sum;
}

// The cloud with its first blob moved by dx, and the region that move touched.
std::pair<MediumDesc, Aabb> moved(const MediumDesc& medium, double dx) {
  MediumDesc next = medium;
  RbfBlob& blob = std::get<RbfDensity>(next.density).blobs[0];
  const RbfBlob before = blob;
  blob.center.x += dx;
  const double r = 6.1 / blob.sharpness;  // beyond it the blob is under e^-37 of its weight
  Aabb region{glm::min(before.center, blob.center) - r, glm::max(before.center, blob.center) + r};
  return {next, region};
}

TEST(PropagationSolution, UpdatesRedoOnlyWhatChangedAndMatchAFreshSolution) {
  register_methods();
  Scene scene = cloud_scene(20, 14);
  scene.medium->bounds = {Vec3(-1.0), Vec3(1.0)};
  const RenderOptions options = with({{"resolution", 24}});
  Solution solution = prepare(scene, "propagation", options);
  scene.lights[1] = PointLight{Vec3(-2.0, 0.5, 1.0), Rgb(3.0)};
  UpdateReport report = solution.update({.lights = scene.lights});
  EXPECT_FALSE(report.rebuilt);
  EXPECT_EQ(report.redone, std::vector<std::string>{"optical depth of lights[1]"});
  EXPECT_EQ(solution.render().radiance.data(), render(scene, "propagation", options).radiance.data());

  const auto [medium, region] = moved(*scene.medium, 0.15);
  scene.medium = medium;
  report = solution.update({.medium = medium, .region = region});
  ASSERT_EQ(report.redone.size(), 3u);
  EXPECT_NE(report.redone[0].find("cells re-injected"), std::string::npos) << report.redone[0];
  EXPECT_EQ(solution.render().radiance.data(), render(scene, "propagation", options).radiance.data());
}

// Before the fix, GMRES with a budget of one sweep after the first-collision one returned the
// warm moments unchanged. Now an update with warm_iterations is a source iteration (one sweep
// with the first-collision source in it, which sets the diamond's fix-up marks): over frames of the moved cloud the residual and the image's
// distance to a cold solve fall, and an update to the tolerance gives the cold image within it.
TEST(DomSolution, WarmStartAdvancesTowardTheNewSolution) {
  register_methods();
  Scene scene = lit_cloud(true, 12, 10);
  scene.medium->bounds = {Vec3(-1.0), Vec3(1.0)};
  const nlohmann::json settings = {{"resolution", 20}, {"directions", 32}, {"terms", 9}};
  nlohmann::json warm = settings;
  warm["warm_iterations"] = 1;
  Solution solution = prepare(scene, "dom", with(warm));
  const auto [medium, region] = moved(*scene.medium, -0.3);
  scene.medium = medium;
  const Image cold = render(scene, "dom", with(settings)).radiance;
  double gap = 1.0, residual = 1.0;
  for (int frame = 0; frame < 3; ++frame) {
    const UpdateReport report = solution.update(frame == 0 ? SceneChange{.medium = medium, .region = region} : SceneChange{.lights = scene.lights});
    EXPECT_FALSE(report.rebuilt);
    EXPECT_EQ(report.stats["iterations"], 3);  // per channel one sweep, the first-collision source in it
    const double next_gap = relative_difference(solution.render().radiance, cold);
    EXPECT_LT(next_gap, gap) << "frame " << frame;
    EXPECT_LT(report.stats["final_change"].get<double>(), residual) << "frame " << frame;
    gap = next_gap, residual = report.stats["final_change"].get<double>();
  }
  EXPECT_LT(gap, 2e-3);
  Solution full = prepare(scene, "dom", with(settings));
  const auto [again, region2] = moved(*scene.medium, 0.2);
  scene.medium = again;
  const UpdateReport report = full.update({.medium = again, .region = region2});
  EXPECT_TRUE(report.stats["converged"].get<bool>());
  EXPECT_LT(relative_difference(full.render().radiance, render(scene, "dom", with(settings)).radiance), 2e-3);
}

// A moving cloud, one warm sweep per update for several frames (a simulation's frames): with the
// diffusion correction (dsa, the default) the image keeps far closer to a cold solve's than
// without it (examples/sim at 48^3: 2.0% against 13% after 8 frames, docs/SIMULATIONS.md).
TEST(DomSolution, DiffusionAccelerationKeepsWarmFramesClose) {
  register_methods();
  double lag[2] = {0.0, 0.0};
  for (int dsa = 0; dsa < 2; ++dsa) {
    Scene scene = lit_cloud(true, 12, 10);
    scene.medium->bounds = {Vec3(-1.0), Vec3(1.0)};
    scene.medium->albedo = Rgb(0.95), scene.medium->sigma_t *= 4.0;
    const nlohmann::json settings = {{"resolution", 20}, {"directions", 32}, {"terms", 9}, {"dsa", dsa}};
    nlohmann::json warm = settings;
    warm["warm_iterations"] = 1;
    Solution solution = prepare(scene, "dom", with(warm));
    for (int frame = 0; frame < 4; ++frame) {
      const auto [medium, region] = moved(*scene.medium, 0.08);
      scene.medium = medium;
      solution.update({.medium = medium, .region = region});
    }
    lag[dsa] = relative_difference(solution.render().radiance, render(scene, "dom", with(settings)).radiance);
  }
  std::printf("after 4 frames of one warm sweep: lag %.4f without dsa, %.4f with\n", lag[0], lag[1]);
  EXPECT_LT(2.0 * lag[1], lag[0]);
}

// Surfaces shadow the first-collision source: a sphere added by an update between the sun and
// the cloud's centre lowers the fluence there, and the updated solution renders what preparing
// the scene with the sphere renders (to the GMRES tolerance; without solving again it would keep
// the unshadowed moments).
TEST(DomSolution, NewSurfacesShadowTheSolvedLight) {
  register_methods();
  Scene scene = lit_cloud(true, 12, 10);
  scene.medium->bounds = {Vec3(-1.0), Vec3(1.0)};
  const nlohmann::json settings = {{"resolution", 20}, {"directions", 32}, {"terms", 9}};
  Solution solution = prepare(scene, "dom", with(settings));
  const Rgb before = solution.fluence(Vec3(0.0));
  const Vec3 to_sun = -std::get<DirectionalLight>(scene.lights[1]).direction;
  scene.surfaces = {Surface{Sphere{1.2 * to_sun, 0.5}, Rgb(0.5), Rgb(0.0), 1.0}};
  const UpdateReport report = solution.update({.surfaces = scene.surfaces});
  EXPECT_FALSE(report.rebuilt);
  EXPECT_LT(solution.fluence(Vec3(0.0)).g, 0.9 * before.g);
  EXPECT_LT(relative_difference(solution.render().radiance, render(scene, "dom", with(settings)).radiance), 2e-3);
}

// With an isotropic phase (no delta-M), S(x, w) = phi(x) / (4 pi) for every w: the two fields
// take different paths (the direction weights against the phase matrix's rows).
TEST(DomSolution, FluenceAndInscatteredAgreeForAnIsotropicPhase) {
  register_methods();
  Scene scene = lit_cloud(false, 8, 8);
  scene.medium->phase = PhaseFunction::isotropic();
  const Solution solution = prepare(scene, "dom", with({{"resolution", 16}, {"directions", 64}}));
  for (const Vec3& x : {Vec3(0.0), Vec3(0.3, -0.2, 0.1), Vec3(-0.5, 0.4, -0.4)}) {
    const Rgb phi = solution.fluence(x);
    for (const Vec3& w : {Vec3(0, 0, 1), glm::normalize(Vec3(1, -1, 0.5))}) {
      const Rgb s = solution.inscattered(x, w);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(s[c], phi[c] / (4.0 * kPi), 1e-4 * phi[c]) << c;
    }
  }
}

// The transmittance field against the exact integral through the RBF density (core's medium),
// inside the grid and from outside it.
TEST(GridSolution, TransmittanceMatchesTheMedium) {
  register_methods();
  Scene scene = cloud_scene(8, 8);
  scene.medium->bounds = {Vec3(-1.0), Vec3(1.0)};
  const Solution solution = prepare(scene, "propagation", with({{"resolution", 48}, {"optical_depth", "exact"}}));
  const auto medium = make_medium(*scene.medium);
  const Vec3 light = std::get<PointLight>(scene.lights[0]).position;
  for (const Vec3& x : {Vec3(0.0), Vec3(-0.4, -0.3, 0.2), Vec3(-0.6, 0.2, 1.5)}) {
    const Rgb exact = medium->transmittance(x, light);
    const Rgb field = solution.transmittance(0, x);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(field[c], exact[c], 0.01) << x.x << " " << c;
  }
  EXPECT_THROW(solution.transmittance(2, Vec3(0.0)), Error);
}

// The grid methods' volume as a haze::Medium: its density is the marchers' trilinear lookup, its
// majorant segments bound it, and its line integral converges to the volume's depth (the DDA's
// cell-constant integral) as both resolve the same smooth density.
TEST(ExtinctionVolume, IsAMediumOnItsOwnCells) {
  Scene scene = cloud_scene(8, 8);
  scene.medium->bounds = {Vec3(-1.0), Vec3(1.0)};
  const ExtinctionVolume volume = make_extinction_volume(scene, 64);
  const auto medium = make_medium(volume.medium());
  EXPECT_EQ(medium->bounds().lo, volume.density.bounds().lo);
  Rng rng(3);
  for (int i = 0; i < 200; ++i) {
    const Vec3 x(2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
    ASSERT_NEAR(medium->density(x), static_cast<double>(sample_trilinear(volume.density, x)), 1e-6 * (1.0 + medium->density(x)));
  }
  const Ray ray{Vec3(-1.5, -0.2, 0.1), glm::normalize(Vec3(1.0, 0.3, -0.1))};
  auto walk = medium->majorants().walk(ray, 0.0, 4.0);
  MajorantSegment seg;
  while (walk.next(seg))
    for (double f : {0.1, 0.5, 0.9}) EXPECT_LE(medium->density(ray.at(seg.t0 + f * (seg.t1 - seg.t0))), seg.density);
  const double dda = density_integral_dda(volume.density, ray.origin, ray.at(4.0));
  EXPECT_NEAR(medium->density_integral(ray.origin, ray.at(4.0)), dda, 0.01 * dda);
}

}  // namespace
}  // namespace haze::grids
