// The GLSL ray-march display (display.h): uploads, uniforms, the offscreen framebuffer, read-back.
#include <haze/gl/display.h>

#include <haze/core/error.h>
#include <haze/core/progress.h>
#include <haze/simd/phase_params.h>

#include "api.h"
#include "fullscreen.h"
#include "march_shader.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace haze::gl {

using grids::DenseGrid;
using internal::Api;

namespace {

// Texture units, one per sampler: samplers of different types may not share a unit.
enum Unit : int { kDensityUnit = 0, kDepthUnit = 1, kPhaseUnit = 5, kMomentsUnit = 6, kWeightsUnit = 7, kVisibilityUnit = 8, kAtlasUnit = 12, kEmissionUnit = 13 };

float f(double v) { return static_cast<float>(v); }

}  // namespace

struct VolumeDisplay::Impl {
  const Api& gl = internal::api();
  DisplaySettings settings;
  Scene scene;  // its delta lights only; sky radiance folded into the background
  std::array<int, 3> cells{1, 1, 1};
  Aabb bounds;
  Rgb sigma_t{1.0}, albedo{0.8};
  PhaseFunction phase;
  std::optional<Texture> density, phase_table, moments, weights, surface_atlas, emission;
  Rgb sky{0.0};  // the sky's radiance, for the surfaces' texels (E_s = pi sky where they have none)
  // Bound to the units of samplers the scene does not use: a unit without a complete texture of
  // its sampler's type is undefined on some drivers.
  std::optional<Texture> unused_plane, unused_volume;
  std::vector<Texture> depths;      // ceil(lights / 4) RGBA volumes (at least one)
  std::vector<Texture> visibility;  // the same for the surfaces' shadows (grids::surface_visibility); none without surfaces
  std::vector<float> packed;        // scratch: interleaved values of one group
  // Multiple scattering: the solution (moments dropped) for the weights, and the camera they are for.
  std::optional<grids::DomSolution> dom;
  int ms_groups = 0;
  std::optional<Camera> weights_camera;
  GLuint program = 0, vao = 0;
  internal::OffscreenTarget target;

  ~Impl() {
    target.release(gl);
    if (vao) gl.DeleteVertexArrays(1, &vao);
    if (program) gl.DeleteProgram(program);
  }

  GLint at(const char* name) const { return gl.GetUniformLocation(program, name); }

  void check_grid(const DenseGrid& grid, const std::string& field) const {
    if (grid.resolution() != cells)
      throw Error(field, "a " + std::to_string(grid.resolution()[0]) + " x " + std::to_string(grid.resolution()[1]) + " x " +
                             std::to_string(grid.resolution()[2]) + " grid",
                  "the density's " + std::to_string(cells[0]) + " x " + std::to_string(cells[1]) + " x " + std::to_string(cells[2]) + " cells");
  }

  // Four lights' volumes a texture, in r, g, b, a.
  void upload_groups(const std::vector<DenseGrid>& grids, std::vector<Texture>& textures, std::span<const Brick> bricks) {
    const size_t n = static_cast<size_t>(cells[0]) * static_cast<size_t>(cells[1]) * static_cast<size_t>(cells[2]);  // zeros for no lights
    for (size_t g = 0; g < textures.size(); ++g) {
      packed.assign(4 * n, 0.0f);
      for (size_t c = 0; c < 4 && 4 * g + c < grids.size(); ++c) {
        const std::vector<float>& v = grids[4 * g + c].values();
        for (size_t i = 0; i < n; ++i) packed[4 * i + c] = v[i];
      }
      if (bricks.empty()) textures[g].upload(packed);
      else textures[g].upload(packed, bricks);
    }
  }

  void upload_depths(const std::vector<DenseGrid>& grids, std::span<const Brick> bricks) {
    if (grids.size() != scene.lights.size())
      throw Error("depths", std::to_string(grids.size()) + " volumes",
                  "one per point, spot or directional light (" + std::to_string(scene.lights.size()) + ")");
    for (size_t l = 0; l < grids.size(); ++l) check_grid(grids[l], "depths[" + std::to_string(l) + "]");
    upload_groups(grids, depths, bricks);
  }

  // The surfaces' shadows in the medium, as the CPU marchers compute them.
  void upload_visibility(const grids::DenseGrid& like) {
    const std::vector<DenseGrid> v = grids::surface_visibility(like, scene.lights, scene.surfaces);
    if (v.empty()) return;
    if (visibility.empty())
      for (size_t g = 0; g < depths.size(); ++g) visibility.push_back(Texture::volume(cells, 4, TexelFormat::float32));
    upload_groups(v, visibility, {});
  }

  // Emission: what follows the density as a uniform, the rest (a grid of its own, blackbody) as an
  // RGB volume at the cell centres, so that update_density changes the glow with the density.
  void upload_emission(const Emission& e) {
    gl.UseProgram(program);
    const Rgb per_density = e.strength > 0.0 && !e.grid ? e.strength * e.color : Rgb(0.0);
    gl.Uniform3f(at("emission_per_density"), f(per_density.r), f(per_density.g), f(per_density.b));
    gl.Uniform1i(at("emission_on"), e.beyond_density() ? 1 : 0);
    if (!e.beyond_density()) return;
    Emission rest = e;
    if (!e.grid) rest.strength = 0.0;
    const Vec3 h = bounds.extent() / Vec3(cells[0], cells[1], cells[2]);
    std::vector<float> values(4 * static_cast<size_t>(cells[0]) * static_cast<size_t>(cells[1]) * static_cast<size_t>(cells[2]), 0.0f);
    size_t i = 0;
    for (int z = 0; z < cells[2]; ++z)
      for (int y = 0; y < cells[1]; ++y)
        for (int x = 0; x < cells[0]; ++x, i += 4) {
          const Rgb le = emitted_radiance(rest, bounds.lo + h * Vec3(x + 0.5, y + 0.5, z + 0.5), 0.0);
          for (int c = 0; c < 3; ++c) values[i + static_cast<size_t>(c)] = f(le[c]);
        }
    emission.emplace(Texture::volume(cells, 4, TexelFormat::float32));
    emission->upload(values);
  }

  void set_static_uniforms() {
    gl.UseProgram(program);
    gl.Uniform3f(at("box_lo"), f(bounds.lo.x), f(bounds.lo.y), f(bounds.lo.z));
    gl.Uniform3f(at("box_hi"), f(bounds.hi.x), f(bounds.hi.y), f(bounds.hi.z));
    gl.Uniform3i(at("cells"), cells[0], cells[1], cells[2]);
    const Vec3 h = bounds.extent() / Vec3(cells[0], cells[1], cells[2]);
    gl.Uniform1f(at("step_length"), f(settings.step_cells * std::min({h.x, h.y, h.z})));
    gl.Uniform1i(at("density"), kDensityUnit);
    const char* depth_names[] = {"depths0", "depths1", "depths2", "depths3"};
    for (int g = 0; g < 4; ++g) gl.Uniform1i(at(depth_names[g]), kDepthUnit + g);
    const char* visibility_names[] = {"visibility0", "visibility1", "visibility2", "visibility3"};
    for (int g = 0; g < 4; ++g) gl.Uniform1i(at(visibility_names[g]), kVisibilityUnit + g);
    gl.Uniform1i(at("shadows"), visibility.empty() ? 0 : 1);
    gl.Uniform1i(at("phase_table"), kPhaseUnit);
    gl.Uniform1i(at("moments"), kMomentsUnit);
    gl.Uniform1i(at("weights"), kWeightsUnit);
    gl.Uniform1i(at("surface_atlas"), kAtlasUnit);
    gl.Uniform1i(at("emission"), kEmissionUnit);
    gl.Uniform1i(at("surface_texels_on"), 0);
    set_phase();
    set_lights();
    set_surfaces();
    set_coefficients(sigma_t, sigma_t, albedo, Rgb(0.0));
    gl.Uniform1i(at("ms_groups"), 0);
    gl.Uniform1i(at("ms_channels"), 1);
  }

  void set_coefficients(const Rgb& view, const Rgb& light, const Rgb& single, const Rgb& ms) {
    gl.UseProgram(program);
    auto set = [&](const char* name, const Rgb& c) { gl.Uniform3f(at(name), f(c.r), f(c.g), f(c.b)); };
    set("sigma_t_view", view);
    set("sigma_t_light", light);
    set("albedo_single", single);
    set("albedo_ms", ms);
    set("background", scene.background);
  }

  // The phase function in the SIMD kernels' constants (haze/simd/phase_params.h), or its table.
  void set_phase() {
    simd::PhaseParams p;
    int lobes = -1;
    if (simd::params_for(phase, p)) {
      lobes = p.lobes;
    } else {
      const std::vector<double>& table = phase.parameters<PhaseFunction::Tabulated>()->values;
      std::vector<float> values(table.begin(), table.end());
      phase_table.emplace(Texture::plane(static_cast<int>(values.size()), 1, 1, TexelFormat::float32));
      phase_table->upload(values);
      gl.Uniform1i(at("phase_table_size"), static_cast<int>(values.size()));
    }
    gl.Uniform1i(at("phase_lobes"), lobes);
    gl.Uniform1f(at("phase_c0"), p.c0);
    gl.Uniform1f(at("phase_c2"), p.c2);
    gl.Uniform2f(at("phase_k"), p.k[0], p.k[1]);
    gl.Uniform2f(at("phase_a"), p.a[0], p.a[1]);
    gl.Uniform2f(at("phase_b"), p.b[0], p.b[1]);
    gl.Uniform2f(at("phase_s"), p.s[0], p.s[1]);
  }

  void set_lights() {
    const int n = static_cast<int>(scene.lights.size());
    int type[kMaxLights] = {};
    float position[3 * kMaxLights] = {}, axis[3 * kMaxLights] = {}, intensity[3 * kMaxLights] = {}, cos_cone[kMaxLights] = {},
          exponent[kMaxLights] = {};
    auto put = [](float* to, int i, const Vec3& v) {
      for (int e = 0; e < 3; ++e) to[3 * i + e] = f(v[e]);
    };
    for (int i = 0; i < n; ++i) {
      const Light& light = scene.lights[static_cast<size_t>(i)];
      if (const auto* p = std::get_if<PointLight>(&light)) {
        type[i] = 0, put(position, i, p->position), put(intensity, i, p->intensity);
      } else if (const auto* s = std::get_if<SpotLight>(&light)) {
        type[i] = 1, put(position, i, s->position), put(axis, i, s->direction), put(intensity, i, s->intensity);
        cos_cone[i] = f(std::cos(s->cone_deg * kPi / 180.0)), exponent[i] = f(s->exponent);
      } else if (const auto* d = std::get_if<DirectionalLight>(&light)) {
        type[i] = 2, put(axis, i, -d->direction), put(intensity, i, d->irradiance);
      }
    }
    gl.Uniform1i(at("light_count"), n);
    gl.Uniform1iv(at("light_type"), kMaxLights, type);
    gl.Uniform3fv(at("light_position"), kMaxLights, position);
    gl.Uniform3fv(at("light_axis"), kMaxLights, axis);
    gl.Uniform3fv(at("light_intensity"), kMaxLights, intensity);
    gl.Uniform1fv(at("light_cos_cone"), kMaxLights, cos_cone);
    gl.Uniform1fv(at("light_exponent"), kMaxLights, exponent);
  }

  void set_surfaces() {
    const int n = static_cast<int>(scene.surfaces.size());
    int type[kMaxSurfaces] = {};
    float shape[4 * kMaxSurfaces] = {}, kd[3 * kMaxSurfaces] = {}, ks[3 * kMaxSurfaces] = {}, shininess[kMaxSurfaces] = {};
    for (int i = 0; i < n; ++i) {
      const Surface& s = scene.surfaces[static_cast<size_t>(i)];
      Vec3 v;
      double w;
      if (const auto* plane = std::get_if<Plane>(&s.shape)) {
        type[i] = 0, v = plane->normal, w = glm::dot(plane->normal, plane->point);
      } else {
        const auto& sphere = std::get<Sphere>(s.shape);
        type[i] = 1, v = sphere.center, w = sphere.radius;
      }
      for (int e = 0; e < 3; ++e) shape[4 * i + e] = f(v[e]), kd[3 * i + e] = f(s.kd[e]), ks[3 * i + e] = f(s.ks[e]);
      shape[4 * i + 3] = f(w), shininess[i] = f(s.shininess);
    }
    gl.Uniform1i(at("surface_count"), n);
    gl.Uniform1iv(at("surface_type"), kMaxSurfaces, type);
    gl.Uniform4fv(at("surface_shape"), kMaxSurfaces, shape);
    gl.Uniform3fv(at("surface_kd"), kMaxSurfaces, kd);
    gl.Uniform3fv(at("surface_ks"), kMaxSurfaces, ks);
    gl.Uniform1fv(at("surface_shininess"), kMaxSurfaces, shininess);
  }

  // The DOM's surface texels as rows of one RGBA float atlas, with each surface's frame.
  void upload_surface_texels(const grids::SurfaceTexels* texels) {
    gl.UseProgram(program);
    gl.Uniform1i(at("surface_texels_on"), texels ? 1 : 0);
    if (!texels) return;
    float map[4 * kMaxSurfaces] = {}, origin[4 * kMaxSurfaces] = {}, u[4 * kMaxSurfaces] = {}, v[4 * kMaxSurfaces] = {};
    int width = 1, rows = 0;
    for (size_t i = 0; i < scene.surfaces.size() && i < texels->planes.size(); ++i) {
      width = std::max({width, texels->planes[i].nu, texels->spheres[i].np});
      rows += texels->planes[i].values.empty() ? texels->spheres[i].nt : texels->planes[i].nv;
    }
    std::vector<float> atlas(4 * static_cast<size_t>(width) * static_cast<size_t>(std::max(1, rows)), 0.0f);
    int row = 0;
    for (size_t i = 0; i < scene.surfaces.size() && i < texels->planes.size(); ++i) {
      const auto& r = texels->planes[i];
      const auto& g = texels->spheres[i];
      const bool plane = !r.values.empty();
      if (!plane && g.values.empty()) continue;
      const int columns = plane ? r.nu : g.np, count = plane ? r.nv : g.nt;
      const std::vector<Rgb>& values = plane ? r.values : g.values;
      for (int y = 0; y < count; ++y)
        for (int x = 0; x < columns; ++x)
          for (int c = 0; c < 3; ++c)
            atlas[4 * (static_cast<size_t>(row + y) * static_cast<size_t>(width) + static_cast<size_t>(x)) + static_cast<size_t>(c)] =
                f(values[static_cast<size_t>(y) * static_cast<size_t>(columns) + static_cast<size_t>(x)][c]);
      const size_t k = 4 * i;
      map[k] = plane ? 1.0f : 2.0f, map[k + 1] = static_cast<float>(row), map[k + 2] = static_cast<float>(columns), map[k + 3] = static_cast<float>(count);
      const Vec3 o = plane ? r.origin : g.centre;
      for (int e = 0; e < 3; ++e) origin[k + static_cast<size_t>(e)] = f(o[e]), u[k + static_cast<size_t>(e)] = f(r.u[e]), v[k + static_cast<size_t>(e)] = f(r.v[e]);
      origin[k + 3] = f(r.size), u[k + 3] = f(r.u0), v[k + 3] = f(r.v0);
      row += count;
    }
    surface_atlas.emplace(Texture::plane(width, std::max(1, rows), 4, TexelFormat::float32));
    surface_atlas->upload(atlas);
    gl.Uniform4fv(at("surface_map"), kMaxSurfaces, map);
    gl.Uniform4fv(at("surface_map_o"), kMaxSurfaces, origin);
    gl.Uniform4fv(at("surface_map_u"), kMaxSurfaces, u);
    gl.Uniform4fv(at("surface_map_v"), kMaxSurfaces, v);
    gl.Uniform3f(at("sky"), f(sky.r), f(sky.g), f(sky.b));
  }

  void set_camera(const Camera& c) {
    const Vec3 forward = glm::normalize(c.look_at - c.position);
    const Vec3 right = glm::normalize(glm::cross(forward, c.up));
    const Vec3 up = glm::cross(right, forward);
    auto set = [&](const char* name, const Vec3& v) { gl.Uniform3f(at(name), f(v.x), f(v.y), f(v.z)); };
    gl.Uniform2f(at("film"), f(c.width_px), f(c.height_px));
    gl.Uniform1i(at("orthographic"), c.type == Camera::Type::orthographic ? 1 : 0);
    set("camera_position", c.position);
    set("camera_forward", forward);
    set("camera_right", right);
    set("camera_up", up);
    gl.Uniform1f(at("tan_half"), f(std::tan(0.5 * c.fov_y_deg * kPi / 180.0)));
    gl.Uniform1f(at("half_height"), f(0.5 * c.height));
    gl.Uniform1f(at("aspect"), f(static_cast<double>(c.width_px) / c.height_px));
  }

  // c_k toward the eye for every pixel (grids::inscatter_weights), in groups of four per texel.
  void update_weights(const Camera& camera) {
    auto same = [](const Camera& a, const Camera& b) {
      return a.type == b.type && a.position == b.position && a.look_at == b.look_at && a.up == b.up && a.height == b.height &&
             a.fov_y_deg == b.fov_y_deg && a.width_px == b.width_px && a.height_px == b.height_px;
    };
    if (!dom || (weights_camera && same(*weights_camera, camera))) return;
    const int w = camera.width_px, h = camera.height_px, n = dom->terms();
    std::vector<float> values(4 * static_cast<size_t>(w) * static_cast<size_t>(h) * static_cast<size_t>(ms_groups), 0.0f);
    parallel_for(h, 0, 4, [&](long long y0, long long y1) {
      for (auto y = static_cast<int>(y0); y < y1; ++y)
        for (int x = 0; x < w; ++x) {
          const Eigen::VectorXd c = grids::inscatter_weights(*dom, -camera.pixel_ray(x, y).direction);
          for (int k = 0; k < n; ++k) {
            const size_t row = static_cast<size_t>(k / 4 * h + y);
            values[4 * (row * static_cast<size_t>(w) + static_cast<size_t>(x)) + static_cast<size_t>(k % 4)] = static_cast<float>(c(k));
          }
        }
    });
    if (!weights || weights->size()[0] != w || weights->size()[1] != h * ms_groups)
      weights.emplace(Texture::plane(w, h * ms_groups, 4, TexelFormat::float32));
    weights->upload(values);
    weights_camera = camera;
  }

  void bind(int unit, GLenum type, GLuint texture) const {
    gl.ActiveTexture(static_cast<GLenum>(GL_TEXTURE0 + unit));
    gl.BindTexture(type, texture);
  }

  void draw(const Camera& camera) {
    update_weights(camera);
    target.bind(gl, camera.width_px, camera.height_px, "display");
    gl.Viewport(0, 0, camera.width_px, camera.height_px);
    gl.UseProgram(program);
    set_camera(camera);
    bind(kDensityUnit, GL_TEXTURE_3D, density->id());
    for (int g = 0; g < 4; ++g) bind(kDepthUnit + g, GL_TEXTURE_3D, depths[std::min<size_t>(static_cast<size_t>(g), depths.size() - 1)].id());
    for (int g = 0; g < 4; ++g)
      bind(kVisibilityUnit + g, GL_TEXTURE_3D,
           (visibility.empty() ? *unused_volume : visibility[std::min<size_t>(static_cast<size_t>(g), visibility.size() - 1)]).id());
    bind(kPhaseUnit, GL_TEXTURE_2D, (phase_table ? *phase_table : *unused_plane).id());
    bind(kMomentsUnit, GL_TEXTURE_3D, (moments ? *moments : *unused_volume).id());
    bind(kWeightsUnit, GL_TEXTURE_2D, (weights ? *weights : *unused_plane).id());
    bind(kAtlasUnit, GL_TEXTURE_2D, (surface_atlas ? *surface_atlas : *unused_plane).id());
    bind(kEmissionUnit, GL_TEXTURE_3D, (emission ? *emission : *unused_volume).id());
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindVertexArray(vao);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);
    gl.Finish();
    internal::check(gl, "display draw");
  }
};

VolumeDisplay::VolumeDisplay(const Scene& scene, const grids::ExtinctionVolume& volume, const std::vector<DenseGrid>& depths,
                             const DisplaySettings& settings)
    : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  if (!(settings.step_cells > 0.0)) throw Error("step", std::to_string(settings.step_cells), "a step > 0 cells");
  d.settings = settings;
  d.scene = scene;
  d.scene.lights.clear();
  for (const Light& l : scene.lights) {
    if (const auto* sky = std::get_if<SkyLight>(&l)) d.scene.background += sky->radiance, d.sky += sky->radiance;
    else d.scene.lights.push_back(l);
  }
  if (d.scene.lights.size() > static_cast<size_t>(kMaxLights))
    throw Error("lights", std::to_string(d.scene.lights.size()) + " point, spot or directional lights", "at most 16 for the GL display");
  if (scene.surfaces.size() > static_cast<size_t>(kMaxSurfaces))
    throw Error("surfaces", std::to_string(scene.surfaces.size()), "at most 16 for the GL display");
  for (size_t i = 0; i < scene.surfaces.size(); ++i)
    if (std::holds_alternative<Mesh>(scene.surfaces[i].shape))
      throw Error("surfaces[" + std::to_string(i) + "].type", "mesh",
                  "a plane or a sphere: the GL display's ray march draws no triangles (a host rasterizes them: docs/HOST.md)");
  d.cells = volume.density.resolution();
  d.bounds = volume.density.bounds();
  d.sigma_t = volume.sigma_t_scale, d.albedo = volume.albedo, d.phase = volume.phase;

  d.unused_plane.emplace(Texture::plane(1, 1, 4, TexelFormat::float32));
  d.unused_plane->upload(std::vector<float>(4, 0.0f));
  d.unused_volume.emplace(Texture::volume({1, 1, 1}, 4, TexelFormat::float32));
  d.unused_volume->upload(std::vector<float>(4, 0.0f));
  d.density.emplace(Texture::volume(d.cells, 1, settings.format));
  d.density->upload(volume.density.values());
  for (size_t g = 0; g < std::max<size_t>(1, (d.scene.lights.size() + 3) / 4); ++g)
    d.depths.push_back(Texture::volume(d.cells, 4, settings.format));
  d.upload_depths(depths, {});
  d.upload_visibility(volume.density);

  d.program = internal::fullscreen_program(d.gl, internal::kMarchFragmentShader, "ray-march");
  d.gl.GenVertexArrays(1, &d.vao);
  d.set_static_uniforms();
  d.upload_emission(volume.emission);
  internal::check(d.gl, "display set-up");
}

VolumeDisplay::VolumeDisplay(const grids::GridSolution& solution, DisplaySettings settings)
    : VolumeDisplay(solution.scene(), solution.volume(), solution.depths(), (settings.step_cells = solution.step_cells(), settings)) {
  if (const grids::DomSolution* dom = solution.dom()) show_dom(*dom);
}

VolumeDisplay::~VolumeDisplay() = default;

void VolumeDisplay::show_dom(const grids::DomSolution& solution) {
  Impl& d = *impl_;
  if (solution.resolution != d.cells)
    throw Error("dom solution", "resolution " + std::to_string(solution.resolution[0]) + " x " + std::to_string(solution.resolution[1]) + " x " +
                                    std::to_string(solution.resolution[2]),
                "the displayed volume's");
  const int n = solution.terms(), channels = solution.channels;
  const int groups = (n + 3) / 4;
  const auto cells = static_cast<size_t>(d.cells[0]) * static_cast<size_t>(d.cells[1]) * static_cast<size_t>(d.cells[2]);
  const auto slab = static_cast<size_t>(d.cells[2]);
  std::vector<float> values(4 * cells * static_cast<size_t>(groups * channels), 0.0f);
  const size_t plane = static_cast<size_t>(d.cells[0]) * static_cast<size_t>(d.cells[1]);
  for (int c = 0; c < channels; ++c)
    for (size_t cell = 0; cell < cells; ++cell) {
      const size_t z = cell / plane, xy = cell % plane;
      for (int k = 0; k < n; ++k) {
        const size_t s = static_cast<size_t>(c * groups + k / 4);
        values[4 * ((s * slab + z) * plane + xy) + static_cast<size_t>(k % 4)] =
            solution.moments[static_cast<size_t>(c)][cell * static_cast<size_t>(n) + static_cast<size_t>(k)];
      }
    }
  d.moments.emplace(Texture::volume({d.cells[0], d.cells[1], d.cells[2] * groups * channels}, 4, d.settings.format));
  d.moments->upload(values);
  d.dom = solution;
  d.dom->moments.clear();
  d.ms_groups = groups;
  d.weights_camera.reset();
  // render_dom's coefficients: delta-M scaled extinction along the view and for surfaces, the
  // single-scattering albedo that restores the peak, the scaled albedo for the diffuse part.
  const double fm = solution.delta_m_fraction;
  const Rgb scale = Rgb(1.0) - d.albedo * fm;
  d.set_coefficients(d.sigma_t * scale, d.sigma_t, d.albedo / scale, d.albedo * (1.0 - fm) / scale);
  d.gl.Uniform1i(d.at("ms_groups"), groups);
  d.gl.Uniform1i(d.at("ms_channels"), channels);
  d.upload_surface_texels(solution.surfaces.get());
  internal::check(d.gl, "dom upload");
}

void VolumeDisplay::update_density(const DenseGrid& density, std::span<const Brick> bricks) {
  impl_->check_grid(density, "density");
  if (bricks.empty()) impl_->density->upload(density.values());
  else impl_->density->upload(density.values(), bricks);
}

void VolumeDisplay::update_depths(const std::vector<DenseGrid>& depths, std::span<const Brick> bricks) { impl_->upload_depths(depths, bricks); }

void VolumeDisplay::draw(const Camera& camera) { impl_->draw(camera); }

Image VolumeDisplay::render(const Camera& camera) {
  if (camera.type != Camera::Type::pinhole && camera.type != Camera::Type::orthographic)
    throw Error("camera.type", camera.type == Camera::Type::matrices ? "matrices" : "rays",
                "pinhole or orthographic for the GL display (a host's matrices and rays render through the CPU methods)");
  Impl& d = *impl_;
  d.draw(camera);
  return d.target.read(d.gl, "display read-back");
}

const Texture& VolumeDisplay::density() const { return *impl_->density; }

std::vector<const Texture*> VolumeDisplay::textures() const {
  std::vector<const Texture*> all{&*impl_->density};
  for (const Texture& t : impl_->depths) all.push_back(&t);
  for (const auto* t : {&impl_->phase_table, &impl_->moments, &impl_->weights, &impl_->surface_atlas, &impl_->emission})
    if (*t) all.push_back(&**t);
  return all;
}

}  // namespace haze::gl
