// The ray marcher of method "propagation" (seed 003 sec. 4.4, eq. 8-10): the float64 reference
// one pixel at a time, and the SIMD kernel (haze/grids/march_rays.h) over each image row. Surfaces
// shadow the medium (surface_visibility, trilinear) and each other (a ray to each light).
#include <haze/core/error.h>
#include <haze/core/directions.h>
#include <haze/core/grid_walk.h>
#include <haze/grids/optical_depth.h>
#include <haze/grids/propagation.h>
#include <haze/grids/march_rays.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

namespace haze::grids {

namespace {

constexpr int kSurfaceDirections = 64;  // MarchSettings::surface_gather

struct Hit {
  const Surface* surface = nullptr;
  double t = kInfinity;
  Vec3 normal{0.0};
};

// The steps of one ray inside the volume, before its hit.
struct Steps {
  double t0 = 0.0, dt = 0.0;
  int count = 0;
};

struct Marcher {
  const Scene& scene;
  const ExtinctionVolume& volume;
  const std::vector<DenseGrid>& depths;
  Rgb sigma_t;
  double step;
  // The lights' depths interleaved (all lights of a cell together): one stencil reads 8 short runs;
  // the same for the surfaces' shadows (surface_visibility; empty without surfaces). The caller's
  // (PackedLights, made once per solution) or made here.
  PackedLights own;
  const PackedLights& packed;

  // MarchSettings::surface_gather: the directions, and the tangent of the cone each stands for.
  bool gather = false;
  std::optional<DirectionSet> around;  // made only when gathering: a frame's marcher allocates nothing else
  double cone = 0.0;

  Marcher(const Scene& s, const ExtinctionVolume& v, const std::vector<DenseGrid>& d, double step_length, int threads,
          const PackedLights* lights, bool surface_gather = false)
      : scene(s), volume(v), depths(d), sigma_t(v.sigma_t_scale), step(step_length),
        own(lights ? PackedLights{} : pack_lights(s, v, d, threads)), packed(lights ? *lights : own) {
    const size_t values = v.density.cell_count() * d.size();
    if (packed.depths.size() != values || (!packed.visibility.empty() && packed.visibility.size() != values))
      throw Error("packed", to_text(packed.depths.size()) + " depths and " + to_text(packed.visibility.size()) + " visibilities",
                  to_text(values) + " each (cells x lights; pack_lights for this volume and these depths)");
    gather = surface_gather && !scene.surfaces.empty() && volume.albedo != Rgb(0.0);
    if (gather) around = DirectionSet::fibonacci(kSurfaceDirections);
    cone = cone_tangent(kSurfaceDirections);
  }

  // The nearest surface before t_max (a host's depth); h.t is t_max where there is none.
  Hit hit(const Ray& ray, double t_max = kInfinity) const {
    Hit h;
    h.surface = nearest_surface(scene.surfaces, ray, t_max, h.t, h.normal);
    return h;
  }

  Steps steps(const Ray& ray, double t_hit) const {
    Steps s;
    double t1 = t_hit;
    if (!volume.density.bounds().clip(ray, s.t0, t1) || !(t1 > s.t0)) return s;
    s.count = static_cast<int>(std::ceil((t1 - s.t0) / step));
    s.dt = (t1 - s.t0) / s.count;
    return s;
  }

  // The medium along the ray's steps (the float64 reference of the SIMD kernel). With cone > 0 a
  // point light nearer than cone t at a step delivers its irradiance at that distance, no more.
  void march(const Ray& ray, const Steps& s, Rgb& radiance, Rgb& transmittance, double cone_tangent = 0.0) const {
    radiance = Rgb(0.0), transmittance = Rgb(1.0);
    const Emission& emission = volume.emission;
    const bool emits = emission.emits();
    const size_t lights = scene.lights.size();
    std::vector<double> depth(lights), visible(lights, 1.0);
    LightArrival a;
    for (int i = 0; i < s.count; ++i) {
      const Vec3 x = ray.at(s.t0 + (i + 0.5) * s.dt);
      const TrilinearStencil stencil(volume.density.bounds(), volume.density.resolution(), x);
      const double rho = stencil.apply(volume.density.values().data());
      const Rgb emitted = emits ? emitted_radiance(emission, x, rho) : Rgb(0.0);
      if (rho <= 0.0) {  // nothing scatters or absorbs here: only emission (a flame grid past the smoke)
        radiance += transmittance * emitted * s.dt;
        continue;
      }
      std::fill(depth.begin(), depth.end(), 0.0);
      for (int m = 0; m < 8; ++m) {
        const float* run = packed.depths.data() + stencil.offset[m] * lights;
        for (size_t l = 0; l < lights; ++l) depth[l] += stencil.weight[m] * static_cast<double>(run[l]);
      }
      if (!packed.visibility.empty()) {
        std::fill(visible.begin(), visible.end(), 0.0);
        for (int m = 0; m < 8; ++m) {
          const float* run = packed.visibility.data() + stencil.offset[m] * lights;
          for (size_t l = 0; l < lights; ++l) visible[l] += stencil.weight[m] * static_cast<double>(run[l]);
        }
      }
      Rgb in(0.0);
      for (size_t l = 0; l < lights; ++l) {
        if (!arrival(scene.lights[l], x, a) || a.irradiance == Rgb(0.0)) continue;
        if (const double radius = cone_tangent * (s.t0 + (i + 0.5) * s.dt); a.distance < radius)
          a.irradiance *= (a.distance / radius) * (a.distance / radius);
        in += volume.phase.eval(-a.to_light, -ray.direction) * a.irradiance * visible[l] * glm::exp(-sigma_t * depth[l]);
      }
      const Rgb tau = sigma_t * rho * s.dt, step_transmittance = glm::exp(-tau);
      radiance += transmittance * volume.albedo * (Rgb(1.0) - step_transmittance) * in;
      // Emission over the step, L_e constant across it: L_e integral_0^dt e^(-sigma_t rho s) ds.
      for (int c = 0; emits && c < 3; ++c)
        radiance[c] += transmittance[c] * emitted[c] * (tau[c] > 1e-9 ? (1.0 - step_transmittance[c]) / (sigma_t[c] * rho) : s.dt);
      transmittance *= step_transmittance;
    }
  }

  // What reaches the eye: the medium's radiance, then the background (not behind a host's depth)
  // or (eq. 10) the surface's shading, each light attenuated by its depth to the surface point,
  // seen through the medium.
  PixelLayers finish(const Ray& ray, const Hit& h, const Rgb& radiance, const Rgb& transmittance) const {
    if (!h.surface) return {radiance, transmittance, std::isinf(h.t) ? scene.background : Rgb(0.0)};
    const Vec3 p = ray.at(h.t);
    Rgb surface = surface_direct(scene.lights, scene.surfaces, volume.density, depths, sigma_t, *h.surface, p, h.normal, -ray.direction);
    for (int j = 0; gather && j < around->size(); ++j) {
      const double cos_i = glm::dot(h.normal, (*around)[j]);
      if (cos_i <= 0.0) continue;
      const Ray up{p, (*around)[j]};
      Rgb arriving, unused;
      march(up, steps(up, hit(up).t), arriving, unused, cone);
      surface += around->weight(j) * cos_i * h.surface->brdf((*around)[j], -ray.direction, h.normal) * arriving;
    }
    return {radiance, transmittance, surface};
  }

  PixelLayers pixel(const Ray& ray, double t_max) const {
    const Hit h = hit(ray, t_max);
    Rgb radiance, transmittance;
    march(ray, steps(ray, h.t), radiance, transmittance);
    return finish(ray, h, radiance, transmittance);
  }
};

// Whether a point or spot light has a cell within MarchSettings::kFarCells cells of its own
// (clamped to the grid) denser than kFarDensity of the volume's largest: there its 1 / r^2 peak
// and turning directions need the march's own steps.
bool near_dense_cells(const DenseGrid& density, float density_max, const MarchLight& light) {
  const auto n = density.resolution();
  const Vec3 h = density.cell_size();
  std::array<int, 3> lo{}, hi{};
  for (int e = 0; e < 3; ++e) {
    const double u = (static_cast<double>(light.position[e]) - density.bounds().lo[e]) / h[e];
    const double c = std::floor(std::clamp(u, -1e6, 1e6)), last = n[static_cast<size_t>(e)] - 1.0;
    if (c + MarchSettings::kFarCells < 0.0 || c - MarchSettings::kFarCells > last) return false;  // no cell that near
    lo[static_cast<size_t>(e)] = static_cast<int>(std::clamp(c - MarchSettings::kFarCells, 0.0, last));
    hi[static_cast<size_t>(e)] = static_cast<int>(std::clamp(c + MarchSettings::kFarCells, 0.0, last));
  }
  const float dense = MarchSettings::kFarDensity * density_max;
  for (int z = lo[2]; z <= hi[2]; ++z)
    for (int y = lo[1]; y <= hi[1]; ++y)
      for (int x = lo[0]; x <= hi[0]; ++x)
        if (density.at(x, y, z) > dense) return true;
  return false;
}

// The kernel's view of the volume and lights; false where it cannot take them (a tabulated phase
// function, a sky light, emission).
bool simd_volume(const Marcher& m, std::vector<MarchLight>& lights, MarchVolume& v) {
  if (!march_supported(m.volume.phase) || m.volume.emission.emits()) return false;
  const DenseGrid& density = m.volume.density;
  const Vec3 h = density.cell_size();
  for (int e = 0; e < 3; ++e) {
    v.n[e] = density.resolution()[static_cast<size_t>(e)];
    v.lo[e] = static_cast<float>(density.bounds().lo[e]), v.h[e] = static_cast<float>(h[e]);
    v.sigma_t[e] = static_cast<float>(m.sigma_t[e]), v.albedo[e] = static_cast<float>(m.volume.albedo[e]);
  }
  bool all_grey = is_grey(m.sigma_t) && is_grey(m.volume.albedo);
  auto set = [&](const Vec3& from, float* to) {
    for (int e = 0; e < 3; ++e) to[e] = static_cast<float>(from[e]);
  };
  for (const Light& light : m.scene.lights) {
    MarchLight l;
    Rgb intensity;
    if (const auto* p = std::get_if<PointLight>(&light)) {
      set(p->position, l.position), intensity = p->intensity;
    } else if (const auto* s = std::get_if<SpotLight>(&light)) {
      l.type = MarchLight::spot;
      set(s->position, l.position), set(s->direction, l.axis), intensity = s->intensity;
      l.cos_cone = static_cast<float>(std::cos(s->cone_deg * kPi / 180.0)), l.exponent = static_cast<float>(s->exponent);
    } else if (const auto* d = std::get_if<DirectionalLight>(&light)) {
      l.type = MarchLight::directional;
      set(-d->direction, l.to_light), intensity = d->irradiance;
    } else {
      return false;
    }
    set(intensity, l.intensity);
    l.slot = static_cast<int>(lights.size());
    all_grey = all_grey && is_grey(intensity);
    lights.push_back(l);
  }
  v.density = density.values().data();
  v.depths = m.packed.depths.data();
  v.visibility = m.packed.visibility.empty() ? nullptr : m.packed.visibility.data();
  v.lights = lights.data();
  v.light_count = v.depth_stride = static_cast<int>(lights.size());
  v.channels = all_grey ? 1 : 3;
  return true;
}

// The kernel's packet over row-major buffers of `stride` floats a row: the nine inputs (origin,
// direction, t0, dt, steps) in `in`'s rows, L_in then T per channel in `out`'s; `count` rays.
RayPacket packet_of(std::vector<float>& in, std::vector<float>& out, size_t stride, size_t count) {
  const auto row = [stride](std::vector<float>& buffer, size_t r) { return buffer.data() + r * stride; };
  return {row(in, 0), row(in, 1), row(in, 2), row(in, 3), row(in, 4), row(in, 5), row(in, 6), row(in, 7), row(in, 8), count,
          {row(out, 0), row(out, 1), row(out, 2)}, {row(out, 3), row(out, 4), row(out, 5)}};
}

// Row y's rays to their hits (a surface or the view's depth) through the SIMD kernel, into each
// thread's kept buffers: L_in in result's rows 0 to 2 and T in rows 3 to 5 (rows of width floats;
// row 0 and 3 alone when grey).
struct RowMarch {
  std::vector<Ray> rays;
  std::vector<Hit> hits;
  std::vector<float> in, result;
  const float* at(size_t row) const { return result.data() + row * rays.size(); }
};
const RowMarch& march_row_rays(const Marcher& m, const MarchVolume& v, const View& view, int y) {
  thread_local RowMarch r;
  const auto width = static_cast<size_t>(view.camera.width_px);
  r.rays.resize(width), r.hits.resize(width), r.in.resize(9 * width), r.result.assign(6 * width, 0.0f);
  view.camera.row_rays(y, r.rays.data());
  for (size_t x = 0; x < width; ++x) {
    r.hits[x] = m.hit(r.rays[x], view.max_distance(static_cast<int>(x), y));
    const Steps s = m.steps(r.rays[x], r.hits[x].t);
    const double values[9] = {r.rays[x].origin.x, r.rays[x].origin.y, r.rays[x].origin.z, r.rays[x].direction.x, r.rays[x].direction.y,
                              r.rays[x].direction.z, s.t0, s.dt, static_cast<double>(s.count)};
    for (size_t a = 0; a < 9; ++a) r.in[a * width + x] = static_cast<float>(values[a]);
  }
  march_rays(v, m.volume.phase, packet_of(r.in, r.result, width, width));
  return r;
}

// One image row through the SIMD kernel; surfaces and the background per pixel after it.
void march_row(const Marcher& m, const MarchVolume& v, const View& view, int y, RenderResult& result) {
  const RowMarch& r = march_row_rays(m, v, view, y);
  for (size_t x = 0; x < r.rays.size(); ++x) {
    Rgb radiance, transmittance;
    for (int c = 0; c < 3; ++c) {
      const size_t channel = v.channels == 1 ? 0 : static_cast<size_t>(c);
      radiance[c] = static_cast<double>(r.at(channel)[x]);
      transmittance[c] = static_cast<double>(r.at(3 + channel)[x]);
    }
    result.set(static_cast<int>(x), y, m.finish(r.rays[x], r.hits[x], radiance, transmittance));
  }
}

// Row y's layers into the caller's spans (march_layers), the surface layer from Marcher::finish.
void march_row_layers(const Marcher& m, const MarchVolume& v, const View& view, int y, LayerSpans out) {
  const RowMarch& r = march_row_rays(m, v, view, y);
  for (size_t x = 0; x < r.rays.size(); ++x) {
    const auto px = static_cast<int>(x);
    float* l = out.inscatter.pixel(px, y);
    float* t = out.transmittance.pixel(px, y);
    for (int c = 0; c < 3; ++c) {
      const size_t channel = v.channels == 1 ? 0 : static_cast<size_t>(c);
      l[c] = r.at(channel)[x], t[c] = r.at(3 + channel)[x];
    }
    if (out.surface.data) {
      const Rgb surface = m.finish(r.rays[x], r.hits[x], Rgb(0.0), Rgb(1.0)).surface;
      float* si = out.surface.pixel(px, y);
      for (int c = 0; c < 3; ++c) si[c] = static_cast<float>(surface[c]);
    }
  }
}

// MarchSettings::toward_eye: the directional lights and the point lights not near dense cells
// folded into `folded` toward `eye` (march_toward_eye) and taken out of `lights`, which v's
// steps keep; nothing where no light folds.
void fold_toward_eye(const Marcher& m, const Vec3& eye, std::vector<MarchLight>& lights, MarchVolume& v, std::vector<uint32_t>& folded, int threads) {
  thread_local std::vector<MarchLight> far;  // kept, as the caller's
  far.clear();
  size_t kept = 0;
  for (const MarchLight& l : lights) {
    const bool stays = l.type == MarchLight::spot || (l.type == MarchLight::point && near_dense_cells(m.volume.density, m.packed.density_max, l));
    if (stays) lights[kept++] = l;
    else far.push_back(l);
  }
  lights.resize(kept);
  if (far.empty()) return;
  for (MarchLight& l : far) l.plane = m.packed.attenuation_plane.empty() ? -1 : m.packed.attenuation_plane[static_cast<size_t>(l.slot)];
  v.attenuation = m.packed.attenuation.empty() ? nullptr : m.packed.attenuation.data();
  const auto n = m.volume.density.resolution();
  folded.resize(static_cast<size_t>(n[0] + 2) * static_cast<size_t>(n[1] + 2) * static_cast<size_t>(n[2] + 2) * static_cast<size_t>(v.channels + 1) / 2);
  // The float16 values' scales: a quarter of their range (the prefilter may double a peak) for the
  // largest each can take, sum_l I_l max p E_l (E_l at most 1 / r^2 from the ghosted grid's box,
  // r at least half a cell), and the largest density.
  const Vec3 h = m.volume.density.cell_size();
  const Aabb box{m.volume.density.bounds().lo - h, m.volume.density.bounds().hi + h};
  const double peak = std::max(m.volume.phase.eval(1.0), m.volume.phase.eval(-1.0)), near = 0.5 * std::min({h.x, h.y, h.z});
  double bound[3] = {0.0, 0.0, 0.0};
  for (const MarchLight& l : far) {
    double falloff = 1.0;
    if (l.type == MarchLight::point) {
      const Vec3 p(static_cast<double>(l.position[0]), static_cast<double>(l.position[1]), static_cast<double>(l.position[2]));
      falloff = 1.0 / std::pow(std::max(glm::length(p - glm::clamp(p, box.lo, box.hi)), near), 2.0);
    }
    for (int c = 0; c < 3; ++c) bound[c] += static_cast<double>(l.intensity[c]) * peak * falloff;
  }
  for (int c = 0; c < 3; ++c) v.folded_scale[c] = bound[c] > 0.0 ? static_cast<float>(bound[c] / 16384.0) : 1.0f;
  v.folded_scale[3] = m.packed.density_max > 0.0f ? m.packed.density_max / 16384.0f : 1.0f;
  const float at[3] = {static_cast<float>(eye.x), static_cast<float>(eye.y), static_cast<float>(eye.z)};
  march_toward_eye(v, m.volume.phase, at, far.data(), static_cast<int>(far.size()), folded.data(), threads);
  v.folded = folded.data();
  v.lights = lights.data(), v.light_count = static_cast<int>(lights.size());
}

// Three rows of `width` floats into row y of an RGB or RGBA span (RGBA's fourth float left as it is).
void put_row(const float* r, const float* g, const float* b, size_t width, const ImageSpan& span, int y) {
  if (span.channels == 3) {
    march_interleave_rgb(r, g, b, width, span.pixel(0, y));
    return;
  }
  for (size_t x = 0; x < width; ++x) {
    float* p = span.pixel(static_cast<int>(x), y);
    p[0] = r[x], p[1] = g[x], p[2] = b[x];
  }
}

// The rays of a film row from `eye` along a + b (px + 0.5) (Camera::row_frame's a and b, shifted
// and scaled for a row's part or a lattice), for march_row_packet.
RowFrame row_frame_of(const Marcher& m, const Vec3& eye, const Vec3& a, const Vec3& b) {
  const Aabb& box = m.volume.density.bounds();
  RowFrame frame{};
  for (int e = 0; e < 3; ++e) {
    frame.eye[e] = static_cast<float>(eye[e]), frame.a[e] = static_cast<float>(a[e]), frame.b[e] = static_cast<float>(b[e]);
    frame.lo[e] = static_cast<float>(box.lo[e]), frame.hi[e] = static_cast<float>(box.hi[e]);
  }
  frame.step = static_cast<float>(m.step);
  return frame;
}

// Row y's L_in and T (march_layers) for a camera whose rays leave one eye, in a scene without
// surfaces of Haze's own (march_layers writes C): the rays made and clipped in float32 lanes
// (march_row_packet), the kernel, the spans. Buffers per thread, kept.
void march_row_layers_from(const Marcher& m, const MarchVolume& v, const View& view, const Vec3& eye, int y, LayerSpans out) {
  const auto width = static_cast<size_t>(view.camera.width_px), padded = width + 64;  // whole vectors of any target
  thread_local std::vector<float> packed, result, depth;
  packed.resize(9 * padded), result.resize(6 * padded);
  Vec3 a, b;
  view.camera.row_frame(y + 0.5, a, b);
  RowFrame frame = row_frame_of(m, eye, a, b);
  if (!view.depth.empty()) {
    depth.assign(padded, std::numeric_limits<float>::infinity());
    std::copy_n(view.depth.begin() + static_cast<std::ptrdiff_t>(static_cast<size_t>(y) * width), width, depth.begin());
    frame.depth = depth.data();
  }
  march_row_packet(frame, packed.data(), padded, width);
  march_rays(v, m.volume.phase, packet_of(packed, result, padded, width));
  const auto row = [&](size_t r) { return result.data() + r * padded; };
  const size_t grey = v.channels == 1 ? 0 : 1;  // channel c's row: c times this
  for (const auto& [span, first] : {std::pair{out.inscatter, size_t(0)}, std::pair{out.transmittance, size_t(3)}})
    put_row(row(first), row(first + grey), row(first + 2 * grey), width, span, y);
}

// The distance from `eye` to the box's farthest corner.
double farthest_corner(const Aabb& box, const Vec3& eye) {
  double far = 0.0;
  for (int c = 0; c < 8; ++c) far = std::max(far, glm::length(Vec3(c & 1 ? box.hi.x : box.lo.x, c & 2 ? box.hi.y : box.lo.y, c & 4 ? box.hi.z : box.lo.z) - eye));
  return far;
}

// march_layers' lattice step in pixels (MarchSettings::kLatticeNodesPerCell): from one eye, a node
// per kLatticeNodesPerCell of the narrowest cell as the view's central pixels see it at the
// volume's farthest corner, rounded down to a power of 2 (the finer levels halve it down to 2);
// else 1. `peaks`: the film positions of the lights in the steps (point lights near dense cells,
// spots: peaks narrower than a cell) in or near the view.
int lattice_step(const Marcher& m, const MarchVolume& v, const View& view, const Vec3& eye, std::vector<std::array<double, 2>>& peaks) {
  const Camera& camera = view.camera;
  const double far = farthest_corner(m.volume.density.bounds(), eye);
  const Vec3 h = m.volume.density.cell_size();
  const double cell_pixels = std::min({h.x, h.y, h.z}) / (far * camera.pixel_angle());
  int step = std::min(static_cast<int>(cell_pixels / MarchSettings::kLatticeNodesPerCell), std::max(camera.width_px, camera.height_px));
  if (step < 2) return 1;
  while (step & (step - 1)) step &= step - 1;  // the highest power of 2 in it
  peaks.clear();
  for (int l = 0; l < v.light_count; ++l) {
    const MarchLight& light = v.lights[l];
    double px, py;
    if (light.type == MarchLight::directional) continue;
    if (!camera.film_position(Vec3(light.position[0], light.position[1], light.position[2]), px, py)) continue;  // behind the eye
    const double margin = MarchSettings::kLatticePeakNodes * step;
    if (px > -margin && px < camera.width_px + margin && py > -margin && py < camera.height_px + margin) peaks.push_back({px, py});
  }
  return step;
}

// One level of march_lattice_layers: nodes at film points (i step + 0.5, j step + 0.5), i < nx,
// j < ny, reaching past the last pixel; their L_in and T ([layers][ny][nx], L_in's rows first: 3
// and 3, or 1 and 1 where the medium and lights are grey); which it holds; which are rough; which
// cells (nodes i..i+1, j..j+1, at [j nx + i]) the next level resolves.
struct LatticeLevel {
  int step = 0;
  size_t nx = 0, ny = 0;
  std::vector<float> nodes;
  // 2: in a cell the level above refines (its node there, or marched); 1: next to one
  // (interpolated from the level above, for the second differences); 0: not held. Level 0 holds all.
  std::vector<std::uint8_t> held;
  std::vector<std::uint8_t> rough, refined;
  // Level 0's cells whose host depths are not bilinear between their corners' (an edge of the
  // host's geometry): every level refines them, down to each pixel's own ray.
  std::vector<std::uint8_t> deep;
  // The refined cells' runs [first, end) along each row of cells: row j's run_count[j] of them
  // from runs[j (nx / 2 + 1)] (no row has more).
  std::vector<std::array<std::uint32_t, 2>> runs;
  std::vector<std::uint32_t> run_count;
  size_t run_stride() const { return nx / 2 + 1; }
  std::vector<float> weight;  // t / step, t < step: a pixel's between the nodes of its cell
  float* at(size_t r, size_t i, size_t j) { return nodes.data() + (r * ny + j) * nx + i; }
};

// march_layers on a lattice of levels: level 0's rays through every node, each row a packet; a
// cell with a rough node at a corner (below) is refined by the next level, at half the step, which
// marches the new nodes of such cells and tests them in turn; a pixel is bilinear between the
// nodes of the first level whose cell around it is not refined, or takes its own ray where even
// the finest level's is. Rough: a second difference along x or y over kLatticeSpread (of T, or of
// L_in over its largest on level 0): a silhouette of the volume, the edge of a light, which the
// bilinear interpolation would blur; and every node near a light in the steps (`peaks`).
void march_lattice_layers(const Marcher& m, const MarchVolume& v, const View& view, const Vec3& eye, int s, std::span<const std::array<double, 2>> peaks,
                          LayerSpans out, int threads) {
  const Camera& camera = view.camera;
  const auto width = static_cast<size_t>(camera.width_px), height = static_cast<size_t>(camera.height_px);
  const float* depth = view.depth.empty() ? nullptr : view.depth.data();
  int count = 1;
  while ((s >> (count - 1)) > 2) ++count;  // s, s / 2, ..., 2 (s a power of 2)
  // Kept per thread, the finest level first: slot k holds steps of at least 2^(k+1) pixels, so the
  // buffers grow to their most once, not each time the step changes.
  thread_local std::vector<LatticeLevel> kept;
  int most_count = 1;  // for the largest step this film takes
  while ((std::max(width, height) >> (most_count - 1)) > 2) ++most_count;
  if (kept.size() < static_cast<size_t>(most_count)) kept.resize(static_cast<size_t>(most_count));
  std::vector<LatticeLevel>& levels = kept;  // the rows' threads read this thread's
  const auto level = [&levels, count](int k) -> LatticeLevel& { return levels[static_cast<size_t>(count - 1 - k)]; };
  // The layers' rows: L_in's, then T's, each one row where grey.
  const size_t grey = v.channels == 1 ? 0 : 1, layers = grey ? 6 : 2;
  for (int k = 0; k < count; ++k) {
    LatticeLevel& l = level(k);
    l.step = s >> k;
    l.nx = (width - 1) / static_cast<size_t>(l.step) + 2, l.ny = (height - 1) / static_cast<size_t>(l.step) + 2;
    l.nodes.resize(layers * l.nx * l.ny), l.held.assign(l.nx * l.ny, k == 0 ? 2 : 0), l.rough.assign(l.nx * l.ny, 0), l.refined.assign(l.nx * l.ny, 0);
    l.deep.assign(k == 0 && depth ? l.nx * l.ny : 0, 0);
    l.weight.resize(static_cast<size_t>(l.step));
    for (int t = 0; t < l.step; ++t) l.weight[static_cast<size_t>(t)] = static_cast<float>(t) / static_cast<float>(l.step);
  }
  for (int slot = 0; slot < most_count; ++slot) {  // slot k: steps of 2^(k+1) or more
    LatticeLevel& l = levels[static_cast<size_t>(slot)];
    const size_t nodes = (((width - 1) >> (slot + 1)) + 2) * (((height - 1) >> (slot + 1)) + 2);
    l.nodes.reserve(6 * nodes), l.held.reserve(nodes), l.rough.reserve(nodes), l.refined.reserve(nodes), l.deep.reserve(nodes);
    l.runs.reserve(((((width - 1) >> (slot + 1)) + 2) / 2 + 1) * (((height - 1) >> (slot + 1)) + 2));
    l.run_count.reserve(((height - 1) >> (slot + 1)) + 2), l.weight.reserve(std::max(width, height));
  }
  // Layer row r's in the kernel's result (L_in then T per channel, row 0 and 3 alone where grey).
  const auto result_row = [layers](size_t r) { return r < layers / 2 ? r : 3 + r - layers / 2; };
  // Rays through row y's film points at[0 .. n) (pixels), their layers into put(r, e, value).
  const size_t most_rays = std::max(width, level(0).nx) + 64;
  // With a host's depth each ray ends at its pixel's (a node's: the pixel it passes through, the
  // last row's or column's past the film).
  const auto march_points = [&](double y, const std::vector<float>& at, size_t n, auto&& put) {
    thread_local std::vector<float> packed, result, ends;
    packed.reserve(9 * most_rays), result.reserve(6 * most_rays), ends.reserve(most_rays);
    const size_t padded = n + 64;
    packed.resize(9 * padded), result.resize(6 * padded);
    Vec3 a, b;
    camera.row_frame(y, a, b);
    RowFrame frame = row_frame_of(m, eye, a, b);
    frame.film = at.data();
    if (depth) {
      const float* row = depth + std::min(static_cast<size_t>(y), height - 1) * width;
      ends.assign(padded, std::numeric_limits<float>::infinity());
      for (size_t e = 0; e < n; ++e) ends[e] = row[std::min(static_cast<size_t>(at[e]), width - 1)];
      frame.depth = ends.data();
    }
    march_row_packet(frame, packed.data(), padded, n);
    march_rays(v, m.volume.phase, packet_of(packed, result, padded, n));
    for (size_t r = 0; r < layers; ++r)
      for (size_t e = 0; e < n; ++e) put(r, e, result[result_row(r) * padded + e]);
  };
  const auto room = [&](std::vector<float>& at, size_t n) {
    at.reserve(most_rays), at.resize(n + 64, 0.0f);  // padded for whole vectors
  };
  // Level 0: every node.
  {
    LatticeLevel& l = level(0);
    const auto rows = [&](long long j0, long long j1) {
      thread_local std::vector<float> at;
      room(at, l.nx);
      for (size_t i = 0; i < l.nx; ++i) at[i] = static_cast<float>(i * static_cast<size_t>(l.step)) + 0.5f;
      for (auto j = static_cast<size_t>(j0); j < static_cast<size_t>(j1); ++j)
        march_points(static_cast<double>(j * static_cast<size_t>(l.step)) + 0.5, at, l.nx, [&](size_t r, size_t e, float value) { *l.at(r, e, j) = value; });
    };
    parallel_for(static_cast<long long>(l.ny), threads, 1, [&rows](long long j0, long long j1) { rows(j0, j1); });
  }
  if (depth) {
    // Level 0's cells whose pixels' depths stray from the bilinear of their corners' by more than
    // kLatticeDepth cells (depths past the volume's farthest corner taken as there).
    const Vec3 h = m.volume.density.cell_size();
    const auto tolerance = static_cast<float>(MarchSettings::kLatticeDepth * std::min({h.x, h.y, h.z}));
    const auto reach = static_cast<float>(farthest_corner(m.volume.density.bounds(), eye));
    LatticeLevel& l = level(0);
    const auto step = static_cast<size_t>(l.step);
    const auto d = [&](size_t x, size_t y) { return std::min(depth[std::min(y, height - 1) * width + std::min(x, width - 1)], reach); };
    const auto cells = [&](long long j0, long long j1) {
      for (auto j = static_cast<size_t>(j0); j < static_cast<size_t>(j1); ++j)
        for (size_t i = 0; i + 1 < l.nx; ++i) {
          const float c00 = d(i * step, j * step), c10 = d((i + 1) * step, j * step), c01 = d(i * step, (j + 1) * step), c11 = d((i + 1) * step, (j + 1) * step);
          float off = 0.0f;
          for (size_t y = j * step; y < std::min(height, (j + 1) * step); ++y) {
            const float fy = l.weight[y - j * step], left = c00 + fy * (c01 - c00), right = c10 + fy * (c11 - c10);
            const float* row = depth + y * width + i * step;
            const size_t n = std::min(width, (i + 1) * step) - i * step;
            for (size_t x = 0; x < n; ++x) off = std::max(off, std::abs(std::min(row[x], reach) - (left + l.weight[x] * (right - left))));
          }
          l.deep[j * l.nx + i] = off > tolerance;
        }
    };
    parallel_for(static_cast<long long>(l.ny - 1), threads, 8, [&cells](long long j0, long long j1) { cells(j0, j1); });
  }
  float peak = 0.0f;
  {
    LatticeLevel& l = level(0);
    for (size_t e = 0; e < layers / 2 * l.nx * l.ny; ++e) peak = std::max(peak, l.nodes[e]);
  }
  for (int k = 0; k < count; ++k) {
    LatticeLevel& l = level(k);
    if (k > 0) {
      // The nodes in the refined cells of the level above (and those next to them), taken from it
      // where they coincide, marched where new, interpolated from it next to them.
      LatticeLevel& above = level(k - 1);
      for (int pass = 2; pass >= 1; --pass)
        for (size_t b = 0; b + 1 < above.ny; ++b)
          for (size_t a = 0; a + 1 < above.nx; ++a) {
            if (!above.refined[b * above.nx + a]) continue;
            const size_t wide = pass == 1 ? 1 : 0;  // pass 1: a node wider
            for (size_t j = 2 * b >= wide ? 2 * b - wide : 0; j <= std::min(l.ny - 1, 2 * b + 2 + wide); ++j)
              for (size_t i = 2 * a >= wide ? 2 * a - wide : 0; i <= std::min(l.nx - 1, 2 * a + 2 + wide); ++i)
                l.held[j * l.nx + i] = std::max<std::uint8_t>(l.held[j * l.nx + i], static_cast<std::uint8_t>(pass));
          }
      const auto rows = [&](long long j0, long long j1) {
        thread_local std::vector<float> at;
        thread_local std::vector<size_t> which;
        room(at, l.nx), which.reserve(most_rays), which.resize(l.nx);
        for (auto j = static_cast<size_t>(j0); j < static_cast<size_t>(j1); ++j) {
          size_t n = 0;
          const size_t pj = j / 2;
          const float fj = (j % 2) ? 0.5f : 0.0f;
          for (size_t i = 0; i < l.nx; ++i) {
            const std::uint8_t held = l.held[j * l.nx + i];
            if (held == 0) continue;
            const size_t pi = i / 2;
            if (i % 2 == 0 && j % 2 == 0) {
              for (size_t r = 0; r < layers; ++r) *l.at(r, i, j) = *above.at(r, pi, pj);
            } else if (held == 2) {
              at[n] = static_cast<float>(i * static_cast<size_t>(l.step)) + 0.5f, which[n++] = i;
            } else {
              const float fi = (i % 2) ? 0.5f : 0.0f;
              for (size_t r = 0; r < layers; ++r) {
                const float* p = above.at(r, pi, pj);
                const float top = fi > 0.0f ? p[0] + fi * (p[1] - p[0]) : p[0];
                float below = top;
                if (fj > 0.0f) {
                  const float* q = p + above.nx;
                  below = fi > 0.0f ? q[0] + fi * (q[1] - q[0]) : q[0];
                }
                *l.at(r, i, j) = top + fj * (below - top);
              }
            }
          }
          if (n > 0)
            march_points(static_cast<double>(j * static_cast<size_t>(l.step)) + 0.5, at, n, [&](size_t r, size_t e, float value) { *l.at(r, which[e], j) = value; });
        }
      };
      parallel_for(static_cast<long long>(l.ny), threads, 4, [&rows](long long j0, long long j1) { rows(j0, j1); });
    }
    // Rough nodes among those this level holds in refined cells.
    const auto roughness = [&](long long j0, long long j1) {
      for (auto j = static_cast<size_t>(j0); j < static_cast<size_t>(j1); ++j)
        for (size_t i = 0; i < l.nx; ++i) {
          if (l.held[j * l.nx + i] != 2) continue;
          for (size_t r = 0; r < layers && !l.rough[j * l.nx + i]; ++r) {
            const float* at = l.at(r, i, j);
            const float limit = MarchSettings::kLatticeSpread * (r < layers / 2 ? peak : 1.0f);
            const bool across = i > 0 && i + 1 < l.nx && std::abs(at[-1] - 2.0f * at[0] + at[1]) > limit;
            const bool down = j > 0 && j + 1 < l.ny && std::abs(at[-static_cast<std::ptrdiff_t>(l.nx)] - 2.0f * at[0] + at[l.nx]) > limit;
            if (across || down) l.rough[j * l.nx + i] = 1;
          }
        }
    };
    parallel_for(static_cast<long long>(l.ny), threads, 8, [&roughness](long long j0, long long j1) { roughness(j0, j1); });
    for (const auto& [px, py] : peaks) {  // around a light in the steps, kLatticePeakNodes of this level's
      const int reach = MarchSettings::kLatticePeakNodes, ci = static_cast<int>(std::floor((px - 0.5) / l.step)), cj = static_cast<int>(std::floor((py - 0.5) / l.step));
      for (int j = std::max(0, cj - reach); j <= std::min(static_cast<int>(l.ny) - 1, cj + reach + 1); ++j)
        for (int i = std::max(0, ci - reach); i <= std::min(static_cast<int>(l.nx) - 1, ci + reach + 1); ++i)
          l.rough[static_cast<size_t>(j) * l.nx + static_cast<size_t>(i)] = 1;
    }
    // The cells the next level (or, on the last, each pixel's own ray) resolves: a rough corner,
    // or in a deep cell of level 0, inside a cell the level above refined.
    const LatticeLevel* above = k > 0 ? &level(k - 1) : nullptr;
    const LatticeLevel& first = level(0);
    l.runs.resize(l.run_stride() * l.ny), l.run_count.assign(l.ny, 0);
    const auto cells = [&](long long j0, long long j1) {
      for (auto j = static_cast<size_t>(j0); j < static_cast<size_t>(j1); ++j) {
        std::array<std::uint32_t, 2>* runs = l.runs.data() + j * l.run_stride();
        std::uint32_t& n = l.run_count[j];
        for (size_t i = 0; i + 1 < l.nx; ++i) {
          const std::uint8_t* c = l.rough.data() + j * l.nx + i;
          const bool deep = depth && first.deep[(j >> k) * first.nx + (i >> k)];
          if (!(deep || c[0] | c[1] | c[l.nx] | c[l.nx + 1]) || (above && !above->refined[(j / 2) * above->nx + i / 2])) continue;
          l.refined[j * l.nx + i] = 1;
          if (n > 0 && runs[n - 1][1] == i) ++runs[n - 1][1];
          else runs[n++] = {static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(i + 1)};
        }
      }
    };
    parallel_for(static_cast<long long>(l.ny - 1), threads, 16, [&cells](long long j0, long long j1) { cells(j0, j1); });
  }
  // Each pixel: level 0 between its nodes, then each finer level over the pixels of the cells the
  // level above refines, then its own ray in the cells the last refines.
  const auto pixel_rows = [&](long long y0, long long y1) {
    const size_t padded = width + 64;
    thread_local std::vector<float> line, at, mix;
    thread_local std::vector<size_t> which;
    const size_t mix_stride = (width - 1) / 2 + 2;  // nodes a row of any level holds
    line.reserve(6 * (most_rays + 64)), line.resize(layers * padded), mix.reserve(6 * mix_stride), mix.resize(layers * mix_stride);
    room(at, width), which.reserve(most_rays), which.resize(width);
    // Pixels [x0, x1) of row y (x0 on a node) bilinear between level l's nodes: between its node
    // rows, then each cell's pixels along x.
    const auto blend = [&](LatticeLevel& l, size_t x0, size_t x1, size_t y) {
      const auto step = static_cast<size_t>(l.step);
      const size_t i0 = x0 / step, i1 = (x1 - 1) / step + 2, row = y / step;
      const float fy = l.weight[y % step];
      const float* w = l.weight.data();
      for (size_t r = 0; r < layers; ++r) {
        const float* above = l.at(r, 0, row);
        float* b = mix.data() + r * mix_stride;
        for (size_t i = i0; i < i1; ++i) b[i] = above[i] + fy * (above[i + l.nx] - above[i]);
        float* to = line.data() + r * padded;
        for (size_t i = i0, x = x0; x < x1; ++i, x += step) {
          const float left = b[i], d = b[i + 1] - left;
          const size_t n = std::min(step, x1 - x);
          for (size_t t = 0; t < n; ++t) to[x + t] = left + w[t] * d;
        }
      }
    };
    for (auto y = static_cast<size_t>(y0); y < static_cast<size_t>(y1); ++y) {
      blend(level(0), 0, width, y);
      for (int k = 0; k < count; ++k) {
        LatticeLevel& l = level(k);
        const auto step = static_cast<size_t>(l.step);
        const size_t b = y / step;
        size_t n = 0;
        for (size_t r = b * l.run_stride(); r < b * l.run_stride() + l.run_count[b]; ++r) {
          const size_t x0 = l.runs[r][0] * step, x1 = std::min(width, l.runs[r][1] * step);
          if (k + 1 < count) {
            blend(level(k + 1), x0, x1, y);
            continue;
          }
          for (size_t x = x0; x < x1; ++x) {
            at[n] = static_cast<float>(x) + 0.5f, which[n++] = x;
          }
        }
        if (n > 0) march_points(static_cast<double>(y) + 0.5, at, n, [&](size_t r, size_t e, float value) { line[r * padded + which[e]] = value; });
      }
      for (const auto& [span, first] : {std::pair{out.inscatter, size_t(0)}, std::pair{out.transmittance, layers / 2}}) {
        const float* r = line.data() + first * padded;
        put_row(r, r + grey * padded, r + 2 * grey * padded, width, span, static_cast<int>(y));
      }
    }
  };
  parallel_for(camera.height_px, threads, 8, [&pixel_rows](long long y0, long long y1) { pixel_rows(y0, y1); });
}

// A slice's stretch takes kSliceSteps steps where they are coarser than the columns' spacing, each
// at most kStepShare of the distance (160 x 90 x 64 froxels: 3.3 columns' spacing, the build 36%
// faster, the composite's error against the per-pixel layers unchanged at 0.72%).
constexpr double kSliceSteps = 4, kStepShare = 0.05;

// Row y's stretches between consecutive distances, one packet, chained per ray (march_distances).
// A stretch from distance d steps no finer than pitch d, the spacing of the view's rays there (a
// froxel column's width: the froxels resolve no more across) nor than kSliceSteps to its slice,
// up to kStepShare d, unless a point or spot light lies within two such steps of it: its 1 / d^2
// peak there takes the marcher's own step (farther, the midpoints of steps s take the peak of a
// light at h from the line to e^(-2 pi h / s) of its integral). The segments go slice by slice,
// so that a vector's lanes march the same slice of neighbouring rays (similar step counts).
// Buffers are per thread and kept: a frame allocates nothing once they have grown.
void march_row_distances(const Marcher& m, const MarchVolume& v, const View& view, std::span<const double> distances, int y,
                         DistanceLayers out, double pitch) {
  const Camera& camera = view.camera;
  const auto width = static_cast<size_t>(camera.width_px), n = distances.size();
  struct Column {
    double t0 = 0.0, t1 = 0.0;  // the ray's stretch in the medium
    size_t k0 = 0, k1 = 0;      // the slices [k0, k1) that hold some of it
    size_t near0 = 0, near1 = 0;  // its lights in `near`
  };
  // A point or spot light within two coarse steps of a ray (where it passes nearest, t along it
  // and h from it): the segments that come as near take fine steps.
  struct Near {
    double t, h;
  };
  thread_local std::vector<Ray> rays;
  thread_local std::vector<Column> columns;
  thread_local std::vector<Near> near;
  thread_local std::vector<float> packed, result;
  thread_local std::vector<Vec3f> l, t;  // each ray's layers so far
  thread_local std::vector<size_t> start, next;
  thread_local std::vector<uint32_t> column;
  rays.resize(width), columns.resize(width), near.clear();
  // Grown once to the most a row can take (every column near every light, in every slice), so
  // that no later frame's row grows them.
  near.reserve(width * m.scene.lights.size()), packed.reserve(9 * width * n), result.reserve(6 * width * n), column.reserve(width * n);
  camera.row_rays(y, rays.data());
  size_t count = 0;
  for (size_t x = 0; x < width; ++x) {
    Column& c = columns[x];
    const Ray& ray = rays[x];
    double a = 0.0, b = m.hit(ray).t;
    if (!m.volume.density.bounds().clip(ray, a, b) || !(b > a)) b = a;
    c.t0 = a, c.t1 = b;
    // Slice k holds [max(t0, d_k-1), min(t1, d_k)): from the first d_k past t0 to the first at or past t1.
    c.k0 = static_cast<size_t>(std::upper_bound(distances.begin(), distances.end(), a) - distances.begin());
    c.k1 = b > a ? std::min(n, static_cast<size_t>(std::lower_bound(distances.begin(), distances.end(), b) - distances.begin()) + 1) : c.k0;
    count += c.k1 > c.k0 ? c.k1 - c.k0 : 0;
    c.near0 = near.size();
    for (const Light& light : m.scene.lights) {
      const Vec3* p = nullptr;
      if (const auto* point = std::get_if<PointLight>(&light)) p = &point->position;
      else if (const auto* spot = std::get_if<SpotLight>(&light)) p = &spot->position;
      if (!p || !(b > a)) continue;
      const Vec3 to_light = *p - ray.origin;
      const double along = glm::dot(to_light, ray.direction), h = glm::length(to_light - along * ray.direction);
      if (h < 2.0 * pitch * b) near.push_back({along, h});
    }
    c.near1 = near.size();
  }
  const auto fine = [&](const Column& c, double from, double to, double coarse) {
    for (size_t e = c.near0; e < c.near1; ++e) {
      const double off = near[e].t - std::clamp(near[e].t, from, to);
      if (near[e].h * near[e].h + off * off < 4.0 * coarse * coarse) return true;
    }
    return false;
  };
  // The segments slice by slice: slice k's are [start[k], start[k + 1]), of the columns `column`
  // (a counting sort over the columns' slice ranges).
  start.assign(n + 1, 0), column.resize(count);
  for (size_t x = 0; x < width; ++x)
    for (size_t k = columns[x].k0; k < columns[x].k1; ++k) ++start[k + 1];
  for (size_t k = 0; k < n; ++k) start[k + 1] += start[k];
  next.assign(start.begin(), start.end() - 1);
  for (size_t x = 0; x < width; ++x)
    for (size_t k = columns[x].k0; k < columns[x].k1; ++k) column[next[k]++] = static_cast<uint32_t>(x);
  packed.resize(9 * count), result.assign(6 * count, 0.0f);
  for (size_t k = 0; k < n; ++k)
    for (size_t i = start[k]; i < start[k + 1]; ++i) {
      const size_t x = column[i];
      const Column& c = columns[x];
      const double from = std::max(c.t0, k == 0 ? 0.0 : distances[k - 1]), to = std::min(c.t1, distances[k]);
      const double slice = distances[k] - (k == 0 ? 0.0 : distances[k - 1]);
      const double coarse = std::max(pitch * from, std::min(slice / kSliceSteps, kStepShare * from)), step = coarse > m.step && !fine(c, from, to, coarse) ? coarse : m.step;
      const int steps = std::max(1, static_cast<int>(std::ceil((to - from) / step)));
      const Ray& r = rays[x];
      const double segment[9] = {r.origin.x, r.origin.y, r.origin.z, r.direction.x, r.direction.y, r.direction.z, from, (to - from) / steps,
                                 static_cast<double>(steps)};
      for (size_t e = 0; e < 9; ++e) packed[e * count + i] = static_cast<float>(segment[e]);
    }
  if (count > 0) march_rays(v, m.volume.phase, packet_of(packed, result, count, count));
  const auto row = [&](std::vector<float>& buffer, size_t a) { return buffer.data() + a * count; };
  // Chained front to back: L(d_k) = L(d_k-1) + T(d_k-1) L_k, T(d_k) = T(d_k-1) T_k.
  l.assign(width, Vec3f(0.0f)), t.assign(width, Vec3f(1.0f));
  const size_t per_slice = width * static_cast<size_t>(camera.height_px), first = static_cast<size_t>(y) * width;
  const size_t grey = v.channels == 1 ? 0 : 1;  // channel c's row: c times this
  for (size_t k = 0; k < n; ++k) {
    for (size_t i = start[k]; i < start[k + 1]; ++i) {
      const size_t x = column[i];
      for (size_t c = 0; c < 3; ++c) l[x][c] += t[x][c] * row(result, c * grey)[i], t[x][c] *= row(result, 3 + c * grey)[i];
    }
    std::copy(l.begin(), l.begin() + static_cast<std::ptrdiff_t>(width), out.inscatter.begin() + static_cast<std::ptrdiff_t>(k * per_slice + first));
    std::copy(t.begin(), t.begin() + static_cast<std::ptrdiff_t>(width), out.transmittance.begin() + static_cast<std::ptrdiff_t>(k * per_slice + first));
  }
}

}  // namespace

PackedLights pack_lights(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths, int threads,
                         const std::vector<DenseGrid>* visibility) {
  const auto interleave = [](const std::vector<DenseGrid>& grids) {
    if (grids.empty()) return std::vector<float>{};
    const size_t lights = grids.size(), cells = grids.front().cell_count();
    std::vector<float> out(cells * lights);
    for (size_t c = 0; c < cells; ++c)
      for (size_t l = 0; l < lights; ++l) out[c * lights + l] = grids[l].values()[c];
    return out;
  };
  PackedLights packed{interleave(depths), {}, 0.0f, {}, {}};
  const std::vector<float>& values = volume.density.values();
  packed.density_max = values.empty() ? 0.0f : *std::max_element(values.begin(), values.end());
  if (visibility && visibility->size() != depths.size())
    throw Error("visibility", to_text(visibility->size()) + " volumes", "one per light (" + to_text(depths.size()) + ")");
  if (volume.albedo != Rgb(0.0) && !scene.surfaces.empty())  // else no light in the medium to shadow
    packed.visibility = interleave(visibility ? *visibility : surface_visibility(volume.density, scene.lights, scene.surfaces, threads));
  // The lights march_toward_eye folds (directional, point away from dense cells) in a grey medium:
  // each one's V e^(-sigma_t depth) per cell, a plane each.
  const size_t lights = depths.size(), cells = volume.density.cell_count();
  if (!is_grey(volume.sigma_t_scale) || lights != scene.lights.size()) return packed;
  packed.attenuation_plane.assign(lights, -1);
  int planes = 0;
  for (size_t l = 0; l < lights; ++l) {
    bool folds = std::holds_alternative<DirectionalLight>(scene.lights[l]);
    if (const auto* point = std::get_if<PointLight>(&scene.lights[l])) {
      MarchLight m;
      for (int e = 0; e < 3; ++e) m.position[e] = static_cast<float>(point->position[e]);
      folds = !near_dense_cells(volume.density, packed.density_max, m);
    }
    if (folds) packed.attenuation_plane[l] = planes++;
  }
  packed.attenuation.resize(static_cast<size_t>(planes) * cells);
  const auto sigma_t = static_cast<float>(volume.sigma_t_scale.r);
  parallel_for(static_cast<long long>(cells), threads, 4096, [&](long long c0, long long c1) {
    for (size_t l = 0; l < lights; ++l) {
      if (packed.attenuation_plane[l] < 0) continue;
      float* plane = packed.attenuation.data() + static_cast<size_t>(packed.attenuation_plane[l]) * cells;
      for (auto c = static_cast<size_t>(c0); c < static_cast<size_t>(c1); ++c) {
        const float visible = packed.visibility.empty() ? 1.0f : packed.visibility[c * lights + l];
        plane[c] = visible * std::exp(-sigma_t * std::max(packed.depths[c * lights + l], 0.0f));
      }
    }
  });
  return packed;
}

double auto_step_cells(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths, const PackedLights& packed,
                       int threads) {
  const Vec3 h = volume.density.cell_size();
  const double cell = std::min({h.x, h.y, h.z});
  const Marcher marcher(scene, volume, depths, 0.5 * cell, threads, &packed, false);
  std::vector<MarchLight> lights;
  MarchVolume v;
  if (!simd_volume(marcher, lights, v)) return kFinestAutoStep;
  for (const MarchLight& light : lights)
    if (light.type != MarchLight::directional && near_dense_cells(volume.density, packed.density_max, light)) return kFinestAutoStep;
  // The probes: chords through the bounds along Fibonacci directions, each offset from the centre
  // by a golden-angle spiral over the disc the bounds cover.
  const Aabb& bounds = volume.density.bounds();
  const Vec3 centre = 0.5 * (bounds.lo + bounds.hi);
  const double radius = 0.5 * glm::length(bounds.hi - bounds.lo);
  const DirectionSet directions = DirectionSet::fibonacci(kAutoStepProbes);
  std::vector<Ray> rays;
  std::vector<double> t0, t1;
  for (int i = 0; i < kAutoStepProbes; ++i) {
    const Vec3 w = directions[i];
    const Vec3 a = glm::normalize(glm::cross(w, std::abs(w.x) < 0.9 ? Vec3(1.0, 0.0, 0.0) : Vec3(0.0, 1.0, 0.0))), b = glm::cross(w, a);
    const double r = radius * std::sqrt((i + 0.5) / kAutoStepProbes), phi = 2.399963229728653 * i;  // the golden angle
    const Ray ray{centre - 2.0 * radius * w + r * (std::cos(phi) * a + std::sin(phi) * b), w};
    double a0 = 0.0, a1 = kInfinity;
    if (bounds.clip(ray, a0, a1) && a1 > a0) rays.push_back(ray), t0.push_back(a0), t1.push_back(a1);
  }
  const size_t count = rays.size(), channels = static_cast<size_t>(v.channels);
  if (count == 0) return kFinestAutoStep;
  // Each candidate's L_in and T per probe and channel: rows of `count`, L then T.
  const auto march = [&](double step) {
    std::vector<float> in(9 * count), out(6 * count);
    for (size_t i = 0; i < count; ++i) {
      const int steps = std::max(1, static_cast<int>(std::ceil((t1[i] - t0[i]) / (step * cell))));
      const double values[9] = {rays[i].origin.x, rays[i].origin.y, rays[i].origin.z, rays[i].direction.x, rays[i].direction.y, rays[i].direction.z,
                                t0[i], (t1[i] - t0[i]) / steps, static_cast<double>(steps)};
      for (size_t e = 0; e < 9; ++e) in[e * count + i] = static_cast<float>(values[e]);
    }
    march_rays(v, volume.phase, packet_of(in, out, count, count));
    return out;
  };
  const std::vector<float> finest = march(kFinestAutoStep);
  // Relative RMS of L_in and of T over the probes and channels, the larger.
  const auto error = [&](const std::vector<float>& got) {
    double worst = 0.0;
    for (size_t layer : {size_t(0), size_t(3)}) {
      double d2 = 0.0, r2 = 0.0;
      for (size_t c = 0; c < channels; ++c)
        for (size_t i = 0; i < count; ++i) {
          const double want = finest[(layer + c) * count + i], diff = static_cast<double>(got[(layer + c) * count + i]) - want;
          d2 += diff * diff, r2 += want * want;
        }
      worst = std::max(worst, r2 > 0.0 ? std::sqrt(d2 / r2) : 0.0);
    }
    return worst;
  };
  double chosen = kFinestAutoStep;
  for (double step : kAutoSteps) {  // the error grows with the step: the first beyond the tolerance ends the search
    if (error(march(step)) > kAutoStepTolerance) break;
    chosen = step;
  }
  return chosen;
}

// The steps take `s`'s radiance per cell beside the lights', and its extinction and albedo.
void take_scattered(const MarchScattered& s, MarchVolume& v) {
  v.source = s.radiance, v.source_channels = s.channels, v.outer = true;
  for (int c = 0; c < 3; ++c) {
    const auto sigma_t = static_cast<float>(s.sigma_t[c]);
    v.depth_scale[c] = sigma_t > 0.0f ? v.sigma_t[c] / sigma_t : 1.0f;
    v.sigma_t[c] = sigma_t, v.albedo[c] = static_cast<float>(s.albedo[c]);
  }
  if (s.channels == 3 || !is_grey(s.sigma_t) || !is_grey(s.albedo)) v.channels = 3;
}

bool march_distances(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths, const MarchSettings& settings,
                     const RenderOptions& options, const View& view, std::span<const double> distances, DistanceLayers out,
                     const PackedLights* packed, const MarchScattered* scattered) {
  const Vec3 h = volume.density.cell_size();
  const Marcher marcher(scene, volume, depths, settings.step_cells * std::min({h.x, h.y, h.z}), options.threads, packed, false);
  // Kept: a frame allocates nothing. The rows read it while this thread waits in parallel_for,
  // which runs only row tasks of Haze's arena meanwhile (none of them marches again).
  thread_local std::vector<MarchLight> lights;
  lights.clear();
  MarchVolume simd_view;
  if (settings.scalar || !simd_volume(marcher, lights, simd_view)) return false;
  if (scattered) take_scattered(*scattered, simd_view);
  const Camera& camera = view.camera;
  const double pitch = camera.pixel_angle();  // a column's width per unit distance: no finer steps along it
  const auto rows = [&](long long y0, long long y1) {
    for (auto y = static_cast<int>(y0); y < y1; ++y) march_row_distances(marcher, simd_view, view, distances, y, out, pitch);
  };
  // A body of one reference: std::function keeps it without allocating.
  parallel_for(camera.height_px, options.threads, 1, [&rows](long long y0, long long y1) { rows(y0, y1); });
  return true;
}

bool march_layers(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths, const MarchSettings& settings,
                  const RenderOptions& options, const View& view, LayerSpans out, const PackedLights* packed, const MarchScattered* scattered) {
  const Vec3 h = volume.density.cell_size();
  const Marcher marcher(scene, volume, depths, settings.step_cells * std::min({h.x, h.y, h.z}), options.threads, packed, settings.surface_gather);
  thread_local std::vector<MarchLight> lights;  // kept, as march_distances' (rows read it while this thread waits)
  lights.clear();
  MarchVolume simd_view;
  if (settings.scalar || marcher.gather || !simd_volume(marcher, lights, simd_view)) return false;
  Vec3 eye, a, b;
  const bool one_eye = view.camera.eye(eye);
  thread_local std::vector<uint32_t> folded;  // kept as `lights`
  if (scattered) take_scattered(*scattered, simd_view);
  else if (one_eye && settings.toward_eye) fold_toward_eye(marcher, eye, lights, simd_view, folded, options.threads);
  // Without surfaces of Haze's own, C is the background where no host depth ends the ray.
  const bool from_eye = one_eye && view.camera.row_frame(0.5, a, b) && scene.surfaces.empty();
  thread_local std::vector<std::array<double, 2>> peaks;  // kept as `lights`
  if (const int step = from_eye && settings.lattice ? lattice_step(marcher, simd_view, view, eye, peaks) : 1; step > 1) {
    march_lattice_layers(marcher, simd_view, view, eye, step, peaks, out, options.threads);
  } else {
    const auto rows = [&](long long y0, long long y1) {
      for (auto y = static_cast<int>(y0); y < y1; ++y) {
        if (from_eye) march_row_layers_from(marcher, simd_view, view, eye, y, out);
        else march_row_layers(marcher, simd_view, view, y, out);
      }
    };
    // A body of one reference: std::function keeps it without allocating.
    parallel_for(view.camera.height_px, options.threads, 1, [&rows](long long y0, long long y1) { rows(y0, y1); });
  }
  if (from_eye && out.surface.data) {
    const float background[3] = {static_cast<float>(scene.background.r), static_cast<float>(scene.background.g), static_cast<float>(scene.background.b)};
    const auto fill = [&](long long y0, long long y1) {
      const size_t channels = static_cast<size_t>(out.surface.channels), width = static_cast<size_t>(view.camera.width_px);
      for (auto y = static_cast<int>(y0); y < y1; ++y) {
        float* p = out.surface.pixel(0, y);
        const float* depth = view.depth.empty() ? nullptr : view.depth.data() + static_cast<size_t>(y) * width;
        for (size_t x = 0; x < width; ++x, p += channels) {
          const bool open = !depth || std::isinf(depth[x]);
          p[0] = open ? background[0] : 0.0f, p[1] = open ? background[1] : 0.0f, p[2] = open ? background[2] : 0.0f;
        }
      }
    };
    parallel_for(view.camera.height_px, options.threads, 16, [&fill](long long y0, long long y1) { fill(y0, y1); });
  }
  return true;
}

Image march_image(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths,
                  const MarchSettings& settings, const RenderOptions& options, const PackedLights* packed) {
  return march_view(scene, volume, depths, settings, options, View{scene.camera}, packed).radiance;
}

RenderResult march_view(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths, const MarchSettings& settings,
                        const RenderOptions& options, const View& view, const PackedLights* packed) {
  if (depths.size() != scene.lights.size())
    throw Error("depths", to_text(depths.size()) + " volumes", "one per light (" + to_text(scene.lights.size()) + ")");
  if (!(settings.step_cells > 0.0)) throw Error("step", to_text(settings.step_cells), "a step > 0 cells");
  const Vec3 h = volume.density.cell_size();
  const Marcher marcher(scene, volume, depths, settings.step_cells * std::min({h.x, h.y, h.z}), options.threads, packed,
                        settings.surface_gather);
  std::vector<MarchLight> lights;
  MarchVolume simd_view;
  const bool use_simd = !settings.scalar && simd_volume(marcher, lights, simd_view);
  const Camera& camera = view.camera;
  RenderResult result = RenderResult::for_view(view);
  ProgressTracker progress(options.progress, camera.height_px);
  parallel_for(camera.height_px, options.threads, 4, [&](long long y0, long long y1) {
    for (auto y = static_cast<int>(y0); y < y1 && !progress.cancelled(); ++y) {
      if (use_simd) {
        march_row(marcher, simd_view, view, y, result);
      } else {
        for (int x = 0; x < camera.width_px; ++x) result.set(x, y, marcher.pixel(camera.pixel_ray(x, y), view.max_distance(x, y)));
      }
      progress.advance();
    }
  });
  progress.throw_if_cancelled();
  return result;
}

}  // namespace haze::grids
