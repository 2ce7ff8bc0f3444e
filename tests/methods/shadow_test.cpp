// Surfaces shadow the medium (DESIGN.md "Surfaces are part of the transport"): a sphere between a
// spot light and a fog box leaves a shadow volume, and every method that claims shadows draws its
// radiance profile across the shadow's edge as the reference does: the single-scattering methods
// against its single scattering, the DOM against all of it.
#include <haze/core/method.h>
#include <haze/grids/methods.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace haze {
namespace {

// Fog in [-1, 1]^3 under a spot light at y = 3 (cone 25 degrees) with a sphere of radius 0.3 at
// y = 1.8 in the way: a lit cone through the box with a dark core 14.5 degrees wide.
Scene shadow_scene() {
  Scene scene;
  scene.camera.position = Vec3(0.0, 0.0, 5.0);
  scene.camera.fov_y_deg = 36.0;
  scene.camera.width_px = 48, scene.camera.height_px = 32;
  MediumDesc fog;
  fog.bounds = {Vec3(-1.0), Vec3(1.0)};
  fog.sigma_t = Rgb(0.8);
  fog.albedo = Rgb(0.8);
  scene.medium = fog;
  SpotLight spot;
  spot.position = Vec3(0.0, 3.0, 0.0), spot.direction = Vec3(0.0, -1.0, 0.0), spot.intensity = Rgb(20.0), spot.cone_deg = 25.0, spot.exponent = 0.0;
  scene.lights.push_back(spot);
  scene.surfaces.push_back(Surface{Sphere{Vec3(0.0, 1.8, 0.0), 0.3}, Rgb(0.5), Rgb(0.0), 1.0});
  return scene;
}

// Each column's mean over the rows of the box's middle (y in [-0.5, 0.5] on the image plane).
std::vector<double> profile(const Image& image) {
  std::vector<double> out(static_cast<size_t>(image.width()), 0.0);
  const int y0 = image.height() / 2 - 5, y1 = image.height() / 2 + 5;
  for (int x = 0; x < image.width(); ++x) {
    for (int y = y0; y < y1; ++y) out[static_cast<size_t>(x)] += image.at(x, y).g / (y1 - y0);
  }
  return out;
}

TEST(SurfaceShadows, ShadowVolumeProfileMatchesTheReference) {
  grids::register_methods();
  const Scene scene = shadow_scene();
  RenderOptions reference_options;
  reference_options.settings = {{"spp", 4096}, {"seed", 2}, {"max_scattering", 1}};
  const RenderResult reference = render(scene, "reference", reference_options);
  const std::vector<double> want = profile(reference.radiance), noise = profile(*reference.std_error);
  const double peak = *std::max_element(want.begin(), want.end());
  const double centre = want[want.size() / 2];
  // The shadow is there: the core is darker than the lit ring beside it.
  ASSERT_LT(centre, 0.6 * peak);
  RenderOptions full_options;
  full_options.settings = {{"spp", 4096}, {"seed", 3}};
  const RenderResult full = render(scene, "reference", full_options);
  for (const char* method : {"quadrature", "propagation", "dom"}) {
    const bool dom = std::string(method) == "dom";
    RenderOptions options;
    if (std::string(method) == "propagation") options.settings = {{"resolution", 64}, {"optical_depth", "exact"}};
    if (dom) options.settings = {{"resolution", 48}};
    const std::vector<double> expected = dom ? profile(full.radiance) : want, spread = dom ? profile(*full.std_error) : noise;
    const double top = *std::max_element(expected.begin(), expected.end());
    const std::vector<double> got = profile(render(scene, method, options).radiance);
    double worst = 0.0;
    for (size_t x = 0; x < expected.size(); ++x) {
      if (expected[x] < 0.1 * top) continue;
      // 3% of the peak, beyond three of the reference's standard errors (of a 10-row mean).
      const double allowed = 0.03 * top + 3.0 * spread[x] / std::sqrt(10.0);
      worst = std::max(worst, std::abs(got[x] - expected[x]) / top);
      EXPECT_NEAR(got[x], expected[x], allowed) << method << " column " << x;
    }
    std::printf("%s: worst column off by %.2f%% of the peak; centre %.4f (reference %.4f, peak %.4f)\n", method, 100.0 * worst,
                got[got.size() / 2], expected[expected.size() / 2], top);
  }
}

}  // namespace
}  // namespace haze
