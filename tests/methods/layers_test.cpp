// A host's view (DESIGN.md, "Callers"): the layers L_in, T and C per pixel, and a depth buffer
// that ends the rays, for every method.
#include <haze/auto/auto.h>
#include <haze/core/error.h>
#include <haze/core/method.h>
#include <haze/grids/methods.h>
#include <haze/particles/methods.h>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/trigonometric.hpp>
#include <gtest/gtest.h>

#include "scenes/fog_box.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace haze {
namespace {

// Homogeneous fog in a box over a floor at y = -1, a point light above it; with `sphere`, a ball
// in the fog (which shadows it).
Scene fog_scene(bool floor, bool black_floor, bool sphere) {
  Scene scene = testing::fog_box(24, 16);
  scene.background = Rgb(0.05, 0.1, 0.2);
  const Rgb kd = black_floor ? Rgb(0.0) : Rgb(0.5), ks = black_floor ? Rgb(0.0) : Rgb(0.2);
  if (floor) scene.surfaces.push_back({Plane{Vec3(0.0, -1.0, 0.0), Vec3(0.0, 1.0, 0.0)}, kd, ks, 20.0});
  if (sphere) scene.surfaces.push_back({Sphere{Vec3(0.3, -0.4, 0.0), 0.5}, Rgb(0.6, 0.3, 0.2), Rgb(0.0), 1.0});
  scene.method = {{"name", "quadrature"}, {"steps", 64}};  // when quadrature renders it
  return scene;
}

// The largest difference over the channels relative to b, or to `floor` where b is smaller.
double relative(const Rgb& a, const Rgb& b, double floor = 1e-6) {
  double worst = 0.0;
  for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(a[c] - b[c]) / std::max(std::abs(b[c]), floor));
  return worst;
}

// With Haze's own surfaces, T C + L_in is Haze's own image (to float rounding), the image is the
// one rendered without layers, T lies in (0, 1], and a pixel that sees the background has it as C.
// examples/particle_cloud.json at 24 x 18 pixels over a floor at y = -1.4, below every particle's
// Gaussian (the lowest centre is at -0.8; the light is above it).
Scene particle_scene(bool black_floor) {
  Scene scene = Scene::load(std::string(HAZE_SOURCE_DIR) + "/examples/particle_cloud.json");
  scene.camera.width_px = 24, scene.camera.height_px = 18;
  const Rgb kd = black_floor ? Rgb(0.0) : Rgb(0.5);
  scene.surfaces.push_back({Plane{Vec3(0.0, -1.4, 0.0), Vec3(0.0, 1.0, 0.0)}, kd, Rgb(0.0), 1.0});
  return scene;
}

constexpr const char* kLayered[] = {"analytic", "quadrature", "propagation", "dom", "reference"};

// Quick settings for the grid methods (the layers do not depend on them).
RenderOptions quick(const std::string& method) {
  RenderOptions options;
  if (method == "propagation") options.settings = {{"resolution", 24}};
  if (method == "dom") options.settings = {{"resolution", 16}, {"directions", 32}, {"terms", 9}};
  // Single scattering without bounces: a path ends at its first scattering's light, so a black
  // floor and a depth buffer in its place draw the same random numbers.
  if (method == "reference") options.settings = {{"spp", 64}, {"max_scattering", 1}, {"max_bounces", 0}};
  return options;
}

TEST(Layers, CompositeIsTheImage) {
  grids::register_methods();
  const Scene scene = fog_scene(true, false, true);
  for (const char* method : kLayered) {
    const RenderResult plain = render(scene, method, quick(method));
    const RenderResult layered = render(scene, method, quick(method), View{scene.camera, {}, true});
    ASSERT_TRUE(layered.inscatter && layered.transmittance && layered.surface) << method;
    EXPECT_EQ(layered.radiance.data(), plain.radiance.data()) << method;
    int background = 0;
    Rgb background_c(0.0);
    for (int y = 0; y < scene.camera.height_px; ++y)
      for (int x = 0; x < scene.camera.width_px; ++x) {
        const Rgb l = layered.inscatter->at(x, y), t = layered.transmittance->at(x, y), c = layered.surface->at(x, y);
        ASSERT_LT(relative(l + t * c, plain.radiance.at(x, y)), 1e-6) << method << " at " << x << ", " << y;
        for (int k = 0; k < 3; ++k) ASSERT_TRUE(t[k] > 0.0 && t[k] <= 1.0) << method << " at " << x << ", " << y;
        const Ray ray = scene.camera.pixel_ray(x, y);
        double t_hit;
        Vec3 n;
        if (!nearest_surface(scene.surfaces, ray, kInfinity, t_hit, n)) {
          // The path tracer's C is its estimate S / T: the background within the noise.
          if (std::string(method) != "reference") {
            EXPECT_LT(relative(c, scene.background), 1e-6) << method << " at " << x << ", " << y;
          }
          background_c += c, ++background;
        }
      }
    EXPECT_GT(background, 20) << method;  // the test sees the background
    EXPECT_LT(relative(background_c / double(background), scene.background), 0.1) << method;
  }
}

// A host's depth buffer in place of Haze's floor: with the floor removed and its distances given
// as the depth, the layers equal those of the scene with a black floor (it shadows no part of the
// view rays: the light is above it), C is 0 where the depth ends a ray, and the background
// elsewhere.
TEST(Layers, DepthBufferEndsTheRaysAsASurfaceWould) {
  grids::register_methods();
  const Scene black = fog_scene(true, true, false), open = fog_scene(false, false, false);
  const Camera& camera = black.camera;
  std::vector<float> depth;
  int cut = 0;
  for (int y = 0; y < camera.height_px; ++y)
    for (int x = 0; x < camera.width_px; ++x) {
      double t;
      Vec3 n;
      const bool hit = nearest_surface(black.surfaces, camera.pixel_ray(x, y), kInfinity, t, n);
      depth.push_back(hit ? static_cast<float>(t) : std::numeric_limits<float>::infinity());
      cut += hit;
    }
  ASSERT_GT(cut, 50);
  ASSERT_LT(cut, camera.width_px * camera.height_px);
  for (const char* method : kLayered) {
    const RenderResult a = render(black, method, quick(method), View{camera, {}, true}),
                       b = render(open, method, quick(method), View{camera, depth, true});
    // The depth is a float: where a ray's segment in the fog is short, its rounding (about 1e-7 of
    // the distance) is a larger share of the in-scatter, which is small there.
    const double floor = 0.01 * a.inscatter->mean().r;
    for (int y = 0; y < camera.height_px; ++y)
      for (int x = 0; x < camera.width_px; ++x) {
        const float d = depth[static_cast<size_t>(y * camera.width_px + x)];
        EXPECT_LT(relative(b.inscatter->at(x, y), a.inscatter->at(x, y), floor), 1e-5) << method << " at " << x << ", " << y;
        EXPECT_LT(relative(b.transmittance->at(x, y), a.transmittance->at(x, y)), 1e-5) << method << " at " << x << ", " << y;
        EXPECT_EQ(b.surface->at(x, y), std::isinf(d) ? a.surface->at(x, y) : Rgb(0.0)) << method << " at " << x << ", " << y;
        EXPECT_LT(relative(b.inscatter->at(x, y) + b.transmittance->at(x, y) * b.surface->at(x, y), b.radiance.at(x, y)), 1e-6);
      }
  }
}

// The network on a particle cloud over a floor: the composite is the image, and a depth buffer in
// place of a black floor gives that floor's layers.
TEST(Layers, NetworkCompositeAndDepth) {
  particles::register_methods();
  const Scene scene = particle_scene(false), black = particle_scene(true);
  Scene open = black;
  open.surfaces.clear();
  const Camera& camera = scene.camera;
  const RenderResult plain = render(scene, "network"), layered = render(scene, "network", {}, View{camera, {}, true});
  EXPECT_EQ(layered.radiance.data(), plain.radiance.data());
  std::vector<float> depth;
  for (int y = 0; y < camera.height_px; ++y)
    for (int x = 0; x < camera.width_px; ++x) {
      const Rgb l = layered.inscatter->at(x, y), t = layered.transmittance->at(x, y), c = layered.surface->at(x, y);
      ASSERT_LT(relative(l + t * c, plain.radiance.at(x, y)), 1e-6) << x << ", " << y;
      double t_hit;
      Vec3 n;
      const bool hit = nearest_surface(black.surfaces, camera.pixel_ray(x, y), kInfinity, t_hit, n);
      depth.push_back(hit ? static_cast<float>(t_hit) : std::numeric_limits<float>::infinity());
    }
  ASSERT_GT(std::count_if(depth.begin(), depth.end(), [](float d) { return std::isfinite(d); }), 20);
  const RenderResult a = render(black, "network", {}, View{camera, {}, true}), b = render(open, "network", {}, View{camera, depth, true});
  const double floor = 0.01 * a.inscatter->mean().r;
  for (int y = 0; y < camera.height_px; ++y)
    for (int x = 0; x < camera.width_px; ++x) {
      EXPECT_LT(relative(b.inscatter->at(x, y), a.inscatter->at(x, y), floor), 1e-5) << x << ", " << y;
      EXPECT_LT(relative(b.transmittance->at(x, y), a.transmittance->at(x, y)), 1e-5) << x << ", " << y;
      EXPECT_EQ(b.surface->at(x, y), std::isinf(depth[static_cast<size_t>(y * camera.width_px + x)]) ? a.surface->at(x, y) : Rgb(0.0));
    }
}

// A host's matrices for the scene's own pinhole camera render its image, with every method that
// takes views (a solution prepared once, rendered from both).
TEST(Layers, HostMatricesRenderAsTheCameraTheyDescribe) {
  grids::register_methods();
  particles::register_methods();
  for (const std::string method : {"analytic", "quadrature", "propagation", "dom", "network"}) {
    const Scene scene = method == "network" ? particle_scene(false) : fog_scene(true, false, true);
    const Camera& c = scene.camera;
    const Camera host = Camera::from_matrices(glm::lookAt(c.position, c.look_at, c.up),
                                              glm::perspective(glm::radians(c.fov_y_deg), double(c.width_px) / c.height_px, 0.1, 100.0),
                                              c.width_px, c.height_px);
    const Solution solution = prepare(scene, method, quick(method));
    const Image own = solution.render(View{c}).radiance, matrices = solution.render(View{host}).radiance;
    for (int y = 0; y < c.height_px; ++y)
      for (int x = 0; x < c.width_px; ++x) ASSERT_LT(relative(matrices.at(x, y), own.at(x, y), 1e-3 * own.mean().r), 1e-4) << method << " at " << x << ", " << y << ": " << matrices.at(x, y).r << " " << own.at(x, y).r;
  }
}

// Method auto renders the layers of the method it chose.
TEST(Layers, AutoPassesTheChosenMethodsLayers) {
  grids::register_methods();
  Scene scene = fog_scene(true, false, true);
  scene.method = {{"name", "auto"}, {"tolerance", 0.1}};
  const AutoChoice choice = choose_method(scene, 0.1);
  ASSERT_NE(std::find(std::begin(kLayered), std::end(kLayered), choice.method), std::end(kLayered)) << choice.method;
  const RenderResult plain = render(scene, "auto"), layered = render(scene, "auto", {}, View{scene.camera, {}, true});
  ASSERT_TRUE(layered.inscatter.has_value());
  for (int y = 0; y < scene.camera.height_px; ++y)
    for (int x = 0; x < scene.camera.width_px; ++x)
      ASSERT_LT(relative(layered.inscatter->at(x, y) + layered.transmittance->at(x, y) * layered.surface->at(x, y), plain.radiance.at(x, y)), 1e-6);
}

// The layers into the caller's memory (render_layers) against render's: analytic's rows of tails
// (SIMD lanes) against its float64 kernel's per-segment render within 1e-3 relative RMS and 2e-3
// per pixel of L_in, in a box, in unbounded fog and in a coloured medium, over a host's floor and
// the sky, and with surfaces (a Phong floor, a sphere shadowing the light: lit stretches, C shaded
// in float32 lanes within 1e-4 of float64); RGBA rows with padding left as they were; propagation's march into the
// spans (march_layers: the rows of its render, the same kernel) as its render's; dom's gather as
// its render's with a point light, and under a sun the marcher's kernel with the moments' light
// toward the eye per cell (4.4e-4 relative RMS, 2.3e-3 at worst: held to 4e-3 there, as its
// froxels are); propagation's and dom's on the march's lattice, T within 1e-3 per pixel (9.3e-5
// at worst under the sun).
TEST(Layers, RenderLayersIntoCallerMemoryMatchesRender) {
  grids::register_methods();
  for (const std::string variant : {"box", "unbounded", "coloured", "surfaces", "propagation", "dom", "dom sun"}) {
    Scene scene = testing::fog_box(48, 32, Vec3(0.1, -0.1, 0.4));
    if (variant == "surfaces") {
      scene.medium->albedo = Rgb(0.9, 0.7, 0.5);
      scene.surfaces.push_back({Plane{Vec3(0.0, -0.9, 0.0), Vec3(0.0, 1.0, 0.0)}, Rgb(0.5), Rgb(0.2), 20.0});
      scene.surfaces.push_back({Sphere{Vec3(0.3, -0.4, 0.0), 0.35}, Rgb(0.6, 0.3, 0.2), Rgb(0.0), 1.0});
    }
    if (variant == "dom sun") scene.lights = {DirectionalLight{glm::normalize(Vec3(0.3, -1.0, 0.2)), Rgb(2.0)}};
    if (variant == "unbounded") scene.medium->bounds = Aabb{};
    if (variant == "coloured") scene.medium->albedo = Rgb(0.9, 0.7, 0.5);
    scene.background = Rgb(0.05, 0.1, 0.2);
    std::vector<float> depth;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 48; ++x) {
        const Ray ray = scene.camera.pixel_ray(x, y);
        depth.push_back(ray.direction.y < 0.0 ? static_cast<float>((-1.0 - ray.origin.y) / ray.direction.y) : std::numeric_limits<float>::infinity());
      }
    RenderOptions prepared;
    if (variant == "propagation") prepared.settings = {{"resolution", 16}};
    if (variant.starts_with("dom")) prepared.settings = {{"resolution", 12}, {"directions", 32}, {"terms", 9}};
    const std::string method = variant == "propagation" ? variant : variant.starts_with("dom") ? "dom" : "analytic";
    const Solution solution = prepare(scene, method, prepared);
    const View layered{scene.camera, depth, true};
    RenderOptions float64;
    float64.settings = {{"kernel", "float64"}};
    const RenderResult exact = method == "analytic" ? prepare(scene, method, float64).render(layered) : solution.render(layered);
    const size_t stride = 4 * 48 + 3;
    std::vector<float> l(stride * 32, -7.0f), t(3 * 48 * 32), c(3 * 48 * 32);
    solution.render_layers(View{scene.camera, depth}, {ImageSpan{l.data(), 48, 32, 4, stride}, ImageSpan{t.data(), 48, 32}, ImageSpan{c.data(), 48, 32}});
    double d2 = 0.0, r2 = 0.0, worst = 0.0;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 48; ++x) {
        const float* li = &l[static_cast<size_t>(y) * stride + 4 * static_cast<size_t>(x)];
        const size_t at = 3 * (static_cast<size_t>(y) * 48 + static_cast<size_t>(x));
        const Rgb got(li[0], li[1], li[2]), want = exact.inscatter->at(x, y);
        d2 += glm::dot(got - want, got - want), r2 += glm::dot(want, want);
        worst = std::max(worst, glm::length(got - want) / std::max(glm::length(want), 1e-6));
        ASSERT_EQ(li[3], -7.0f) << "alpha written";
        // The march's layers on its lattice (propagation.h, MarchSettings::lattice): T between nodes.
        const double t_bound = method == "analytic" ? 1e-6 : 1e-3;
        ASSERT_LT(glm::length(Rgb(t[at], t[at + 1], t[at + 2]) - exact.transmittance->at(x, y)), t_bound) << variant << " T at " << x << ", " << y;
        const Rgb surface = exact.surface->at(x, y);
        ASSERT_LT(glm::length(Rgb(c[at], c[at + 1], c[at + 2]) - surface), 1e-6 + 1e-4 * glm::length(surface)) << variant << " C at " << x << ", " << y;
      }
    std::printf("render_layers (%s) against render: L_in %.2e relative RMS, %.2e at worst\n", variant.c_str(), std::sqrt(d2 / r2), worst);
    EXPECT_LT(std::sqrt(d2 / r2), 1e-3) << variant;
    EXPECT_LT(worst, variant == "dom sun" ? 4e-3 : 2e-3) << variant;
    for (size_t y = 0; y < 32; ++y) EXPECT_EQ(l[y * stride + 4 * 48], -7.0f) << "row padding written";
  }
}

// Analytic's view_shadows 0 (the thesis' model: surfaces end the view rays but do not shadow their
// airlight) is the airlight of the same scene without its surfaces and a host's depth where they
// were: in the rows of tails and in the float64 kernel's per-segment render.
TEST(Layers, AnalyticWithoutViewShadowsIsTheAirlightToTheSurfaces) {
  Scene scene = testing::fog_box(48, 32, Vec3(0.1, -0.1, 0.4));
  scene.surfaces.push_back({Plane{Vec3(0.0, -0.9, 0.0), Vec3(0.0, 1.0, 0.0)}, Rgb(0.5), Rgb(0.0), 1.0});
  scene.surfaces.push_back({Sphere{Vec3(0.3, -0.4, 0.0), 0.35}, Rgb(0.6, 0.3, 0.2), Rgb(0.0), 1.0});
  std::vector<float> depth;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 48; ++x) {
      double t;
      Vec3 normal;
      nearest_surface(scene.surfaces, scene.camera.pixel_ray(x, y), kInfinity, t, normal);
      depth.push_back(static_cast<float>(t));
    }
  Scene bare = scene;
  bare.surfaces.clear();
  const RenderResult want = prepare(bare, "analytic").render(View{bare.camera, depth, true});
  for (const std::string kernel : {"simd", "float64"}) {
    RenderOptions options;
    options.settings = {{"view_shadows", 0}, {"kernel", kernel}};
    const RenderResult got = prepare(scene, "analytic", options).render(View{scene.camera, {}, true});
    RenderOptions shadowed;
    shadowed.settings = {{"kernel", kernel}};
    const RenderResult dark = prepare(scene, "analytic", shadowed).render(View{scene.camera, {}, true});
    double shadow = 0.0;
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 48; ++x) {
        ASSERT_LT(relative(got.inscatter->at(x, y), want.inscatter->at(x, y)), 2e-3) << kernel << " at " << x << ", " << y;
        shadow = std::max(shadow, relative(dark.inscatter->at(x, y), want.inscatter->at(x, y)));
      }
    EXPECT_GT(shadow, 0.05) << kernel << ": the sphere's shadow darkens the airlight when view_shadows is on";
  }
}

// Analytic's rows at a size where the row lattice takes about half the pixels from their
// neighbours (paper 002's fog_lamps at 192 x 128: coloured fog, a floor and a Phong sphere, three
// point lights, one in view) against the float64 kernel's every pixel: L_in within 1e-3 relative
// RMS and 2e-3 at worst, with and without the view rays' shadows.
TEST(Layers, AnalyticRowLatticeKeepsEveryPixelsAirlight) {
  Scene scene;
  scene.camera.width_px = 192, scene.camera.height_px = 128, scene.camera.fov_y_deg = 45.0;
  scene.camera.position = Vec3(1.8, 2.5, 5.7), scene.camera.look_at = Vec3(0.0, 1.0, 0.0);
  MediumDesc medium;
  medium.density = ConstantDensity{1.0};
  medium.sigma_t = Rgb(0.22, 0.26, 0.32), medium.albedo = Rgb(0.8);
  medium.phase = PhaseFunction::henyey_greenstein(0.5);
  medium.bounds = Aabb{Vec3(-4.0, 0.0, -4.0), Vec3(4.0, 3.5, 4.0)};
  scene.medium = medium;
  scene.lights = {PointLight{Vec3(-1.2, 1.8, 0.0), Rgb(14, 11, 7)}, PointLight{Vec3(1.6, 0.9, -1.5), Rgb(3, 5, 10)},
                  PointLight{Vec3(0.3, 2.2, 1.4), Rgb(8.0)}};
  scene.surfaces = {{Plane{Vec3(0.0), Vec3(0.0, 1.0, 0.0)}, Rgb(0.5), Rgb(0.0), 1.0}, {Sphere{Vec3(0.4, 0.6, 0.8), 0.6}, Rgb(0.6, 0.25, 0.2), Rgb(0.4), 24.0}};
  for (int shadows : {1, 0}) {
    RenderOptions rows, float64;
    rows.settings = {{"view_shadows", shadows}};
    float64.settings = {{"view_shadows", shadows}, {"kernel", "float64"}};
    const View view{scene.camera, {}, true};
    const RenderResult got = prepare(scene, "analytic", rows).render(view), want = prepare(scene, "analytic", float64).render(view);
    double d2 = 0.0, r2 = 0.0, worst = 0.0;
    for (int y = 0; y < 128; ++y)
      for (int x = 0; x < 192; ++x) {
        const Rgb a = got.inscatter->at(x, y), b = want.inscatter->at(x, y);
        d2 += glm::dot(a - b, a - b), r2 += glm::dot(b, b);
        worst = std::max(worst, relative(a, b, 1e-6));
      }
    std::printf("rows (view_shadows %d) against the float64 kernel: L_in %.2e relative RMS, %.2e at worst\n", shadows, std::sqrt(d2 / r2), worst);
    EXPECT_LT(std::sqrt(d2 / r2), 1e-3) << shadows;
    EXPECT_LT(worst, 2e-3) << shadows;
  }
}

TEST(Layers, BadViewsAreClearErrors) {
  grids::register_methods();
  const Scene scene = fog_scene(true, false, false);
  auto field_of = [&](const std::string& method, const View& view) {
    try {
      render(scene, method, {}, view);
    } catch (const Error& e) {
      return e.field();
    }
    return std::string("no error");
  };
  const size_t count = static_cast<size_t>(scene.camera.width_px * scene.camera.height_px);
  std::vector<float> short_depth(count - 1, 1.0f), negative(count, 1.0f);
  negative[3] = -0.5f;
  EXPECT_EQ(field_of("quadrature", View{scene.camera, short_depth, false}), "view.depth");
  EXPECT_EQ(field_of("quadrature", View{scene.camera, negative, false}), "view.depth[3]");
}

}  // namespace
}  // namespace haze
