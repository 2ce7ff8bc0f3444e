// The GPU froxel composite (gl/froxels.h) against its CPU form (composite_froxels): the host's
// colour and window depth as GL textures, the froxels streamed as 3D textures, the same image.
#include <haze/core/error.h>
#include <haze/froxels/froxels.h>
#include <haze/gl/context.h>
#include <haze/gl/froxels.h>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/trigonometric.hpp>
#include <gtest/gtest.h>

#include "scenes/fog_box.h"

#include <limits>

namespace haze::gl {
namespace {

TEST(FroxelComposite, MatchesTheCpuComposite) {
  HeadlessContext context;
  constexpr int w = 48, h = 32;
  Scene scene = haze::testing::fog_box(w, h, Vec3(0.5, 2.5, 0.3));
  const glm::dmat4 view = glm::lookAt(Vec3(0.2, 0.6, 5.0), Vec3(0.0, -0.4, 0.0), Vec3(0.0, 1.0, 0.0));
  const glm::dmat4 projection = glm::perspective(glm::radians(40.0), double(w) / h, 0.1, 100.0);
  const Camera camera = Camera::from_matrices(view, projection, w, h);
  scene.camera = camera;
  const Froxels froxels = build_froxels(prepare(scene, "analytic"), camera, {24, 16, 16, 0.5, 20.0});

  // The host: a floor at y = -1 in a checker of two colours, the sky blue; its window depth.
  Image colour(w, h);
  std::vector<float> distance, gl_colour(3 * w * h), gl_depth(w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Ray ray = camera.pixel_ray(x, y);
      const double t = ray.direction.y < 0.0 ? (-1.0 - ray.origin.y) / ray.direction.y : kInfinity;
      distance.push_back(static_cast<float>(t));
      const Vec3 p = ray.at(std::isfinite(t) ? t : 0.0);
      const Rgb c = std::isfinite(t) ? ((int(std::floor(p.x)) + int(std::floor(p.z))) % 2 ? Rgb(0.6, 0.5, 0.4) : Rgb(0.2, 0.3, 0.2)) : Rgb(0.1, 0.2, 0.4);
      colour.set(x, y, c);
      // GL rows bottom up; window depth from the clip position of the point.
      const size_t gl_at = static_cast<size_t>(h - 1 - y) * w + static_cast<size_t>(x);
      for (int k = 0; k < 3; ++k) gl_colour[3 * gl_at + static_cast<size_t>(k)] = static_cast<float>(c[k]);
      const glm::dvec4 clip = projection * view * glm::dvec4(p, 1.0);
      gl_depth[gl_at] = std::isfinite(t) ? static_cast<float>(0.5 * clip.z / clip.w + 0.5) : 1.0f;
    }
  Texture colour_texture = Texture::plane(w, h, 3, TexelFormat::float32), depth_texture = Texture::plane(w, h, 1, TexelFormat::float32);
  colour_texture.upload(gl_colour);
  depth_texture.upload(gl_depth);
  const Image cpu = composite_froxels(froxels, colour, distance);
  for (TexelFormat format : {TexelFormat::float32, TexelFormat::float16}) {
    FroxelComposite composite(format);
    composite.upload(froxels);
    const Image gpu = composite.render(colour_texture.id(), depth_texture.id(), projection, w, h);
    // float16 froxels hold 11 significant bits; float32 ones differ by the window depth's rounding.
    const double tolerance = format == TexelFormat::float16 ? 3e-3 : 5e-4;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        ASSERT_LT(glm::length(gpu.at(x, y) - cpu.at(x, y)), tolerance * glm::length(cpu.at(x, y)))
            << name(format) << " at " << x << ", " << y << ": " << gpu.at(x, y).r << " against " << cpu.at(x, y).r;
  }
  FroxelComposite empty;
  EXPECT_THROW(empty.draw(colour_texture.id(), depth_texture.id(), projection, w, h), Error);
}

}  // namespace
}  // namespace haze::gl
