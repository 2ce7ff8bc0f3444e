// The froxel composite on the GPU (docs/HOST.md, "Froxels"): a froxel volume (haze/froxels/froxels.h) as
// two 3D textures streamed through Texture, and a fullscreen GLSL pass that reads the host's colour
// and depth textures and writes, per pixel, L_in(d) + T(d) * colour, the same lookup as
// Froxels::sample (trilinear: bilinear between columns, linear in the slice coordinate).
#pragma once

#include <haze/froxels/froxels.h>
#include <haze/core/image.h>
#include <haze/gl/texture.h>

#include <glm/mat4x4.hpp>

#include <memory>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::gl {

class FroxelComposite {
 public:
  // Needs a current HeadlessContext on the calling thread for its lifetime; compiles the pass
  // (a haze::Error with the driver's log if it fails). The froxel textures are stored in `format`.
  explicit FroxelComposite(TexelFormat format = TexelFormat::float16);
  ~FroxelComposite();
  FroxelComposite(const FroxelComposite&) = delete;
  FroxelComposite& operator=(const FroxelComposite&) = delete;

  // Streams the froxels into the textures (made anew when the grid's size changes).
  void upload(const Froxels& froxels);
  // Draws into the bound framebuffer over a width x height viewport. `colour`: the host's GL 2D
  // texture of its shading (RGB read); `depth`: its GL 2D texture of window depth (a depth
  // attachment, or R32F holding gl_FragCoord.z; 1 means nothing there); `projection`: the host's
  // projection (OpenGL conventions, as Camera::from_matrices), from which the pass takes each
  // pixel's distance along its ray. Throws haze::Error before any upload.
  void draw(unsigned colour, unsigned depth, const glm::dmat4& projection, int width, int height);
  // draw() into an offscreen RGBA32F target, read back with rows top to bottom.
  Image render(unsigned colour, unsigned depth, const glm::dmat4& projection, int width, int height);

  const Texture& inscatter() const;
  const Texture& transmittance() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace haze::gl

#pragma GCC visibility pop
