// Surfaces in the transport (DESIGN.md "Surfaces are part of the transport"): a sphere between a
// spot light and a fog box leaves a shadow volume, and every method that claims shadows draws its
// radiance profile across the shadow's edge as the reference does (the single-scattering methods
// against its single scattering, the DOM against all of it); a floor under a cloud receives the
// light the cloud scatters onto it in the DOM as in the reference.
#include <haze/core/image.h>
#include <haze/core/method.h>
#include <haze/grids/methods.h>

#include "scenes/cloud_scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace haze {
namespace {

// Fog in [-1, 1]^3 under a spot light at y = 3 (cone 25 degrees) with a sphere of radius 0.3 at
// y = 1.8 in the way: a lit cone through the box with a dark core 14.5 degrees wide. `tall`: the
// fog reaches up to y = 3.2, past the light (the analytic method assumes its lights inside it).
Scene shadow_scene(bool tall = false) {
  Scene scene;
  scene.camera.position = Vec3(0.0, 0.0, 5.0);
  scene.camera.fov_y_deg = 36.0;
  scene.camera.width_px = 48, scene.camera.height_px = 32;
  MediumDesc fog;
  fog.bounds = {Vec3(-1.0), Vec3(1.0, tall ? 3.2 : 1.0, 1.0)};
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

// The worst column of `method` against the reference's profile, within 3% of its peak beyond three
// of its standard errors (of a 10-row mean).
void expect_profile(const Scene& scene, const char* method, const RenderOptions& options, const RenderResult& reference) {
  const std::vector<double> expected = profile(reference.radiance), spread = profile(*reference.std_error);
  const double top = *std::max_element(expected.begin(), expected.end());
  const std::vector<double> got = profile(render(scene, method, options).radiance);
  double worst = 0.0;
  for (size_t x = 0; x < expected.size(); ++x) {
    if (expected[x] < 0.1 * top) continue;
    const double allowed = 0.03 * top + 3.0 * spread[x] / std::sqrt(10.0);
    worst = std::max(worst, std::abs(got[x] - expected[x]) / top);
    EXPECT_NEAR(got[x], expected[x], allowed) << method << " column " << x;
  }
  std::printf("%s: worst column off by %.2f%% of the peak; centre %.4f (reference %.4f, peak %.4f)\n", method, 100.0 * worst,
              got[got.size() / 2], expected[expected.size() / 2], top);
}

TEST(SurfaceShadows, ShadowVolumeProfileMatchesTheReference) {
  grids::register_methods();
  const Scene scene = shadow_scene();
  RenderOptions single;
  single.settings = {{"spp", 4096}, {"seed", 2}, {"max_scattering", 1}};
  const RenderResult reference = render(scene, "reference", single);
  const std::vector<double> want = profile(reference.radiance);
  // The shadow is there: the core is darker than the lit ring beside it.
  ASSERT_LT(want[want.size() / 2], 0.6 * *std::max_element(want.begin(), want.end()));
  RenderOptions full_options;
  full_options.settings = {{"spp", 4096}, {"seed", 3}};
  const RenderResult full = render(scene, "reference", full_options);
  expect_profile(scene, "quadrature", {}, reference);
  RenderOptions propagation;
  propagation.settings = {{"resolution", 64}, {"optical_depth", "exact"}};
  expect_profile(scene, "propagation", propagation, reference);
  RenderOptions dom;
  dom.settings = {{"resolution", 48}};
  expect_profile(scene, "dom", dom, full);  // multiple scattering: against all of the light
  // The analytic method on the tall box, which holds its light.
  const Scene tall = shadow_scene(true);
  expect_profile(tall, "analytic", {}, render(tall, "reference", single));
}

// The floor-under-a-cloud scene, and its floor pixels whose point lies in the cloud's footprint
// (its shadow), seen past the cloud.
Scene floor_scene(MediumDesc& cloud) {
  Scene scene;
  scene.camera.position = Vec3(0.0, 1.6, 4.0), scene.camera.look_at = Vec3(0.0, -0.3, 0.0);
  scene.camera.width_px = 48, scene.camera.height_px = 36;
  cloud.bounds = {Vec3(-0.6, 0.1, -0.6), Vec3(0.6, 0.7, 0.6)};
  cloud.sigma_t = Rgb(4.0), cloud.albedo = Rgb(0.95), cloud.phase = PhaseFunction::henyey_greenstein(0.3);
  scene.medium = cloud;
  scene.lights.push_back(DirectionalLight{Vec3(0.0, -1.0, 0.0), Rgb(1.0)});
  scene.surfaces.push_back(Surface{Plane{Vec3(0.0, -0.2, 0.0), Vec3(0.0, 1.0, 0.0)}, Rgb(0.3), Rgb(0.0), 1.0});
  return scene;
}
std::vector<std::pair<int, int>> shadowed_floor(const Scene& scene, const MediumDesc& cloud) {
  std::vector<std::pair<int, int>> floor;
  for (int y = 0; y < scene.camera.height_px; ++y)
    for (int x = 0; x < scene.camera.width_px; ++x) {
      const Ray ray = scene.camera.pixel_ray(x, y);
      double t;
      Vec3 normal;
      if (!nearest_surface(scene.surfaces, ray, kInfinity, t, normal)) continue;
      const Vec3 p = ray.at(t);
      double t0 = 0.0, t1 = t;
      if (std::abs(p.x) > 0.55 || std::abs(p.z) > 0.55 || (cloud.bounds.clip(ray, t0, t1) && t1 > t0)) continue;
      floor.emplace_back(x, y);
    }
  return floor;
}

// A Lambert floor (kd 0.3) under a box cloud (optical height 2.4, albedo 0.95) lit by the sun from
// straight above: the floor in the cloud's shadow sees little but the light the cloud scatters onto
// it, part of it light the floor itself sent up into the cloud. The DOM's mean over those floor
// pixels is within 3% of the full reference (whose own noise there is 0.55%) with the default two
// surface passes (measured -0.5%; one pass -1.1%). Without them, the floor's light left out of the
// medium, it is 19% dark; before the first bounce onto surfaces it was 67% dark.
TEST(SurfaceLight, FloorUnderACloudReceivesItsScatteredLight) {
  grids::register_methods();
  MediumDesc cloud;
  const Scene scene = floor_scene(cloud);
  RenderOptions reference_options;
  reference_options.settings = {{"spp", 2048}, {"seed", 4}};
  const RenderResult reference = render(scene, "reference", reference_options);
  const std::vector<std::pair<int, int>> floor = shadowed_floor(scene, cloud);
  double want = 0.0, variance = 0.0;
  for (auto [x, y] : floor) want += reference.radiance.at(x, y).g, variance += std::pow(reference.std_error->at(x, y).g, 2);
  ASSERT_GT(floor.size(), 20u);
  const double noise = std::sqrt(variance) / want;
  EXPECT_LT(noise, 0.01);
  for (int passes : {0, 1, 2}) {
    RenderOptions dom_options;
    dom_options.settings = {{"resolution", 24}, {"surface_passes", passes}};
    const Image dom = render(scene, "dom", dom_options).radiance;
    double got = 0.0;
    for (auto [x, y] : floor) got += dom.at(x, y).g;
    std::printf("floor under the cloud, %zu pixels, %d surface passes: dom %.5f, reference %.5f (noise %.2f%%): %+.2f%%\n", floor.size(),
                passes, got / static_cast<double>(floor.size()), want / static_cast<double>(floor.size()), 100.0 * noise,
                100.0 * (got / want - 1.0));
    if (passes == 0) {
      EXPECT_LT(got / want, 0.9);  // the floor's light back through the cloud matters here
    }
    if (passes == 2) {
      EXPECT_NEAR(got / want, 1.0, 0.03);
    }
  }
}

// Propagation with surface_light 1 gathers the single-scattered light onto that floor: against the
// reference with one scattering event and one surface reflection per path, within 3% (its noise a
// fraction of that); without it the floor there gets the sun through the cloud only.
TEST(SurfaceLight, PropagationGathersTheSingleScatteredLightOntoTheFloor) {
  grids::register_methods();
  MediumDesc cloud;
  const Scene scene = floor_scene(cloud);
  RenderOptions reference_options;
  reference_options.settings = {{"spp", 1024}, {"seed", 7}, {"max_scattering", 1}, {"max_bounces", 1}};
  const RenderResult reference = render(scene, "reference", reference_options);
  const std::vector<std::pair<int, int>> floor = shadowed_floor(scene, cloud);
  double want = 0.0, variance = 0.0;
  for (auto [x, y] : floor) want += reference.radiance.at(x, y).g, variance += std::pow(reference.std_error->at(x, y).g, 2);
  for (int gather : {0, 1}) {
    RenderOptions options;
    options.settings = {{"resolution", 48}, {"surface_light", gather}};
    const Image image = render(scene, "propagation", options).radiance;
    double got = 0.0;
    for (auto [x, y] : floor) got += image.at(x, y).g;
    std::printf("propagation, surface_light %d: floor in the cloud's shadow %+.2f%% (reference noise %.2f%%)\n", gather,
                100.0 * (got / want - 1.0), 100.0 * std::sqrt(variance) / want);
    if (gather == 1) {
      EXPECT_NEAR(got / want, 1.0, 0.03);
    } else {
      EXPECT_LT(got / want, 0.8);
    }
  }
}

// A point light 0.5 above a Lambert floor in haze (optical depth 0.2 across), beside a glossy
// sphere (ks 0.6, shininess 24): the light's single scattering glows about its direction, the
// sphere's Phong lobe is about 12 degrees wide, and its highlight is a small bright spot seen from
// the floor, all narrower than the spacing of the DOM gather's 64 directions (25 degrees), which
// alias them into blotches and spikes. With the glow's share over a polar grid about the light,
// the lobe over its own nodes and the gathers seeing other surfaces' Lambert part only, the floor's
// pixels are 3.2% RMS from the full reference (noise removed; its own noise 1.5%) and the sphere's
// 4.9% (2.0%); the 64 directions alone were 8.4% and 7.3% off. What the sphere still misses is the
// floor's bright spot under the light, as small as the glow seen from it (docs/DOM.md).
TEST(SurfaceLight, DomGathersALightsGlowAndAGlossyLobeWithoutAliasing) {
  grids::register_methods();
  Scene scene;
  scene.camera.position = Vec3(0.0, 1.4, 3.2), scene.camera.look_at = Vec3(0.0, 0.2, 0.0);
  scene.camera.width_px = 48, scene.camera.height_px = 36;
  MediumDesc haze;
  haze.bounds = {Vec3(-2.0, 0.0, -2.0), Vec3(2.0, 1.5, 2.0)};
  haze.sigma_t = Rgb(0.05), haze.albedo = Rgb(0.9), haze.phase = PhaseFunction::henyey_greenstein(0.7);
  scene.medium = haze;
  scene.lights.push_back(PointLight{Vec3(-0.3, 0.5, 0.0), Rgb(4.0)});
  scene.surfaces.push_back(Surface{Plane{Vec3(0.0), Vec3(0.0, 1.0, 0.0)}, Rgb(0.5), Rgb(0.0), 1.0});
  scene.surfaces.push_back(Surface{Sphere{Vec3(0.6, 0.4, 0.2), 0.4}, Rgb(0.2), Rgb(0.6), 24.0});
  RenderOptions reference_options;
  reference_options.settings = {{"spp", 16384}, {"seed", 5}};
  const RenderResult reference = render(scene, "reference", reference_options);
  RenderOptions dom_options;
  dom_options.settings = {{"resolution", 24}, {"directions", 48}, {"terms", 16}};
  const Image dom = render(scene, "dom", dom_options).radiance;
  for (size_t which = 0; which < 2; ++which) {
    Image mask(scene.camera.width_px, scene.camera.height_px);  // the reference where `which` is seen
    for (int y = 0; y < mask.height(); ++y)
      for (int x = 0; x < mask.width(); ++x) {
        double t;
        Vec3 normal;
        const Surface* hit = nearest_surface(scene.surfaces, scene.camera.pixel_ray(x, y), kInfinity, t, normal);
        if (hit == &scene.surfaces[which]) mask.set(x, y, reference.radiance.at(x, y));
      }
    const LitPixelError e = lit_pixel_error(dom, reference.radiance, &*reference.std_error, &mask);
    std::printf("%s: %d pixels, RMS %.2f%% (noise removed; reference noise %.2f%%), signed mean %+.2f%%\n", which == 0 ? "floor" : "sphere",
                e.pixels, 100.0 * e.rms_noise_removed, 100.0 * e.noise_rms, 100.0 * e.signed_mean);
    EXPECT_GT(e.pixels, which == 0 ? 400 : 40);
    EXPECT_LT(e.rms_noise_removed, which == 0 ? 0.045 : 0.065);
  }
}

// A dark sphere (kd 0.1) inside a dense fog box (optical radius 2, albedo 0.95) under the sun: the
// sweeps let the medium's scattered light through the sphere, so the fog beside it, where the
// sphere fills much of what a point sees, comes out bright unless the gather takes the sphere's
// own light there instead (Gather::sphere_correction). Over the fog pixels whose rays pass within
// two radii of its centre, the DOM's signed mean is within 4% of the reference (measured +2.3%,
// its standard error 0.2%, with the diamond scheme; -1.0% with step; without the correction
// +4.9% with step).
TEST(SurfaceLight, DomFogBesideASphereInsideTheGrid) {
  grids::register_methods();
  Scene scene = grids::fog_cube(2.0, 0.95, 0.3);
  scene.lights.push_back(DirectionalLight{glm::normalize(Vec3(0.3, -1.0, -0.2)), Rgb(1.0)});
  const Sphere ball{Vec3(0.0), 0.35};
  scene.surfaces.push_back(Surface{ball, Rgb(0.1), Rgb(0.0), 1.0});
  RenderOptions reference_options;
  reference_options.settings = {{"spp", 4096}, {"seed", 3}};
  const RenderResult reference = render(scene, "reference", reference_options);
  Image beside(32, 32);  // the reference where a ray passes the sphere within two radii
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const Ray ray = scene.camera.pixel_ray(x, y);
      const double t = glm::dot(ball.center - ray.origin, ray.direction), miss = glm::length(ray.at(t) - ball.center);
      if (miss > ball.radius && miss < 2.0 * ball.radius) beside.set(x, y, reference.radiance.at(x, y));
    }
  RenderOptions options;
  options.settings = {{"resolution", 24}, {"directions", 48}, {"terms", 16}};
  const LitPixelError e = lit_pixel_error(render(scene, "dom", options).radiance, reference.radiance, &*reference.std_error, &beside);
  std::printf("fog beside the sphere, %d pixels: signed mean %+.2f%% (its standard error %.2f%%), RMS %.2f%%\n", e.pixels,
              100.0 * e.signed_mean, 100.0 * e.signed_mean_error, 100.0 * e.rms_noise_removed);
  EXPECT_GT(e.pixels, 100);
  EXPECT_NEAR(e.signed_mean, 0.0, 0.04);
}

}  // namespace
}  // namespace haze
