// Froxels (haze/froxels/froxels.h) from every kind of solution: at the columns' centres and the slices'
// boundaries they hold the per-pixel layers; between them the composite's error against the
// per-pixel layers falls as the volume is refined; the float32 threaded composite into a caller's
// memory agrees with the float64 lookup it replaces; bad grids and spans are clear errors.
#include <haze/core/error.h>
#include <haze/core/rng.h>
#include <haze/froxels/froxels.h>
#include <haze/grids/methods.h>
#include <haze/particles/methods.h>

#include <gtest/gtest.h>

#include "scenes/fog_box.h"

#include <cmath>
#include <cstdio>
#include <limits>

namespace haze {
namespace {

using testing::fog_box;

std::vector<float> floor_depth(const Camera& camera) {
  std::vector<float> depth;
  for (int y = 0; y < camera.height_px; ++y)
    for (int x = 0; x < camera.width_px; ++x) {
      const Ray ray = camera.pixel_ray(x, y);
      depth.push_back(ray.direction.y < 0.0 ? static_cast<float>((-1.0 - ray.origin.y) / ray.direction.y) : std::numeric_limits<float>::infinity());
    }
  return depth;
}

// A host's colour over its floor: grey-brown where the depth ends the ray, sky beyond.
Image floor_and_sky(const std::vector<float>& depth, int width, int height) {
  Image host(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      host.set(x, y, std::isinf(depth[static_cast<size_t>(y * width + x)]) ? Rgb(0.05, 0.1, 0.2) : Rgb(0.3, 0.25, 0.2));
  return host;
}

// The per-pixel layers composited over the host: L_in + T host.
Image composited(const RenderResult& layers, const Image& host) {
  Image out(host.width(), host.height());
  for (int y = 0; y < host.height(); ++y)
    for (int x = 0; x < host.width(); ++x) out.set(x, y, layers.inscatter->at(x, y) + layers.transmittance->at(x, y) * host.at(x, y));
  return out;
}

double relative_to(const Rgb& a, const Rgb& b) { return glm::length(a - b) / std::max(glm::length(b), 1e-9); }

// With one column per pixel, the froxels at a slice boundary are the layers of a render with that
// boundary as every pixel's depth: the columns, the slices and the lookup line up, for every kind
// of solution (the network on its particle cloud; analytic's own path in a box and in unbounded
// fog, where its error is the table's relative to the whole ray's in-scatter). Propagation's and
// dom's one pass step each slice's stretch on its own, no finer than the columns' spacing there
// (12 columns: 5 of propagation's steps at the far slices), dom's through propagation's kernel with
// the moments' light toward the eye per cell (0.37% off its gather at worst here): held to 4e-3
// (dom against its gather at step 0.02 cells: its layered render 2.2e-3 off at the default step),
// not to 2e-4.
TEST(Froxels, HoldTheLayersAtColumnsAndBoundaries) {
  grids::register_methods();
  particles::register_methods();
  for (const std::string method : {"analytic", "unbounded analytic", "propagation", "dom", "network"}) {
    Scene scene = method == "network" ? Scene::load(std::string(HAZE_SOURCE_DIR) + "/examples/particle_cloud.json") : fog_box(12, 8);
    if (method == "unbounded analytic") scene.medium->bounds = Aabb{};
    scene.camera.width_px = 12, scene.camera.height_px = 8;
    RenderOptions options;
    if (method == "propagation") options.settings = {{"resolution", 16}};
    if (method == "dom") options.settings = {{"resolution", 12}, {"directions", 32}, {"terms", 9}};
    const Solution solution = prepare(scene, method == "unbounded analytic" ? "analytic" : method, options);
    const FroxelGrid grid{12, 8, 6, 0.5, 20.0};
    const Froxels froxels = build_froxels(solution, scene.camera, grid);
    const RenderResult whole = solution.render(View{scene.camera, {}, true});
    for (int k : {0, 3, 5}) {
      const std::vector<float> depth(96, static_cast<float>(grid.boundary(k)));
      const RenderResult r = solution.render(View{scene.camera, depth, true});
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 12; ++x) {
          const PixelLayers p = froxels.sample((x + 0.5) / 12.0, (y + 0.5) / 8.0, grid.boundary(k));
          const Rgb exact = r.inscatter->at(x, y);
          const double step_error = method == "dom" || method == "propagation" ? 4e-3 : 2e-4;
          ASSERT_LE(glm::length(p.inscatter - exact), step_error * glm::length(exact) + 1e-3 * glm::length(whole.inscatter->at(x, y)))
              << method << " slice " << k << " at " << x << ", " << y << ": " << p.inscatter.r << " against " << exact.r;
          ASSERT_LT(relative_to(p.transmittance, r.transmittance->at(x, y)), 2e-4) << method << " slice " << k << " at " << x << ", " << y;
        }
    }
  }
}

// The composite over a host's floor against the per-pixel layers, 96 x 64 pixels, the light above
// the view: the error falls as the froxels shrink (figures in docs/HOST.md; a light in view puts a
// glow narrower than a froxel on screen, which only finer columns resolve).
TEST(Froxels, CompositeConvergesToThePerPixelLayers) {
  const Scene scene = fog_box(96, 64, Vec3(0.5, 2.5, 0.3));
  const std::vector<float> depth = floor_depth(scene.camera);
  const Solution solution = prepare(scene, "analytic");
  const Image host = floor_and_sky(depth, 96, 64);
  const Image truth = composited(solution.render(View{scene.camera, depth, true}), host);
  double previous = kInfinity;
  for (const FroxelGrid& grid : {FroxelGrid{12, 8, 16, 0.5, 20.0}, FroxelGrid{24, 16, 32, 0.5, 20.0}, FroxelGrid{48, 32, 64, 0.5, 20.0}}) {
    const double error = relative_rmse(composite_froxels(build_froxels(solution, scene.camera, grid), host, depth), truth);
    std::printf("froxels %d x %d x %d for 96 x 64 pixels: composite relative RMS error %.2e\n", grid.nx, grid.ny, grid.nz, error);
    EXPECT_LT(error, 0.7 * previous);
    previous = error;
  }
  EXPECT_LT(previous, 0.02);
}

// A point light in view: its glow is narrower than a column, and the froxels alone are far off
// near it; with glow_columns the froxels leave each light's glow out and add_glow adds it per
// pixel in closed form.
TEST(Froxels, AddGlowMendsALightInView) {
  for (const bool unbounded : {false, true}) {
    Scene scene = fog_box(96, 64, Vec3(0.1, -0.1, 0.4));
    if (unbounded) scene.medium->bounds = Aabb{};  // the sky's rays never end
    const std::vector<float> depth = floor_depth(scene.camera);
    const Solution solution = prepare(scene, "analytic");
    const Image host = floor_and_sky(depth, 96, 64);
    const Image truth = composited(solution.render(View{scene.camera, depth, true}), host);
    double errors[2];
    for (int glow : {0, 1}) {
      FroxelGrid grid{24, 16, 32, 0.5, 20.0};
      grid.glow_columns = glow ? 4.0 : 0.0;
      const Froxels froxels = build_froxels(solution, scene.camera, grid);
      Image composite = composite_froxels(froxels, host, depth);
      add_glow(solution, scene.camera, froxels, depth, ImageSpan{composite.data().data(), 96, 64});
      errors[glow] = relative_rmse(composite, truth);
    }
    std::printf("a light in view (%s), froxels 24 x 16 x 32 for 96 x 64 pixels: composite %.2e off, with the glow added %.2e\n",
                unbounded ? "unbounded fog" : "fog box", errors[0], errors[1]);
    EXPECT_GT(errors[0], 0.2);
    EXPECT_LT(errors[1], 0.05);
  }
}

// The composite into the caller's memory (float32, rows over threads, RGBA rows with padding, in
// place over the colour) against Froxels::sample's float64 lookup, pixel by pixel, over depths
// before near, inside every slice, past far and the background; and for a single column and slice.
TEST(Froxels, CompositeIntoCallerMemoryMatchesTheFloat64Lookup) {
  Rng rng(7, 0);
  for (const FroxelGrid grid : {FroxelGrid{12, 7, 9, 0.2, 30.0}, FroxelGrid{1, 1, 1, 0.5, 5.0}}) {
    Froxels froxels;
    froxels.grid = grid;
    for (int n = 0; n < grid.nx * grid.ny * grid.nz; ++n) {
      froxels.inscatter.push_back(Vec3f(rng.uniform(), rng.uniform(), rng.uniform()));
      froxels.transmittance.push_back(Vec3f(rng.uniform(), rng.uniform(), rng.uniform()));
    }
    const int w = 37, h = 23;
    const size_t stride = 4 * w + 5;
    std::vector<float> rgba(stride * h), depth;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        for (int c = 0; c < 4; ++c) rgba[y * stride + 4 * x + c] = static_cast<float>(rng.uniform());
        const double u = rng.uniform();
        depth.push_back(u < 0.1 ? std::numeric_limits<float>::infinity() : static_cast<float>(0.1 * std::pow(400.0, u)));
      }
    const std::vector<float> before = rgba;
    const ImageSpan image{rgba.data(), w, h, 4, stride};
    composite_froxels(froxels, ConstImageSpan{rgba.data(), w, h, 4, stride}, depth, image, 2);
    double worst = 0.0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const float* c = &before[y * stride + 4 * x];
        const PixelLayers p = froxels.sample((x + 0.5) / w, (y + 0.5) / h, depth[static_cast<size_t>(y * w + x)]);
        const Rgb want = p.inscatter + p.transmittance * Rgb(c[0], c[1], c[2]);
        const float* got = image.pixel(x, y);
        worst = std::max(worst, relative_to(Rgb(got[0], got[1], got[2]), want));
        EXPECT_EQ(got[3], c[3]) << "alpha left as it is";
      }
    EXPECT_LT(worst, 1e-5) << grid.nx << " x " << grid.ny << " x " << grid.nz;
    for (size_t y = 0; y < static_cast<size_t>(h); ++y)
      for (size_t pad = 4 * w; pad < stride; ++pad) EXPECT_EQ(rgba[y * stride + pad], before[y * stride + pad]) << "row padding written";
  }
}

TEST(Froxels, BadSpansAreClearErrors) {
  Froxels froxels;
  froxels.grid = {2, 2, 2, 0.1, 10.0};
  froxels.inscatter.assign(8, Vec3f(0.0f)), froxels.transmittance.assign(8, Vec3f(1.0f));
  std::vector<float> colour(4 * 3 * 2), depth(4 * 2, 1.0f);
  auto message = [&](ConstImageSpan in, ImageSpan out, std::span<const float> d) {
    try {
      composite_froxels(froxels, in, d, out);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const ConstImageSpan in{colour.data(), 4, 2};
  const ImageSpan out{colour.data(), 4, 2};
  EXPECT_EQ(message(in, ImageSpan{colour.data(), 4, 2, 2}, depth), "out.channels: got 2, expected 3 (RGB) or 4 (RGBA)");
  EXPECT_EQ(message(in, ImageSpan{colour.data(), 4, 2, 3, 6}, depth), "out.stride: got 6 floats, expected at least width x channels = 12");
  EXPECT_EQ(message(in, ImageSpan{colour.data(), 3, 2}, depth), "out: got 3 x 2, expected the colour's size, 4 x 2");
  EXPECT_EQ(message(ConstImageSpan{nullptr, 4, 2}, out, depth), "colour: got 4 x 2 without data, expected an image of at least 1 x 1 pixels");
  EXPECT_EQ(message(in, out, std::span<const float>(depth).first(7)), "depth: got 7 values, expected one per pixel of the colour, 4 x 2");
}

TEST(Froxels, BadGridsAreClearErrors) {
  const Scene scene = fog_box(8, 8);
  const Solution solution = prepare(scene, "analytic");
  auto field = [&](const FroxelGrid& grid) {
    try {
      build_froxels(solution, scene.camera, grid);
    } catch (const Error& e) {
      return e.field();
    }
    return std::string("no error");
  };
  EXPECT_EQ(field({0, 8, 8, 0.1, 10.0}), "froxels.nx");
  EXPECT_EQ(field({8, 8, 5000, 0.1, 10.0}), "froxels.nz");
  EXPECT_EQ(field({8, 8, 8, 10.0, 10.0}), "froxels.near");
  EXPECT_EQ(field({8, 8, 8, 0.1, kInfinity}), "froxels.far");
  EXPECT_EQ(field({8, 8, 8, 0.1, 10.0, -1.0}), "froxels.glow_columns");
  // add_glow's output must be the view's size.
  const Froxels froxels = build_froxels(solution, scene.camera, FroxelGrid{8, 8, 8, 0.1, 10.0, 4.0});
  std::vector<float> small(3 * 4 * 4);
  try {
    add_glow(solution, scene.camera, froxels, {}, ImageSpan{small.data(), 4, 4});
    ADD_FAILURE() << "no error for a 4 x 4 output";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "out");
  }
}

}  // namespace
}  // namespace haze
