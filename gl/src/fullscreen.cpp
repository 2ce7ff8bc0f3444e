#include "fullscreen.h"

#include <haze/core/error.h>

#include "march_shader.h"

#include <string>
#include <vector>

namespace haze::gl::internal {

namespace {

GLuint compile(const Api& gl, GLenum type, const char* source, const char* what) {
  const GLuint shader = gl.CreateShader(type);
  gl.ShaderSource(shader, 1, &source, nullptr);
  gl.CompileShader(shader);
  GLint ok = 0;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    gl.GetShaderInfoLog(shader, sizeof log, nullptr, log);
    gl.DeleteShader(shader);
    throw Error(type == GL_VERTEX_SHADER ? "vertex shader" : std::string(what) + " shader", log, "a shader this driver compiles");
  }
  return shader;
}

}  // namespace

GLuint fullscreen_program(const Api& gl, const char* fragment, const char* what) {
  const GLuint vs = compile(gl, GL_VERTEX_SHADER, kFullscreenVertexShader, what);
  GLuint fs = 0;
  try {
    fs = compile(gl, GL_FRAGMENT_SHADER, fragment, what);
  } catch (...) {
    gl.DeleteShader(vs);
    throw;
  }
  const GLuint program = gl.CreateProgram();
  gl.AttachShader(program, vs);
  gl.AttachShader(program, fs);
  gl.LinkProgram(program);
  gl.DeleteShader(vs);
  gl.DeleteShader(fs);
  GLint ok = 0;
  gl.GetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    gl.GetProgramInfoLog(program, sizeof log, nullptr, log);
    gl.DeleteProgram(program);
    throw Error(std::string(what) + " program", log, "a program this driver links");
  }
  return program;
}

void OffscreenTarget::bind(const Api& gl, int w, int h, const char* what) {
  if (w != width || h != height) {
    release(gl);
    gl.GenTextures(1, &texture);
    gl.BindTexture(GL_TEXTURE_2D, texture);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, w, h, 0, GL_RGBA, GL_FLOAT, nullptr);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.GenFramebuffers(1, &framebuffer);
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture, 0);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw Error(std::string(what) + " framebuffer", std::to_string(w) + " x " + std::to_string(h) + " RGBA32F incomplete", "a complete framebuffer");
    width = w, height = h;
  }
  gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer);
}

Image OffscreenTarget::read(const Api& gl, const char* what) const {
  std::vector<float> rgba(4 * static_cast<size_t>(width) * static_cast<size_t>(height));
  gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
  gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, rgba.data());
  check(gl, what);
  Image image(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float* p = &rgba[4 * (static_cast<size_t>(height - 1 - y) * static_cast<size_t>(width) + static_cast<size_t>(x))];
      image.set(x, y, Rgb(p[0], p[1], p[2]));
    }
  return image;
}

void OffscreenTarget::release(const Api& gl) {
  if (framebuffer) gl.DeleteFramebuffers(1, &framebuffer);
  if (texture) gl.DeleteTextures(1, &texture);
  framebuffer = texture = 0, width = height = 0;
}

}  // namespace haze::gl::internal
