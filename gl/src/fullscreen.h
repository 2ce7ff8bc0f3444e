// What the display and the froxel composite share: a fullscreen-triangle program and an offscreen
// RGBA32F target read back with rows top to bottom (internal).
#pragma once

#include <haze/core/image.h>

#include "api.h"

namespace haze::gl::internal {

// The fullscreen vertex shader linked with `fragment`; haze::Error naming `what` with the driver's
// log when either does not compile or they do not link.
GLuint fullscreen_program(const Api& gl, const char* fragment, const char* what);

// An RGBA32F texture as a framebuffer's colour attachment, remade when the size changes.
struct OffscreenTarget {
  GLuint framebuffer = 0, texture = 0;
  int width = 0, height = 0;
  // Sized width x height and bound (GL_FRAMEBUFFER).
  void bind(const Api& gl, int w, int h, const char* what);
  // The attachment's pixels, rows top to bottom (GL's run bottom up).
  Image read(const Api& gl, const char* what) const;
  void release(const Api& gl);
};

}  // namespace haze::gl::internal
