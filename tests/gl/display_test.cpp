// The GL display against the CPU marchers on the same fields: within 1% mean relative error over
// lit pixels. Runs on llvmpipe where there is no GPU; without a context these tests fail (the
// HeadlessContext constructor throws), they do not skip.
#include <haze/core/error.h>
#include <haze/gl/context.h>
#include <haze/gl/display.h>
#include <haze/grids/dom.h>
#include <haze/grids/methods.h>
#include <haze/grids/optical_depth.h>
#include <haze/grids/propagation.h>

#include <gtest/gtest.h>

#include <cstdio>

#include "scenes/cloud_scene.h"

namespace haze::gl {
namespace {

using grids::DenseGrid;

// The grid tests' RBF cloud with every light type, a floor plane crossing the volume's bounds (lit
// through the depth volumes inside them, a DDA walk outside) and a glossy sphere beside it.
Scene full_scene(int width, int height) {
  Scene scene = grids::cloud_scene(width, height);
  scene.lights.push_back(SpotLight{Vec3(0.0, 1.6, 0.4), glm::normalize(Vec3(0.0, -1.0, -0.2)), Rgb(4.0, 3.5, 3.0), 2.0, 35.0});
  scene.lights.push_back(DirectionalLight{glm::normalize(Vec3(0.3, -0.9, -0.3)), Rgb(0.6, 0.6, 0.7)});
  scene.surfaces.push_back(Surface{Plane{Vec3(0.0, -0.45, 0.0), Vec3(0.0, 1.0, 0.0)}, Rgb(0.6, 0.55, 0.5), Rgb(0.0), 1.0});
  scene.surfaces.push_back(Surface{Sphere{Vec3(1.0, -0.1, 0.3), 0.3}, Rgb(0.3, 0.4, 0.6), Rgb(0.3), 20.0});
  scene.background = Rgb(0.02, 0.03, 0.05);
  return scene;
}

struct Fields {
  grids::ExtinctionVolume volume;
  std::vector<DenseGrid> depths;
};

Fields fields(const Scene& scene, int resolution) {
  Fields f{grids::make_extinction_volume(scene, resolution), {}};
  f.depths = grids::optical_depths(f.volume.density, scene.lights);
  return f;
}

Image cpu(const Scene& scene, const Fields& f) {
  grids::MarchSettings reference;
  reference.scalar = true;  // the float64 marcher
  return grids::march_image(scene, f.volume, f.depths, reference, {});
}

TEST(VolumeDisplay, MatchesTheCpuMarcherWithinOnePercent) {
  HeadlessContext context;
  const Scene scene = full_scene(96, 72);
  const Fields f = fields(scene, 32);
  const Image reference = cpu(scene, f);
  VolumeDisplay display(scene, f.volume, f.depths);
  const Image image = display.render(scene.camera);
  const LitPixelError e = lit_pixel_error(image, reference);
  EXPECT_GT(e.pixels, 96 * 72 / 2);
  EXPECT_LT(e.mean_abs, 0.01) << context.info().renderer;
  EXPECT_LT(std::abs(e.signed_mean), 0.002);
  // float16 textures round density and depths to 11 bits: still well under 1%.
  DisplaySettings half;
  half.format = TexelFormat::float16;
  VolumeDisplay half_display(scene, f.volume, f.depths, half);
  EXPECT_LT(lit_pixel_error(half_display.render(scene.camera), reference).mean_abs, 0.01);
}

TEST(VolumeDisplay, OrthographicCameraTabulatedPhaseAndGreyMedium) {
  HeadlessContext context;
  Scene scene = full_scene(64, 64);
  scene.camera.type = Camera::Type::orthographic;
  scene.camera.height = 2.4;
  std::vector<double> table(181);
  for (size_t i = 0; i < table.size(); ++i) table[i] = 1.0 + 0.8 * std::pow(0.5 * (1.0 + (-1.0 + 2.0 * static_cast<double>(i) / 180.0)), 4.0);
  scene.medium->phase = PhaseFunction::tabulated(table);
  scene.medium->sigma_t = Rgb(2.0);
  const Fields f = fields(scene, 24);
  VolumeDisplay display(scene, f.volume, f.depths);
  const LitPixelError e = lit_pixel_error(display.render(scene.camera), cpu(scene, f));
  EXPECT_GT(e.pixels, 64 * 64 / 2);
  EXPECT_LT(e.mean_abs, 0.01);
}

TEST(VolumeDisplay, BrickUpdatesGiveTheImageOfTheNewFields) {
  HeadlessContext context;
  const Scene scene = full_scene(64, 48);
  Fields f = fields(scene, 32);
  VolumeDisplay display(scene, f.volume, f.depths);
  const Image before = display.render(scene.camera);
  // A dense block appears in one corner: the density changes there, the depths wherever its shadow falls.
  DenseGrid& density = f.volume.density;
  std::vector<unsigned char> changed(density.cell_count(), 0);
  for (int k = 20; k < 28; ++k)
    for (int j = 20; j < 28; ++j)
      for (int i = 4; i < 12; ++i) density.at(i, j, k) += 3.0f, changed[density.index(i, j, k)] = 1;
  const std::vector<DenseGrid> depths = grids::optical_depths(density, scene.lights);
  for (size_t c = 0; c < changed.size(); ++c)
    for (size_t l = 0; l < depths.size(); ++l) changed[c] |= depths[l].values()[c] != f.depths[l].values()[c];
  f.depths = depths;
  const std::vector<Brick> bricks = changed_bricks(density.resolution(), changed, 8);
  EXPECT_LT(bricks.size(), 64u);  // not every brick
  display.update_density(density, bricks);
  display.update_depths(depths, bricks);
  const Image after = display.render(scene.camera);
  const Image reference = cpu(scene, f);
  EXPECT_LT(lit_pixel_error(after, reference).mean_abs, 0.01);
  EXPECT_GT(lit_pixel_error(before, reference).mean_abs, 0.05);  // the change is visible
  // The same as a display built from the new fields.
  VolumeDisplay fresh(scene, f.volume, f.depths);
  EXPECT_EQ(after.data(), fresh.render(scene.camera).data());
}

TEST(VolumeDisplay, AddsTheDomMultipleScatteringTermWithinOnePercent) {
  HeadlessContext context;
  const Scene scene = grids::lit_cloud(true, 64, 48);
  const Fields f = fields(scene, 24);
  grids::DomSettings settings;
  settings.directions = 48;
  settings.terms = 16;
  const grids::DomSolution solution = grids::solve_dom(f.volume, scene.lights, f.depths, settings);
  const Image reference = grids::render_dom(scene, f.volume, f.depths, solution, 0.5, {}, View{scene.camera}).radiance;
  VolumeDisplay display(scene, f.volume, f.depths);
  const Image single = display.render(scene.camera);
  display.show_dom(solution);
  const LitPixelError e = lit_pixel_error(display.render(scene.camera), reference);
  EXPECT_GT(e.pixels, 64 * 48 / 3);
  EXPECT_LT(e.mean_abs, 0.01);
  EXPECT_GT(lit_pixel_error(single, reference).mean_abs, 0.1);  // the multiple-scattering term matters here
}

// Any grid method's solution displays as it is (no method name): the DOM's through its moments,
// within 1% of the solution's own CPU render.
TEST(VolumeDisplay, ShowsAnyGridSolution) {
  grids::register_methods();
  HeadlessContext context;
  const Scene scene = grids::lit_cloud(true, 64, 48);
  RenderOptions options;
  options.settings = {{"resolution", 24}, {"directions", 48}, {"terms", 16}};
  const Solution solution = prepare(scene, "dom", options);
  const auto* grid = dynamic_cast<const grids::GridSolution*>(&solution.method_solution());
  ASSERT_NE(grid, nullptr);
  VolumeDisplay display(*grid);
  const LitPixelError e = lit_pixel_error(display.render(scene.camera), solution.render().radiance);
  EXPECT_GT(e.pixels, 64 * 48 / 3);
  EXPECT_LT(e.mean_abs, 0.01);
  EXPECT_EQ(dynamic_cast<const grids::GridSolution*>(&prepare(scene, "reference").method_solution()), nullptr);
}

// With surfaces, the DOM's scattered light on them from its surface texels (method setting
// surface_view "texels", what the display shows): within 1% of the CPU render, and without that
// light (surface_passes 0 and no texels shown) the floor and sphere are far darker.
TEST(VolumeDisplay, ShowsTheDomSurfaceLightWithinOnePercent) {
  grids::register_methods();
  HeadlessContext context;
  const Scene scene = full_scene(64, 48);
  RenderOptions options;
  options.settings = {{"resolution", 24}, {"directions", 48}, {"terms", 16}, {"surface_view", "texels"}};
  const Solution solution = prepare(scene, "dom", options);
  const auto& grid = dynamic_cast<const grids::GridSolution&>(solution.method_solution());
  ASSERT_NE(grid.dom()->surfaces, nullptr);
  VolumeDisplay display(grid);
  const Image shown = display.render(scene.camera), cpu_image = solution.render().radiance;
  const LitPixelError e = lit_pixel_error(shown, cpu_image);
  std::printf("dom with surface texels, %d lit pixels: GL against CPU %.3f%% mean |relative|\n", e.pixels, 100.0 * e.mean_abs);
  EXPECT_GT(e.pixels, 64 * 48 / 3);
  EXPECT_LT(e.mean_abs, 0.01);
  grids::DomSolution without = *grid.dom();
  without.surfaces.reset();
  VolumeDisplay bare(scene, grid.volume(), grid.depths(), DisplaySettings{grid.step_cells()});
  bare.show_dom(without);
  EXPECT_GT(lit_pixel_error(bare.render(scene.camera), cpu_image).mean_abs, 0.03);
}

// Emission: a uniformly emitting, non-scattering box has L_e (1 - e^-tau) / sigma_t along each ray
// (to float rounding); an emitting, scattering, lit cloud (emission following the density plus a
// uniform blackbody glow, the texture's part) with the DOM shown within 1% of the CPU render.
TEST(VolumeDisplay, RendersEmission) {
  grids::register_methods();
  HeadlessContext context;
  Scene box = grids::lit_cloud(true, 48, 36);
  box.lights.clear();
  MediumDesc& m = *box.medium;
  m.density = ConstantDensity{1.0};
  m.bounds = Aabb{Vec3(-0.6, -0.5, -0.4), Vec3(0.6, 0.5, 0.4)};
  m.sigma_t = Rgb(1.0, 2.0, 0.5), m.albedo = Rgb(0.0);
  m.emission.strength = 2.0, m.emission.color = Rgb(1.0, 0.5, 0.25);
  const Fields f = fields(box, 16);
  const Image image = VolumeDisplay(box, f.volume, f.depths).render(box.camera);
  int inside = 0;
  for (int y = 0; y < 36; ++y)
    for (int x = 0; x < 48; ++x) {
      const Ray ray = box.camera.pixel_ray(x, y);
      double t0 = 0.0, t1 = kInfinity;
      const bool hits = m.bounds.clip(ray, t0, t1);
      const Rgb expected = hits ? 2.0 * Rgb(1.0, 0.5, 0.25) * (Rgb(1.0) - glm::exp(-m.sigma_t * (t1 - t0))) / m.sigma_t : box.background;
      inside += hits;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(image.at(x, y)[c], expected[c], 1e-4 + 1e-4 * expected[c]) << x << "," << y;
    }
  EXPECT_GT(inside, 300);

  Scene cloud = grids::lit_cloud(true, 64, 48);
  cloud.medium->emission.strength = 1.0, cloud.medium->emission.color = Rgb(1.0, 0.7, 0.4);
  cloud.medium->emission.blackbody_intensity = 2.0, cloud.medium->emission.temperature = 1200.0;
  RenderOptions options;
  options.settings = {{"resolution", 24}, {"directions", 48}, {"terms", 16}};
  const Solution solution = prepare(cloud, "dom", options);
  const auto& grid = dynamic_cast<const grids::GridSolution&>(solution.method_solution());
  const Image cpu_image = solution.render().radiance;
  const LitPixelError e = lit_pixel_error(VolumeDisplay(grid).render(cloud.camera), cpu_image);
  std::printf("emitting cloud with the dom: GL against CPU %.3f%% mean |relative| over %d lit pixels\n", 100.0 * e.mean_abs, e.pixels);
  EXPECT_GT(e.pixels, 64 * 48 / 3);
  EXPECT_LT(e.mean_abs, 0.01);
  // The glow is a good part of the picture: without emission it differs by far more.
  Scene dark = cloud;
  dark.medium->emission = {};
  EXPECT_GT(lit_pixel_error(solution.render().radiance, prepare(dark, "dom", options).render().radiance).mean_abs, 0.1);
}

TEST(VolumeDisplay, RefusesMismatchedFields) {
  HeadlessContext context;
  const Scene scene = full_scene(16, 16);
  const Fields f = fields(scene, 16);
  std::vector<DenseGrid> one(f.depths.begin(), f.depths.begin() + 1);
  try {
    VolumeDisplay display(scene, f.volume, one);
    FAIL() << "accepted one depth volume for four lights";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "depths");
  }
  VolumeDisplay display(scene, f.volume, f.depths);
  const DenseGrid coarse({8, 8, 8}, f.volume.density.bounds());
  try {
    display.update_density(coarse);
    FAIL() << "accepted an 8^3 density for a 16^3 display";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "density");
  }
}

}  // namespace
}  // namespace haze::gl
