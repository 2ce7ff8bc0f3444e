// A host renderer with Haze's fog (docs/HOST.md): it rasterizes its own room (room.obj, a window
// in one wall, the sun outside) with OpenGL, hands its camera matrices to Haze, and composites
// Haze's froxels over its own colour and depth on the GPU. Headless (EGL, or OSMesa/llvmpipe).
//
//   host_example [--scene room.json] [--out room.png] [--width 320] [--height 180]
//                [--check SPP]   also render the reference path tracer's single scattering of the
//                                same view and print the fog's error against it: exit 1 if the RMS
//                                relative error (the reference's noise removed) is above
//                                --tolerance (default 0.45) or the means differ by more than 3%
//                                (docs/HOST.md gives the figures)
#include <haze/core/error.h>
#include <haze/froxels/froxels.h>
#include <haze/core/image.h>
#include <haze/gl/context.h>
#include <haze/gl/froxels.h>
#include <haze/all.h>

#include <GL/glcorearb.h>
#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/trigonometric.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

// The GL entry points the host draws with, from Haze's headless context.
#define HOST_GL(X)                                                                                       \
  X(PFNGLGENBUFFERSPROC, GenBuffers) X(PFNGLBINDBUFFERPROC, BindBuffer) X(PFNGLBUFFERDATAPROC, BufferData) \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays) X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer) X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray) \
  X(PFNGLCREATESHADERPROC, CreateShader) X(PFNGLSHADERSOURCEPROC, ShaderSource) X(PFNGLCOMPILESHADERPROC, CompileShader) \
  X(PFNGLGETSHADERIVPROC, GetShaderiv) X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                      \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram) X(PFNGLATTACHSHADERPROC, AttachShader) X(PFNGLLINKPROGRAMPROC, LinkProgram) \
  X(PFNGLUSEPROGRAMPROC, UseProgram) X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                     \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv) X(PFNGLUNIFORM3FPROC, Uniform3f) X(PFNGLUNIFORM1FPROC, Uniform1f) \
  X(PFNGLGENTEXTURESPROC, GenTextures) X(PFNGLBINDTEXTUREPROC, BindTexture) X(PFNGLTEXIMAGE2DPROC, TexImage2D) \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri) X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                    \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer) X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)      \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus) X(PFNGLVIEWPORTPROC, Viewport)                \
  X(PFNGLCLEARCOLORPROC, ClearColor) X(PFNGLCLEARPROC, Clear) X(PFNGLENABLEPROC, Enable) X(PFNGLDISABLEPROC, Disable) \
  X(PFNGLDRAWARRAYSPROC, DrawArrays) X(PFNGLFINISHPROC, Finish)

struct Gl {
#define HOST_GL_DECLARE(type, name) type name = nullptr;
  HOST_GL(HOST_GL_DECLARE)
#undef HOST_GL_DECLARE
  explicit Gl(const haze::gl::HeadlessContext& context) {
#define HOST_GL_LOAD(type, name)                                                          \
  name = reinterpret_cast<type>(context.proc_address("gl" #name));                        \
  if (!name) throw haze::Error("gl entry point", "gl" #name, "one the context's driver has");
    HOST_GL(HOST_GL_LOAD)
#undef HOST_GL_LOAD
  }
};

const char* kVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
uniform mat4 view_projection;
out vec3 world;
void main() { world = position; gl_Position = view_projection * vec4(position, 1.0); }
)";

// The host's own shading: Lambert walls lit by the sun where it comes through the window (the
// window's rectangle in the plane x = 2 is the only opening), plus a little ambient light.
const char* kFragment = R"(#version 330 core
in vec3 world;
out vec4 colour;
uniform vec3 eye, to_sun, sun, albedo;
void main() {
  vec3 n = normalize(cross(dFdx(world), dFdy(world)));
  if (dot(n, eye - world) < 0.0) n = -n;
  float lit = 0.0;
  if (to_sun.x > 0.0 && world.x < 1.999) {
    vec3 at = world + to_sun * ((2.0 - world.x) / to_sun.x);
    lit = float(at.y > 1.2 && at.y < 2.0 && at.z > -0.6 && at.z < 0.6);
  }
  vec3 direct = albedo / 3.14159265 * sun * max(dot(n, to_sun), 0.0) * lit;
  colour = vec4(direct + 0.03 * albedo, 1.0);
}
)";

GLuint compile(const Gl& gl, GLenum type, const char* source) {
  const GLuint shader = gl.CreateShader(type);
  gl.ShaderSource(shader, 1, &source, nullptr);
  gl.CompileShader(shader);
  GLint ok = 0;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    gl.GetShaderInfoLog(shader, sizeof log, nullptr, log);
    throw haze::Error("host shader", log, "a shader the driver compiles");
  }
  return shader;
}

// A texture of the given format as a framebuffer attachment.
GLuint attachment(const Gl& gl, GLint internal, GLenum format, int w, int h, GLenum point) {
  GLuint t = 0;
  gl.GenTextures(1, &t);
  gl.BindTexture(GL_TEXTURE_2D, t);
  gl.TexImage2D(GL_TEXTURE_2D, 0, internal, w, h, 0, format, GL_FLOAT, nullptr);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  gl.FramebufferTexture2D(GL_FRAMEBUFFER, point, GL_TEXTURE_2D, t, 0);
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene_file = HAZE_HOST_EXAMPLE_DIR "/room.json", out = "room.png";
  int width = 320, height = 180;
  long long check_spp = 0;
  double tolerance = 0.45;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--scene") scene_file = value;
    else if (flag == "--out") out = value;
    else if (flag == "--width") width = std::atoi(value.c_str());
    else if (flag == "--height") height = std::atoi(value.c_str());
    else if (flag == "--check") check_spp = std::atoll(value.c_str());
    else if (flag == "--tolerance") tolerance = std::atof(value.c_str());
    else {
      std::fprintf(stderr, "unknown option %s\n", flag.c_str());
      return 2;
    }
  }
  try {
    haze::register_all();
    haze::Scene scene = haze::Scene::load(scene_file);
    scene.camera.width_px = width, scene.camera.height_px = height;
    const haze::Camera& c = scene.camera;
    // The host's matrices (what it rasterizes with) and Haze's camera from them.
    const glm::dmat4 view = glm::lookAt(c.position, c.look_at, c.up);
    const glm::dmat4 projection = glm::perspective(glm::radians(c.fov_y_deg), double(width) / height, 0.05, 50.0);
    const haze::Camera host_camera = haze::Camera::from_matrices(view, projection, width, height);

    // 1. The host draws its room: colour and window depth into textures.
    haze::gl::HeadlessContext context;
    const Gl gl(context);
    const auto& room = std::get<haze::Mesh>(scene.surfaces.at(0).shape).triangles;
    std::vector<float> vertices;
    for (size_t t = 0; t < room->triangle_count(); ++t)
      for (int k = 0; k < 3; ++k)
        for (int e = 0; e < 3; ++e) vertices.push_back(static_cast<float>(room->vertex(t, k)[e]));
    GLuint vao = 0, vbo = 0, framebuffer = 0;
    gl.GenVertexArrays(1, &vao);
    gl.BindVertexArray(vao);
    gl.GenBuffers(1, &vbo);
    gl.BindBuffer(GL_ARRAY_BUFFER, vbo);
    gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(float)), vertices.data(), GL_STATIC_DRAW);
    gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    gl.EnableVertexAttribArray(0);
    const GLuint program = gl.CreateProgram();
    gl.AttachShader(program, compile(gl, GL_VERTEX_SHADER, kVertex));
    gl.AttachShader(program, compile(gl, GL_FRAGMENT_SHADER, kFragment));
    gl.LinkProgram(program);
    gl.GenFramebuffers(1, &framebuffer);
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    const GLuint colour = attachment(gl, GL_RGBA32F, GL_RGBA, width, height, GL_COLOR_ATTACHMENT0);
    const GLuint depth = attachment(gl, GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, width, height, GL_DEPTH_ATTACHMENT);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) throw haze::Error("host framebuffer", "incomplete", "a complete one");
    gl.Viewport(0, 0, width, height);
    gl.ClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    gl.Enable(GL_DEPTH_TEST);
    gl.UseProgram(program);
    const glm::mat4 view_projection(projection * view);
    gl.UniformMatrix4fv(gl.GetUniformLocation(program, "view_projection"), 1, GL_FALSE, glm::value_ptr(view_projection));
    const auto& sun = std::get<haze::DirectionalLight>(scene.lights.at(0));
    const glm::vec3 to_sun(-glm::normalize(sun.direction)), eye(c.position);
    gl.Uniform3f(gl.GetUniformLocation(program, "eye"), eye.x, eye.y, eye.z);
    gl.Uniform3f(gl.GetUniformLocation(program, "to_sun"), to_sun.x, to_sun.y, to_sun.z);
    gl.Uniform3f(gl.GetUniformLocation(program, "sun"), float(sun.irradiance.r), float(sun.irradiance.g), float(sun.irradiance.b));
    gl.Uniform3f(gl.GetUniformLocation(program, "albedo"), 0.6f, 0.55f, 0.5f);
    gl.DrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(vertices.size() / 3));
    gl.Disable(GL_DEPTH_TEST);
    gl.Finish();

    // 2. Haze: one solution of the fog (the room shadows it: a mesh Haze does not shade), its
    // froxels for the host's camera, composited over the host's colour and depth on the GPU.
    const haze::Solution fog = haze::prepare(scene);  // the scene's method: propagation
    const haze::Froxels froxels = haze::build_froxels(fog, host_camera, {width / 2, height / 2, 64, 0.1, 10.0});
    haze::gl::FroxelComposite pass;
    pass.upload(froxels);
    const haze::Image frame = pass.render(colour, depth, projection, width, height);
    haze::write_png(out, frame);
    std::printf("host_example: %d x %d, %s, froxels %d x %d x %d -> %s\n", width, height, context.info().backend.c_str(), froxels.grid.nx,
                froxels.grid.ny, froxels.grid.nz, out.c_str());
    if (check_spp <= 0) return 0;

    // 3. The fog alone (composited over black) against the reference path tracer's single
    // scattering of the same scene, whose room is black to Haze: its image is the fog's.
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    gl.Clear(GL_COLOR_BUFFER_BIT);
    const haze::Image fog_only = pass.render(colour, depth, projection, width, height);
    haze::RenderOptions reference;
    reference.settings = {{"spp", check_spp}, {"max_scattering", 1}, {"seed", 3}};
    scene.camera = host_camera;
    const haze::RenderResult truth = haze::render(scene, "reference", reference);
    const haze::LitPixelError error = haze::lit_pixel_error(fog_only, truth.radiance, &*truth.std_error);
    std::printf("fog against the reference (single scattering, %lld spp): RMS relative error %.3f with the reference's noise "
                "(%.3f) removed, mean %.4f against %.4f\n",
                check_spp, error.rms_noise_removed, error.noise_rms, fog_only.mean().r, truth.radiance.mean().r);
    const double mean_error = std::abs(fog_only.mean().r / truth.radiance.mean().r - 1.0);
    return error.rms_noise_removed <= tolerance && mean_error <= 0.03 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "host_example: %s\n", e.what());
    return 1;
  }
}
