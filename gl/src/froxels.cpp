// The GPU froxel composite (froxels.h): uploads, the pass's GLSL, the offscreen target.
#include <haze/gl/froxels.h>

#include <haze/core/error.h>

#include "api.h"
#include "march_shader.h"

#include <glm/matrix.hpp>

#include <cmath>
#include <optional>
#include <vector>

namespace haze::gl {

using internal::Api;

namespace {

constexpr const char* kCompositeShader = R"(#version 330 core
out vec4 out_color;
uniform vec2 viewport;
uniform sampler2D host_colour, host_depth;
uniform sampler3D froxel_inscatter, froxel_transmittance;
uniform mat4 projection_inverse;
uniform int perspective;
uniform float slices, near_distance, log_ratio;  // nz, near, log(far / near)

void main() {
  vec2 uv = gl_FragCoord.xy / viewport;  // GL rows bottom up
  vec3 colour = texture(host_colour, uv).rgb;
  float z = texture(host_depth, uv).r;
  // The distance along the pixel's ray (core/camera.h): from the eye (perspective) or the eye
  // plane (orthographic) to the point at window depth z; nothing there: past every slice.
  float d = 1e30;
  if (z < 1.0) {
    vec4 p = projection_inverse * vec4(2.0 * uv - 1.0, 2.0 * z - 1.0, 1.0);
    p /= p.w;
    d = perspective == 1 ? length(p.xyz) : -p.z;
  }
  // Froxels::sample: slice coordinate s, k at boundary k, -1 at near (L_in 0, T 1 there); texel
  // centres at s = k, so w = (s + 0.5) / nz; rows top to bottom, so v = 1 - uv.y.
  float s = d > near_distance ? min(slices * log(d / near_distance) / log_ratio - 1.0, slices - 1.0) : -1.0;
  vec3 at = vec3(uv.x, 1.0 - uv.y, (max(s, 0.0) + 0.5) / slices);
  vec3 l = texture(froxel_inscatter, at).rgb, t = texture(froxel_transmittance, at).rgb;
  if (s < 0.0) {
    l = mix(vec3(0.0), l, s + 1.0);
    t = mix(vec3(1.0), t, s + 1.0);
  }
  out_color = vec4(l + t * colour, 1.0);
}
)";

GLuint compile(const Api& gl, GLenum type, const char* source) {
  const GLuint shader = gl.CreateShader(type);
  gl.ShaderSource(shader, 1, &source, nullptr);
  gl.CompileShader(shader);
  GLint ok = 0;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    gl.GetShaderInfoLog(shader, sizeof log, nullptr, log);
    gl.DeleteShader(shader);
    throw Error(type == GL_VERTEX_SHADER ? "vertex shader" : "froxel composite shader", log, "a shader this driver compiles");
  }
  return shader;
}

}  // namespace

struct FroxelComposite::Impl {
  const Api& gl = internal::api();
  TexelFormat format;
  GLuint program = 0, vao = 0, framebuffer = 0, target = 0;
  int target_width = 0, target_height = 0;
  std::optional<Texture> inscatter, transmittance;
  FroxelGrid grid;

  ~Impl() {
    if (framebuffer) gl.DeleteFramebuffers(1, &framebuffer);
    if (target) gl.DeleteTextures(1, &target);
    if (vao) gl.DeleteVertexArrays(1, &vao);
    if (program) gl.DeleteProgram(program);
  }
  GLint at(const char* name) const { return gl.GetUniformLocation(program, name); }
};

FroxelComposite::FroxelComposite(TexelFormat format) : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  d.format = format;
  const GLuint vs = compile(d.gl, GL_VERTEX_SHADER, internal::kFullscreenVertexShader);
  const GLuint fs = compile(d.gl, GL_FRAGMENT_SHADER, kCompositeShader);
  d.program = d.gl.CreateProgram();
  d.gl.AttachShader(d.program, vs);
  d.gl.AttachShader(d.program, fs);
  d.gl.LinkProgram(d.program);
  d.gl.DeleteShader(vs);
  d.gl.DeleteShader(fs);
  GLint ok = 0;
  d.gl.GetProgramiv(d.program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    d.gl.GetProgramInfoLog(d.program, sizeof log, nullptr, log);
    throw Error("froxel composite program", log, "a program this driver links");
  }
  d.gl.GenVertexArrays(1, &d.vao);
  d.gl.UseProgram(d.program);
  d.gl.Uniform1i(d.at("host_colour"), 0);
  d.gl.Uniform1i(d.at("host_depth"), 1);
  d.gl.Uniform1i(d.at("froxel_inscatter"), 2);
  d.gl.Uniform1i(d.at("froxel_transmittance"), 3);
  internal::check(d.gl, "froxel composite setup");
}

FroxelComposite::~FroxelComposite() = default;

void FroxelComposite::upload(const Froxels& froxels) {
  Impl& d = *impl_;
  const FroxelGrid& g = froxels.grid;
  const std::array<int, 3> size{g.nx, g.ny, g.nz};
  if (!d.inscatter || d.inscatter->size() != size) {
    d.inscatter.emplace(Texture::volume(size, 3, d.format));
    d.transmittance.emplace(Texture::volume(size, 3, d.format));
  }
  auto values = [](const std::vector<Vec3f>& v) { return std::span<const float>(&v.data()->x, 3 * v.size()); };
  d.inscatter->upload(values(froxels.inscatter));
  d.transmittance->upload(values(froxels.transmittance));
  d.grid = g;
}

void FroxelComposite::draw(unsigned colour, unsigned depth, const glm::dmat4& projection, int width, int height) {
  Impl& d = *impl_;
  if (!d.inscatter) throw Error("froxels", "none uploaded", "FroxelComposite::upload before draw");
  const glm::mat4 inverse(glm::inverse(projection));
  d.gl.UseProgram(d.program);
  d.gl.Viewport(0, 0, width, height);
  d.gl.Uniform2f(d.at("viewport"), static_cast<float>(width), static_cast<float>(height));
  d.gl.UniformMatrix4fv(d.at("projection_inverse"), 1, GL_FALSE, &inverse[0][0]);
  d.gl.Uniform1i(d.at("perspective"), projection[2][3] != 0.0 ? 1 : 0);
  d.gl.Uniform1f(d.at("slices"), static_cast<float>(d.grid.nz));
  d.gl.Uniform1f(d.at("near_distance"), static_cast<float>(d.grid.near));
  d.gl.Uniform1f(d.at("log_ratio"), static_cast<float>(std::log(d.grid.far / d.grid.near)));
  const GLuint textures[] = {colour, depth, d.inscatter->id(), d.transmittance->id()};
  for (int unit = 0; unit < 4; ++unit) {
    d.gl.ActiveTexture(static_cast<GLenum>(GL_TEXTURE0 + unit));
    d.gl.BindTexture(unit < 2 ? GL_TEXTURE_2D : GL_TEXTURE_3D, textures[unit]);
  }
  d.gl.ActiveTexture(GL_TEXTURE0);
  d.gl.BindVertexArray(d.vao);
  d.gl.DrawArrays(GL_TRIANGLES, 0, 3);
  internal::check(d.gl, "froxel composite draw");
}

Image FroxelComposite::render(unsigned colour, unsigned depth, const glm::dmat4& projection, int width, int height) {
  Impl& d = *impl_;
  if (width != d.target_width || height != d.target_height) {
    if (d.framebuffer) d.gl.DeleteFramebuffers(1, &d.framebuffer);
    if (d.target) d.gl.DeleteTextures(1, &d.target);
    d.gl.GenTextures(1, &d.target);
    d.gl.BindTexture(GL_TEXTURE_2D, d.target);
    d.gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
    d.gl.GenFramebuffers(1, &d.framebuffer);
    d.gl.BindFramebuffer(GL_FRAMEBUFFER, d.framebuffer);
    d.gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, d.target, 0);
    if (d.gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw Error("froxel composite framebuffer", std::to_string(width) + " x " + std::to_string(height) + " RGBA32F incomplete", "a complete framebuffer");
    d.target_width = width, d.target_height = height;
  }
  d.gl.BindFramebuffer(GL_FRAMEBUFFER, d.framebuffer);
  draw(colour, depth, projection, width, height);
  std::vector<float> rgba(4 * static_cast<size_t>(width) * static_cast<size_t>(height));
  d.gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
  d.gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  d.gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, rgba.data());
  internal::check(d.gl, "froxel composite read-back");
  Image image(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float* p = &rgba[4 * (static_cast<size_t>(height - 1 - y) * static_cast<size_t>(width) + static_cast<size_t>(x))];
      image.set(x, y, Rgb(p[0], p[1], p[2]));
    }
  return image;
}

const Texture& FroxelComposite::inscatter() const { return *impl_->inscatter; }
const Texture& FroxelComposite::transmittance() const { return *impl_->transmittance; }

}  // namespace haze::gl
