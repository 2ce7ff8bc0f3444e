// The lights folded into a radiance per cell toward one eye (march_toward_eye): the SIMD kernel on
// every compiled target against its float64 reference, and the per-pixel layers read through it
// against the march's steps (MarchSettings::toward_eye) on the frame benchmark's cloud.
#include <haze/core/error.h>
#include <haze/grids/march_rays.h>
#include <haze/grids/optical_depth.h>
#include <haze/grids/propagation.h>

#include "scenes/cloud_scene.h"

#include <gtest/gtest.h>
#include <hwy/tests/hwy_gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace haze::grids {
namespace {

// The kernel's view of a volume and its lights, as the marcher builds it (slots in scene order).
struct KernelView {
  ExtinctionVolume volume;
  std::vector<DenseGrid> depths;
  PackedLights packed;
  std::vector<MarchLight> lights;
  MarchVolume v;

  KernelView(const Scene& scene, int resolution)
      : volume(make_extinction_volume(scene, resolution)), depths(optical_depths(volume.density, scene.lights)),
        packed(pack_lights(scene, volume, depths, 1)) {
    for (size_t l = 0; l < scene.lights.size(); ++l) {
      MarchLight m;
      m.slot = static_cast<int>(l);
      Rgb intensity;
      if (const auto* p = std::get_if<PointLight>(&scene.lights[l])) {
        for (int e = 0; e < 3; ++e) m.position[e] = static_cast<float>(p->position[e]);
        intensity = p->intensity;
      } else {
        const auto& d = std::get<DirectionalLight>(scene.lights[l]);
        m.type = MarchLight::directional;
        for (int e = 0; e < 3; ++e) m.to_light[e] = static_cast<float>(-d.direction[e]);
        intensity = d.irradiance;
      }
      for (int c = 0; c < 3; ++c) m.intensity[c] = static_cast<float>(intensity[c]);
      lights.push_back(m);
    }
    const DenseGrid& g = volume.density;
    for (int e = 0; e < 3; ++e) {
      v.n[e] = g.resolution()[static_cast<size_t>(e)];
      v.lo[e] = static_cast<float>(g.bounds().lo[e]), v.h[e] = static_cast<float>(g.cell_size()[e]);
      v.sigma_t[e] = static_cast<float>(volume.sigma_t_scale[e]);
    }
    v.density = g.values().data(), v.depths = packed.depths.data();
    v.lights = lights.data(), v.light_count = v.depth_stride = static_cast<int>(lights.size());
  }
};

class TowardEyeTargets : public hwy::TestWithParamTarget {};
HWY_TARGET_INSTANTIATE_TEST_SUITE_P(TowardEyeTargets);

// A float16 value's bits as a double (0, normal and subnormal).
double from_half(uint32_t h) {
  const int exponent = static_cast<int>((h >> 10) & 31), mantissa = static_cast<int>(h & 1023);
  return exponent == 0 ? std::ldexp(mantissa, -24) : std::ldexp(1024 + mantissa, exponent - 25);
}

// float32 positions, Highway's Exp and the phase's fast inverse square roots against float64, the
// values stored as float16 over their scales: within 2^-10 of each value (float16's rounding, 2^-11,
// where the CPU converts; Highway's conversion on targets without F16C truncates) plus 1e-4 of its
// scale's unit (the float32 arithmetic and 0 below 2^-14), three channels and one, on a grid whose
// x side (21) is no multiple of any vector's lanes; the grey medium's also from the attenuation
// planes (PackedLights::attenuation) in place of the depths.
TEST_P(TowardEyeTargets, MatchesTheFloat64Reference) {
  for (bool coloured : {true, false}) {
    Scene scene = cloud_scene(8, 8);
    scene.medium->bounds = Aabb{Vec3(-0.7, -0.5, -0.6), Vec3(0.7, 0.5, 0.6)};
    scene.lights = {PointLight{Vec3(1.4, 0.9, -0.6), Rgb(2.0, 1.8, 1.5)}, DirectionalLight{glm::normalize(Vec3(0.3, -1.0, 0.2)), Rgb(0.5, 0.6, 0.7)}};
    if (!coloured) {
      scene.medium->sigma_t = Rgb(2.4);
      scene.lights = {PointLight{Vec3(1.4, 0.9, -0.6), Rgb(2.0)}, DirectionalLight{glm::normalize(Vec3(0.3, -1.0, 0.2)), Rgb(0.5)}};
    }
    KernelView k(scene, 21);
    const int channels = k.v.channels = coloured ? 3 : 1;
    const float eye[3] = {0.3f, 0.4f, 3.2f};
    const double eye64[3] = {0.3, 0.4, 3.2};
    const auto n = k.volume.density.resolution();
    const size_t cells = static_cast<size_t>(n[0] + 2) * static_cast<size_t>(n[1] + 2) * static_cast<size_t>(n[2] + 2);  // with the ghosts
    std::vector<double> reference;
    march_toward_eye_reference(k.v, k.volume.phase, eye64, k.lights.data(), 2, reference);
    ASSERT_EQ(reference.size(), cells * static_cast<size_t>(channels + 1));
    // Each value's scale: its largest over 16384, as march_layers takes a bound.
    double scale[4] = {0.0, 0.0, 0.0, 0.0};
    for (size_t i = 0; i < reference.size(); ++i) {
      const size_t value = i % static_cast<size_t>(channels + 1), slot = value == static_cast<size_t>(channels) ? 3 : value;
      scale[slot] = std::max(scale[slot], reference[i] / 16384.0);
    }
    ASSERT_GT(scale[0], 1e-5);
    for (int c = 0; c < 4; ++c) k.v.folded_scale[c] = static_cast<float>(scale[c]);
    // The depths, then (grey) the attenuation planes of both lights.
    ASSERT_EQ(k.packed.attenuation.empty(), coloured);
    for (const bool planes : {false, true}) {
      if (planes && coloured) continue;
      if (planes) {
        for (MarchLight& l : k.lights) l.plane = k.packed.attenuation_plane[static_cast<size_t>(l.slot)];
        ASSERT_TRUE(k.lights[0].plane >= 0 && k.lights[1].plane >= 0);
        k.v.attenuation = k.packed.attenuation.data();
      }
      std::vector<uint32_t> words(cells * static_cast<size_t>(channels + 1) / 2, 0xFFFFFFFFu);
      march_toward_eye(k.v, k.volume.phase, eye, k.lights.data(), 2, words.data(), 2);
      for (size_t i = 0; i < reference.size(); ++i) {
        const size_t value = i % static_cast<size_t>(channels + 1), slot = value == static_cast<size_t>(channels) ? 3 : value;
        const double got = from_half(words[i / 2] >> (16 * (i % 2)) & 0xFFFFu) * static_cast<double>(k.v.folded_scale[slot]);
        ASSERT_NEAR(got, reference[i], std::ldexp(reference[i], -10) + 1e-4 * scale[slot])
            << "value " << i << (coloured ? " coloured" : " grey") << (planes ? " planes" : "") << " target " << hwy::TargetName(GetParam());
      }
    }
  }
}

// The folded march (MarchFoldedVector on vector targets, MarchVector's folded reads on the scalar
// one) on every compiled target against the steps on the same target (held to the float64
// marcher by MarchTargets): the frame benchmark's cloud at 48^3 and 64 x 36, within the folding's
// own error there (measured 3.2e-4 relative RMS of L_in on every target; held to 6e-4).
TEST_P(TowardEyeTargets, FoldedMarchMatchesTheSteps) {
  Scene scene = Scene::load(std::string(HAZE_SOURCE_DIR) + "/bench/frame/cloud_propagation.json");
  const int w = 64, h = 36;
  scene.camera.width_px = w, scene.camera.height_px = h;
  const ExtinctionVolume volume = make_extinction_volume(scene, 48);
  const std::vector<DenseGrid> depths = optical_depths(volume.density, scene.lights);
  std::vector<float> folded(3 * w * h), steps(3 * w * h), t(3 * w * h);
  MarchSettings settings;
  ASSERT_TRUE(march_layers(scene, volume, depths, settings, {}, View{scene.camera}, {ImageSpan{folded.data(), w, h}, ImageSpan{t.data(), w, h}, ImageSpan{}}));
  settings.toward_eye = false;
  ASSERT_TRUE(march_layers(scene, volume, depths, settings, {}, View{scene.camera}, {ImageSpan{steps.data(), w, h}, ImageSpan{t.data(), w, h}, ImageSpan{}}));
  double d2 = 0.0, r2 = 0.0;
  for (size_t i = 0; i < folded.size(); ++i) d2 += std::pow(folded[i] - steps[i], 2.0), r2 += std::pow(steps[i], 2.0);
  std::printf("%s: folded against the steps %.2e relative RMS\n", hwy::TargetName(GetParam()), std::sqrt(d2 / r2));
  ASSERT_GT(r2, 0.0);
  EXPECT_LT(std::sqrt(d2 / r2), 6e-4) << hwy::TargetName(GetParam());
}

TEST(TowardEye, SpotsAreLeftToTheMarch) {
  Scene scene = cloud_scene(8, 8);
  KernelView k(scene, 8);
  MarchLight spot;
  spot.type = MarchLight::spot;
  std::vector<uint32_t> out(10 * 10 * 10 * 2);
  const float eye[3] = {0.0f, 0.0f, 3.0f};
  try {
    march_toward_eye(k.v, k.volume.phase, eye, &spot, 1, out.data(), 1);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "lights[0].type");
  }
}

// The frame benchmark's cloud (bench/frame/cloud_propagation.json: 128^3 cells, four coloured
// point lights 4 to 21 cells outside the bounds, all folded in) at 240 x 135: the layers with the
// lights folded in toward the eye against every light's depth at every step, relative RMS of L_in
// over the image: 3.0e-4 (3.4e-4 in the address-sanitizer build), held to 5e-4. A bright light
// added 4.5 cells above the cloud's top, where the density is 12% of its largest, stays in the
// steps (2.3e-4, held to 5e-4); 8.5 cells above, it is folded in (5.1e-4, held to 1e-3). T within
// 1e-4: the folded density is float16 (2^-11 a value) and a spent ray stops under 1e-4 (5e-6;
// 3.5e-5 in the sanitizer build). The rows made in float32 lanes from the eye (march_row_packet)
// within 2e-5 of those made of float64 rays.
TEST(TowardEye, LayersWithinTheStepsOnTheFrameCloud) {
  const Scene bench = Scene::load(std::string(HAZE_SOURCE_DIR) + "/bench/frame/cloud_propagation.json");
  for (double above : {0.0, 4.5, 8.0}) {
    Scene scene = bench;
    scene.camera.width_px = 240, scene.camera.height_px = 135;
    if (above > 0.0) scene.lights.push_back(PointLight{Vec3(0.2, 1.5 + above * 3.0 / 128.0, 0.3), Rgb(2.0)});
    const ExtinctionVolume volume = make_extinction_volume(scene, 128);
    const std::vector<DenseGrid> depths = optical_depths(volume.density, scene.lights);
    const int w = 240, h = 135;
    std::vector<float> folded(3 * w * h), steps(3 * w * h), t_folded(3 * w * h), t_steps(3 * w * h);
    MarchSettings settings;
    const RenderOptions options;
    ASSERT_TRUE(march_layers(scene, volume, depths, settings, options, View{scene.camera},
                             {ImageSpan{folded.data(), w, h}, ImageSpan{t_folded.data(), w, h}, ImageSpan{}}));
    settings.toward_eye = false;
    ASSERT_TRUE(march_layers(scene, volume, depths, settings, options, View{scene.camera},
                             {ImageSpan{steps.data(), w, h}, ImageSpan{t_steps.data(), w, h}, ImageSpan{}}));
    const auto relative_rms = [](const std::vector<float>& got, const std::vector<float>& want) {
      double d2 = 0.0, r2 = 0.0;
      for (size_t i = 0; i < got.size(); ++i) d2 += std::pow(got[i] - want[i], 2.0), r2 += std::pow(want[i], 2.0);
      return std::sqrt(d2 / r2);
    };
    if (above == 0.0) {  // the rows from the eye in float32 lanes (march_row_packet) against float64 rays: a camera of the same rays given per pixel takes those
      auto rays = std::make_shared<std::vector<Ray>>();
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) rays->push_back(scene.camera.pixel_ray(x, y));
      std::vector<float> l64(3 * w * h), t64(3 * w * h), c64(3 * w * h);
      ASSERT_TRUE(march_layers(scene, volume, depths, settings, options, View{Camera::from_rays(rays, w, h)},
                               {ImageSpan{l64.data(), w, h}, ImageSpan{t64.data(), w, h}, ImageSpan{c64.data(), w, h}}));
      EXPECT_LT(relative_rms(steps, l64), 2e-5);
      EXPECT_LT(relative_rms(t_steps, t64), 1e-6);
    }
    const double rms = relative_rms(folded, steps), t_rms = relative_rms(t_folded, t_steps);
    std::printf("toward the eye against the steps, a light %.1f cells above: L_in %.2e relative RMS, T %.1e\n", above, rms, t_rms);
    EXPECT_LT(t_rms, 1e-4) << above;  // the same steps, the density in float16 and rays stopped once T < 1e-4
    EXPECT_LT(rms, above == 8.0 ? 1e-3 : 5e-4) << above;
  }
}

// The frame benchmark's per-pixel layers as a frame takes them (the step auto_step_cells chooses,
// the lights folded in) against the 0.5-cell march with every light in the steps (the images
// before either; issue 51 holds them to 1e-3): measured 3.5e-4 relative RMS of L_in at 240 x 135.
TEST(TowardEye, FrameLayersWithinTheIssuesBoundOfTheHalfCellSteps) {
  Scene scene = Scene::load(std::string(HAZE_SOURCE_DIR) + "/bench/frame/cloud_propagation.json");
  scene.camera.width_px = 240, scene.camera.height_px = 135;
  const ExtinctionVolume volume = make_extinction_volume(scene, 128);
  const std::vector<DenseGrid> depths = optical_depths(volume.density, scene.lights);
  const PackedLights packed = pack_lights(scene, volume, depths, 0);
  const int w = 240, h = 135;
  std::vector<float> frame(3 * w * h), before(3 * w * h), t(3 * w * h);
  MarchSettings settings;
  settings.step_cells = auto_step_cells(scene, volume, depths, packed, 0);
  ASSERT_TRUE(march_layers(scene, volume, depths, settings, {}, View{scene.camera}, {ImageSpan{frame.data(), w, h}, ImageSpan{t.data(), w, h}, ImageSpan{}}, &packed));
  settings.step_cells = 0.5, settings.toward_eye = false;
  ASSERT_TRUE(march_layers(scene, volume, depths, settings, {}, View{scene.camera}, {ImageSpan{before.data(), w, h}, ImageSpan{t.data(), w, h}, ImageSpan{}}, &packed));
  double d2 = 0.0, r2 = 0.0;
  for (size_t i = 0; i < frame.size(); ++i) d2 += std::pow(frame[i] - before[i], 2.0), r2 += std::pow(before[i], 2.0);
  const double rms = std::sqrt(d2 / r2);
  std::printf("the frame's layers against 0.5 cells with the lights in the steps: L_in %.2e relative RMS\n", rms);
  EXPECT_LT(rms, 1e-3);
}

// The distance along each pixel's ray to the floor y = height (+inf above the horizon).
std::vector<float> floor_depths(const Camera& camera, double height) {
  std::vector<float> depth;
  std::vector<Ray> rays(static_cast<size_t>(camera.width_px));
  for (int y = 0; y < camera.height_px; ++y) {
    camera.row_rays(y, rays.data());
    for (const Ray& r : rays)
      depth.push_back(r.direction.y < 0.0 ? static_cast<float>((height - r.origin.y) / r.direction.y) : std::numeric_limits<float>::infinity());
  }
  return depth;
}

// A coarse grid seen up close, as paper 003's: RBF fog in [-1, 1]^3, a point light, 400 x 300.
Scene lattice_scene(const Vec3& light) {
  Scene scene = Scene::load(std::string(HAZE_SOURCE_DIR) + "/examples/smoke_rbf.json");
  scene.lights = {PointLight{light, Rgb(6.0)}};
  scene.medium->bounds = Aabb{Vec3(-1.0), Vec3(1.0)};
  scene.camera.width_px = 400, scene.camera.height_px = 300;
  scene.camera.position = Vec3(-1.0, -0.6, 4.2);
  return scene;
}

// The same at the benchmark's 1920 x 1080 with its floor as the host's depth, where a cell spans
// about 4 pixels and march_layers takes a lattice 4 pixels apart: against every pixel's own ray
// (with the test above, the images before either within the issue's 1e-3 by the triangle
// inequality): measured 5.6e-4 relative RMS of L_in, 7.4e-5 of T.
TEST(TowardEye, FrameLayersOnTheLatticeWithinTheIssuesBound) {
  Scene scene = Scene::load(std::string(HAZE_SOURCE_DIR) + "/bench/frame/cloud_propagation.json");
  const int w = 1920, h = 1080;
  scene.camera.width_px = w, scene.camera.height_px = h;
  const ExtinctionVolume volume = make_extinction_volume(scene, 128);
  const std::vector<DenseGrid> depths = optical_depths(volume.density, scene.lights);
  const PackedLights packed = pack_lights(scene, volume, depths, 0);
  const std::vector<float> host = floor_depths(scene.camera, -1.5);  // the benchmark's floor
  const size_t n = 3 * static_cast<size_t>(w) * static_cast<size_t>(h);
  std::vector<float> lattice(n), pixels(n), t_lattice(n), t_pixels(n);
  MarchSettings settings;
  settings.step_cells = auto_step_cells(scene, volume, depths, packed, 0);
  ASSERT_TRUE(march_layers(scene, volume, depths, settings, {}, View{scene.camera, host}, {ImageSpan{lattice.data(), w, h}, ImageSpan{t_lattice.data(), w, h}, ImageSpan{}}, &packed));
  settings.lattice = false;
  ASSERT_TRUE(march_layers(scene, volume, depths, settings, {}, View{scene.camera, host}, {ImageSpan{pixels.data(), w, h}, ImageSpan{t_pixels.data(), w, h}, ImageSpan{}}, &packed));
  double d2 = 0.0, r2 = 0.0, t_d2 = 0.0, t_r2 = 0.0;
  for (size_t i = 0; i < n; ++i) {
    d2 += std::pow(lattice[i] - pixels[i], 2.0), r2 += std::pow(pixels[i], 2.0);
    t_d2 += std::pow(t_lattice[i] - t_pixels[i], 2.0), t_r2 += std::pow(t_pixels[i], 2.0);
  }
  const double rms = std::sqrt(d2 / r2), t_rms = std::sqrt(t_d2 / t_r2);
  std::printf("the frame's layers on the lattice against every pixel: L_in %.2e relative RMS, T %.2e\n", rms, t_rms);
  EXPECT_GT(rms, 0.0) << "the lattice taken";
  EXPECT_LT(rms, 6e-4);
  EXPECT_LT(t_rms, 6e-4);
}

// A coarse grid seen up close: march_layers takes its rays on a lattice (0.9 to 1.8 nodes per
// cell as the view sees it), halves its step in the cells with rough corners down to 2 pixels and
// interpolates the pixels, but in the rough cells of the finest level and around a near point
// light in view: RBF fog at 15^3 and 20^3, 400 x 300, the light out of view and in it, against
// every pixel's own ray (MarchSettings::lattice false): L_in within 2e-3
// relative RMS, T within 1e-3 (measured: 8.3e-4 and 3.2e-4 at 15^3, 8.1e-4 and 3.3e-4 at 20^3).
TEST(TowardEye, LatticeLayersWithinTheirBoundOfEveryPixel) {
  const int w = 400, h = 300;
  for (const bool in_view : {false, true})
    for (int n : {15, 20}) {
      const Scene scene = lattice_scene(in_view ? Vec3(0.6, 0.5, 1.3) : Vec3(1.4, 1.2, 1.0));
      const ExtinctionVolume volume = make_extinction_volume(scene, n);
      const std::vector<DenseGrid> depths = optical_depths(volume.density, scene.lights);
      std::vector<float> lattice(3 * w * h), pixels(3 * w * h), t_lattice(3 * w * h), t_pixels(3 * w * h);
      MarchSettings settings;
      ASSERT_TRUE(march_layers(scene, volume, depths, settings, {}, View{scene.camera}, {ImageSpan{lattice.data(), w, h}, ImageSpan{t_lattice.data(), w, h}, ImageSpan{}}));
      settings.lattice = false;
      ASSERT_TRUE(march_layers(scene, volume, depths, settings, {}, View{scene.camera}, {ImageSpan{pixels.data(), w, h}, ImageSpan{t_pixels.data(), w, h}, ImageSpan{}}));
      const auto relative_rms = [](const std::vector<float>& got, const std::vector<float>& want) {
        double d2 = 0.0, r2 = 0.0;
        for (size_t i = 0; i < got.size(); ++i) d2 += std::pow(got[i] - want[i], 2.0), r2 += std::pow(want[i], 2.0);
        return std::sqrt(d2 / r2);
      };
      const double rms = relative_rms(lattice, pixels), t_rms = relative_rms(t_lattice, t_pixels);
      std::printf("%d^3, the light %s: lattice against every pixel, L_in %.2e relative RMS, T %.2e\n", n, in_view ? "in view" : "out of view", rms, t_rms);
      EXPECT_GT(rms, 0.0) << n << ": the lattice taken";
      EXPECT_LT(rms, 2e-3) << n;
      EXPECT_LT(t_rms, 1e-3) << n;
    }
}

// With a host's depth the lattice still holds: a floor under the fog (depths bilinear enough
// between the nodes) and a pole 3 pixels wide in front of it (its edges, and the cells whose
// corners fall on it, take every pixel's own ray): RBF fog at 15^3, 400 x 300, against every
// pixel's own ray to the same depths: L_in within 2e-3 relative RMS, T within 1e-3, the pole's
// pixels exact (measured: 7.9e-4 and 2.7e-4).
TEST(TowardEye, LatticeLayersKeepTheHostsDepth) {
  const Scene scene = lattice_scene(Vec3(1.4, 1.2, 1.0));
  const int w = 400, h = 300;
  const ExtinctionVolume volume = make_extinction_volume(scene, 15);
  const std::vector<DenseGrid> depths = optical_depths(volume.density, scene.lights);
  std::vector<float> host = floor_depths(scene.camera, -0.4);
  for (int y = 0; y < h; ++y)
    for (int x = 197; x < 200; ++x) host[static_cast<size_t>(y * w + x)] = std::min(host[static_cast<size_t>(y * w + x)], 3.9f);  // the pole
  std::vector<float> lattice(3 * w * h), pixels(3 * w * h), t_lattice(3 * w * h), t_pixels(3 * w * h);
  MarchSettings settings;
  ASSERT_TRUE(march_layers(scene, volume, depths, settings, {}, View{scene.camera, host}, {ImageSpan{lattice.data(), w, h}, ImageSpan{t_lattice.data(), w, h}, ImageSpan{}}));
  settings.lattice = false;
  ASSERT_TRUE(march_layers(scene, volume, depths, settings, {}, View{scene.camera, host}, {ImageSpan{pixels.data(), w, h}, ImageSpan{t_pixels.data(), w, h}, ImageSpan{}}));
  double d2 = 0.0, r2 = 0.0, t_d2 = 0.0, t_r2 = 0.0, pole = 0.0;
  for (size_t i = 0; i < lattice.size(); ++i) {
    d2 += std::pow(lattice[i] - pixels[i], 2.0), r2 += std::pow(pixels[i], 2.0);
    t_d2 += std::pow(t_lattice[i] - t_pixels[i], 2.0), t_r2 += std::pow(t_pixels[i], 2.0);
    const size_t x = (i / 3) % static_cast<size_t>(w);
    if (x >= 197 && x < 200) pole = std::max({pole, std::abs(static_cast<double>(lattice[i] - pixels[i])), std::abs(static_cast<double>(t_lattice[i] - t_pixels[i]))});
  }
  const double rms = std::sqrt(d2 / r2), t_rms = std::sqrt(t_d2 / t_r2);
  std::printf("a floor and a pole: lattice against every pixel, L_in %.2e relative RMS, T %.2e; the pole's pixels %.1e off\n", rms, t_rms, pole);
  EXPECT_GT(rms, 0.0) << "the lattice taken";
  EXPECT_LT(rms, 2e-3);
  EXPECT_LT(t_rms, 1e-3);
  EXPECT_EQ(pole, 0.0);
}

// The lattice's levels (marched, tested and blended row by row on Haze's threads) come out the
// same on one thread and on four: RBF fog at 15^3, 400 x 300, a host's floor.
TEST(TowardEye, LatticeLayersThreadIndependent) {
  const Scene scene = lattice_scene(Vec3(0.6, 0.5, 1.3));
  const int w = 400, h = 300;
  const ExtinctionVolume volume = make_extinction_volume(scene, 15);
  const std::vector<DenseGrid> depths = optical_depths(volume.density, scene.lights);
  const std::vector<float> host = floor_depths(scene.camera, -0.4);
  std::vector<float> one(3 * w * h), four(3 * w * h), t_one(3 * w * h), t_four(3 * w * h);
  RenderOptions options;
  options.threads = 1;
  ASSERT_TRUE(march_layers(scene, volume, depths, {}, options, View{scene.camera, host}, {ImageSpan{one.data(), w, h}, ImageSpan{t_one.data(), w, h}, ImageSpan{}}));
  options.threads = 4;
  ASSERT_TRUE(march_layers(scene, volume, depths, {}, options, View{scene.camera, host}, {ImageSpan{four.data(), w, h}, ImageSpan{t_four.data(), w, h}, ImageSpan{}}));
  EXPECT_EQ(one, four);
  EXPECT_EQ(t_one, t_four);
}

}  // namespace
}  // namespace haze::grids
