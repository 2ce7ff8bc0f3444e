// The GPU froxel composite (froxels.h): uploads, the pass's GLSL, the offscreen target.
#include <haze/gl/froxels.h>

#include <haze/core/error.h>

#include "api.h"
#include "fullscreen.h"

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

}  // namespace

struct FroxelComposite::Impl {
  const Api& gl = internal::api();
  TexelFormat format;
  GLuint program = 0, vao = 0;
  internal::OffscreenTarget target;
  std::optional<Texture> inscatter, transmittance;
  FroxelGrid grid;

  ~Impl() {
    target.release(gl);
    if (vao) gl.DeleteVertexArrays(1, &vao);
    if (program) gl.DeleteProgram(program);
  }
  GLint at(const char* name) const { return gl.GetUniformLocation(program, name); }
};

FroxelComposite::FroxelComposite(TexelFormat format) : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  d.format = format;
  d.program = internal::fullscreen_program(d.gl, kCompositeShader, "froxel composite");
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
  d.target.bind(d.gl, width, height, "froxel composite");
  draw(colour, depth, projection, width, height);
  return d.target.read(d.gl, "froxel composite read-back");
}

const Texture& FroxelComposite::inscatter() const { return *impl_->inscatter; }
const Texture& FroxelComposite::transmittance() const { return *impl_->transmittance; }

}  // namespace haze::gl
