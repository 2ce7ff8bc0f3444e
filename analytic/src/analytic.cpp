// Method "analytic": closed-form single scattering in a homogeneous medium from point and spot
// lights (seed 002 ch. 4, seed 004). Per pixel and light: the airlight of the view segment inside the
// medium from the tabulated tail form (airlight.h), plus the surface's direct radiance attenuated
// along both legs (eq. 4.2, 4.10 in Haze's energy-normalized BRDFs) and the airlight scattered onto
// it (eq. 4.11-4.15, tables J1 and J_n). Surfaces shadow the view segments (each light's airlight is
// summed over the stretches it lights, core's lit_stretches) and each other's direct light; the
// airlight onto a surface is not shadowed. Like the thesis' model it has no multiple scattering.
#include <haze/analytic/airlight.h>
#include <haze/analytic/airlight_batch.h>
#include <haze/analytic/shadow_batch.h>
#include <haze/analytic/surface_batch.h>
#include <haze/analytic/methods.h>
#include <haze/core/features.h>
#include <haze/core/error.h>
#include <haze/core/method.h>
#include <haze/core/stopwatch.h>

#include <array>
#include <map>
#include <memory>
#include <mutex>
#include <optional>

namespace haze::analytic {

// The method's name, written once: the registry, its settings and its errors read it here.
constexpr const char* kAnalyticName = "analytic";

namespace {

// out[i] += airlight of segment i: add_airlight (SIMD, float32) or add_airlight_float64.
using AirlightKernel = void (*)(const AirlightTable& table, const AirlightChannel& light, const SegmentBatch& batch, float* out);

// Point lights use the airlight table; spot lights integrate the stretches inside their cone.
struct AnalyticLight {
  Light light;
  Vec3 position;
  Rgb intensity;
  const SpotLight* spot() const { return std::get_if<SpotLight>(&light); }
};

// What surface shading needs: the medium, the lights and the J tables.
struct SurfaceShading {
  const Medium& medium;
  const std::vector<Surface>& surfaces;
  const std::vector<AnalyticLight>& lights;
  Rgb sigma_t, sigma_s;
  bool grey;
  bool surface_airlight;
  const std::optional<SurfaceAirlightTable>& lambert;
  const std::map<double, SurfaceAirlightTable>& phong;

  // Radiance leaving surface point p toward the viewer (eq. 4.9): direct light attenuated on the way
  // in (eq. 4.10), plus the airlight scattered onto it (eq. 4.15) where p is in the medium.
  Rgb operator()(const Surface& surface, const Vec3& p, const Vec3& normal, const Vec3& view_dir) const {
    Rgb radiance(0.0);
    LightArrival a;
    for (const auto& light : lights) {
      arrival(light.light, p, a);
      double cos_i = glm::dot(normal, a.to_light);
      if (cos_i <= 0.0 || occluded(surfaces, p, a.to_light, a.distance)) continue;
      radiance += surface.brdf(a.to_light, -view_dir, normal) * a.irradiance * cos_i * medium.transmittance(p, light.position);
    }
    // In the medium on the side the normal faces (toward the viewer): a floor on the medium's
    // bottom face has it above, where the point itself sits on the boundary, in or out of the
    // box by rounding (pixels of one floor came out 43% apart).
    if (!surface_airlight || !medium.bounds().contains(off_surface(p, normal))) return radiance;
    const Vec3 mirrored = glm::reflect(view_dir, normal);
    const double cos_r = std::max(0.0, glm::dot(normal, mirrored));
    for (const auto& light : lights) {
      // A spot light's J tables are scaled by its intensity toward the surface point.
      arrival(light.light, p, a);
      const Rgb intensity = a.irradiance * a.distance * a.distance;
      const double theta_s = std::acos(std::clamp(glm::dot(normal, a.to_light), -1.0, 1.0));
      const double theta_r = std::acos(std::clamp(glm::dot(mirrored, a.to_light), -1.0, 1.0));
      // J depends on the channel only through T; a grey medium looks it up once.
      double j_d = 0.0, j_s = 0.0;
      for (int c = 0; c < 3; ++c) {
        double T = sigma_t[c] * a.distance;
        if (c == 0 || !grey) {
          j_d = lambert && surface.kd != Rgb(0.0) ? lambert->eval(T, theta_s) : 0.0;
          j_s = surface.ks != Rgb(0.0) ? phong.at(surface.shininess).eval(T, theta_r) * cos_r : 0.0;
        }
        radiance[c] += sigma_s[c] * intensity[c] * std::exp(-T) / a.distance * (surface.kd[c] * j_d + surface.ks[c] * j_s);
      }
    }
    return radiance;
  }
};

// Prepared: the medium, the lights and the tables; each view is evaluated from them.
class AnalyticSolution final : public MethodSolution {
 public:
  AnalyticSolution(const Scene& scene, std::vector<AnalyticLight> lights, std::unique_ptr<Medium> medium, const Rgb& sigma_t,
                   const Rgb& sigma_s, bool grey, bool airlight, bool surface_airlight, bool view_shadows, AirlightKernel kernel, AirlightTable table,
                   std::optional<SurfaceAirlightTable> lambert, std::map<double, SurfaceAirlightTable> phong)
      : scene_(scene),
        lights_(std::move(lights)),
        medium_(std::move(medium)),
        sigma_t_(sigma_t),
        sigma_s_(sigma_s),
        grey_(grey),
        airlight_(airlight),
        surface_airlight_(surface_airlight),
        view_shadows_(view_shadows),
        kernel_(kernel),
        table_(std::move(table)),
        lambert_(std::move(lambert)),
        phong_(std::move(phong)) {
    for (const AnalyticLight& light : lights_) {
      positions_.insert(positions_.end(), {light.position.x, light.position.y, light.position.z});
      shadows_.emplace_back(scene_.surfaces, light.position);
    }
    const Aabb box = medium_->bounds();
    for (int e = 0; e < 3; ++e) {
      shading_medium_.lo[e] = box.lo[e], shading_medium_.hi[e] = box.hi[e];
      shading_medium_.sigma_t[e] = static_cast<float>(sigma_t_[e]), shading_medium_.sigma_s[e] = static_cast<float>(sigma_s_[e]);
    }
  }

  RenderResult render(const View& view, const RenderOptions& options) const override {
    const Camera& camera = view.camera;
    const Aabb bounds = medium_->bounds();
    const Stopwatch watch;
    RenderResult result = RenderResult::for_view(view);
    ProgressTracker progress(options.progress, camera.height_px);
    if (layers_pass()) {  // render_layers' rows
      parallel_for(camera.height_px, options.threads, 1, [&](long long y0, long long y1) {
        for (auto y = static_cast<int>(y0); y < y1 && !progress.cancelled(); ++y) {
          const float* rgb = row_layers(view, y);
          const size_t padded = padded_count(static_cast<size_t>(camera.width_px));
          const auto at = [&](size_t part, int x) {
            const float* v = rgb + 3 * (part * padded + static_cast<size_t>(x));
            return Rgb(v[0], v[1], v[2]);
          };
          for (int x = 0; x < camera.width_px; ++x) result.set(x, y, PixelLayers{at(0, x), at(1, x), at(2, x)});
          progress.advance();
        }
      });
      progress.throw_if_cancelled();
      result.stats = {{"seconds", watch.seconds()}};
      return result;
    }
    const AirlightKernel add_airlight = kernel_;
    const SurfaceShading shade{*medium_, scene_.surfaces, lights_, sigma_t_, sigma_s_, grey_, surface_airlight_, lambert_, phong_};
    parallel_for(camera.height_px, options.threads, 1, [&](long long y0, long long y1) {
      // Per row: the view segments inside the medium as float arrays, then each point light's
      // airlight over the whole row in one batch (SIMD unless the kernel setting says float64).
      std::vector<float> ox, oy, oz, dx, dy, dz, seg;
      std::vector<int> slot(static_cast<size_t>(camera.width_px));
      struct PixelHit {
        Ray ray;
        double t_hit;
        Vec3 normal;
        const Surface* hit;
        double t_entry;  // where the ray enters the medium
      };
      std::vector<PixelHit> row(static_cast<size_t>(camera.width_px));
      std::array<std::vector<float>, 3> batch_airlight;
      std::vector<float> unit;
      // A light's lit stretches (with surfaces): start, length, the segment each belongs to and
      // its offset from the segment's entry.
      std::vector<float> sx, sy, sz, sl;
      std::array<std::vector<float>, 3> sd;
      std::vector<size_t> owner;
      std::vector<double> offset;
      std::vector<std::pair<double, double>> stretches;
      std::vector<Ray> rays(static_cast<size_t>(camera.width_px));
      for (auto y = static_cast<int>(y0); y < y1 && !progress.cancelled(); ++y) {
        for (auto* v : {&ox, &oy, &oz, &dx, &dy, &dz, &seg}) v->clear();
        camera.row_rays(y, rays.data());
        for (int x = 0; x < camera.width_px; ++x) {
          PixelHit& px = row[static_cast<size_t>(x)];
          px.ray = rays[static_cast<size_t>(x)];
          px.normal = Vec3(0.0);
          px.hit = nearest_surface(scene_.surfaces, px.ray, view.max_distance(x, y), px.t_hit, px.normal);
          const Ray& ray = px.ray;
          double t0 = 0.0, t1 = px.t_hit;
          slot[static_cast<size_t>(x)] = -1;
          if (!(airlight_ && bounds.clip(ray, t0, t1) && t1 > t0)) continue;
          slot[static_cast<size_t>(x)] = static_cast<int>(ox.size());
          px.t_entry = t0;
          Vec3 entry = ray.at(t0);
          ox.push_back(static_cast<float>(entry.x)), oy.push_back(static_cast<float>(entry.y)), oz.push_back(static_cast<float>(entry.z));
          dx.push_back(static_cast<float>(ray.direction.x)), dy.push_back(static_cast<float>(ray.direction.y));
          dz.push_back(static_cast<float>(ray.direction.z));
          seg.push_back(std::isfinite(t1) ? static_cast<float>(t1 - t0) : INFINITY);
        }
        const SegmentBatch batch{ox.data(), oy.data(), oz.data(), dx.data(), dy.data(), dz.data(), seg.data(), ox.size()};
        for (auto& channel : batch_airlight) channel.assign(ox.size(), 0.0f);
        for (const auto& light : lights_) {
          if (light.spot()) continue;
          const Vec3& p = light.position;
          // With surfaces, the light's own batch: the stretches of each segment it lights, each
          // seen from its start and carried to the segment's entry by e^(-sigma_t offset).
          const SegmentBatch* lit = &batch;
          SegmentBatch stretch_batch{};
          if (view_shadows_ && !scene_.surfaces.empty()) {
            for (auto* v : {&sx, &sy, &sz, &sl}) v->clear();
            owner.clear(), offset.clear();
            for (int x = 0; x < camera.width_px; ++x) {
              const int k = slot[static_cast<size_t>(x)];
              if (k < 0) continue;
              const auto kk = static_cast<size_t>(k);
              const PixelHit& px = row[static_cast<size_t>(x)];
              const Ray entry{px.ray.at(px.t_entry), px.ray.direction};
              stretches.clear();
              lit_stretches(scene_.surfaces, entry, 0.0, std::isfinite(seg[kk]) ? static_cast<double>(seg[kk]) : kInfinity, p, stretches);
              for (const auto& [a, b] : stretches) {
                const Vec3 start = entry.at(a);
                sx.push_back(static_cast<float>(start.x)), sy.push_back(static_cast<float>(start.y)), sz.push_back(static_cast<float>(start.z));
                sl.push_back(std::isfinite(b) ? static_cast<float>(b - a) : INFINITY);
                owner.push_back(kk), offset.push_back(a);
              }
            }
            sd[0].assign(sx.size(), 0.0f), sd[1].assign(sx.size(), 0.0f), sd[2].assign(sx.size(), 0.0f);
            for (size_t i = 0; i < owner.size(); ++i) sd[0][i] = dx[owner[i]], sd[1][i] = dy[owner[i]], sd[2][i] = dz[owner[i]];
            stretch_batch = {sx.data(), sy.data(), sz.data(), sd[0].data(), sd[1].data(), sd[2].data(), sl.data(), sx.size()};
            lit = &stretch_batch;
          }
          // out[segment] += airlight, from the light's batch (the segments, or their lit stretches).
          light_airlight(add_airlight, light, *lit, unit, [&](const Rgb& scale) {
            for (int e = 0; e < 3; ++e) {
              if (scale[e] == 0.0) continue;
              std::vector<float>& to = batch_airlight[static_cast<size_t>(e)];
              for (size_t i = 0; i < unit.size(); ++i) {
                const size_t k = lit == &batch ? i : owner[i];
                const double carried = lit == &batch ? 1.0 : std::exp(-sigma_t_[e] * offset[i]);
                to[k] += static_cast<float>(scale[e] * carried * static_cast<double>(unit[i]));
              }
            }
          });
        }
        for (int x = 0; x < camera.width_px; ++x) {
          const auto& [ray, t_hit, normal, hit, t_entry] = row[static_cast<size_t>(x)];
          Rgb radiance(0.0);
          if (int k = slot[static_cast<size_t>(x)]; k >= 0) {
            for (int c = 0; c < 3; ++c) radiance[c] = static_cast<double>(batch_airlight[static_cast<size_t>(c)][static_cast<size_t>(k)]);
            double t0 = 0.0, t1 = t_hit;
            bounds.clip(ray, t0, t1);
            Vec3 entry = ray.at(t0);
            for (const auto& light : lights_) {
              if (!light.spot()) continue;
              stretches.clear();
              if (!view_shadows_ || scene_.surfaces.empty()) stretches.emplace_back(0.0, t1 - t0);
              else lit_stretches(scene_.surfaces, Ray{entry, ray.direction}, 0.0, t1 - t0, light.position, stretches);
              for (const auto& [a, b] : stretches)
                for (int c = 0; c < 3; ++c) {
                  if (sigma_s_[c] == 0.0 || light.intensity[c] == 0.0) continue;
                  radiance[c] += std::exp(-sigma_t_[c] * a) * spot_airlight(scene_.medium->phase, {sigma_t_[c], sigma_s_[c], light.intensity[c]},
                                                                            entry + a * ray.direction, ray.direction, b - a, light.position,
                                                                            light.spot()->direction, light.spot()->exponent, light.spot()->cone_deg);
                }
            }
          }
          PixelLayers layers{radiance, medium_->transmittance_along(ray.origin, ray.direction, t_hit), Rgb(0.0)};
          if (hit) layers.surface = shade(*hit, ray.at(t_hit), normal, ray.direction);
          else if (std::isinf(t_hit)) layers.surface = scene_.background;  // not behind a host's depth
          result.set(x, y, layers);
        }
        progress.advance();
      }
    });
    progress.throw_if_cancelled();
    result.stats = {{"seconds", watch.seconds()}};
    return result;
  }
  bool renders_layers() const override { return true; }

  // Point lights without surfaces, a row of rays in SIMD lanes through the slices
  // (airlight_slices): with [t0, t1] a ray's stretch in the medium, L_in(d) = sum of sigma_s I
  // (g(t0) - T(d) g(d)), one unit tail per ray, light and distance, the ray's geometry toward each
  // light in float64 once.
  // Its error is the table's relative to the whole ray's in-scatter, not to L_in(d): at most 1e-3
  // of it (froxels composite it over the host's colour, where that is what matters). The float64
  // kernel setting renders once per distance instead.
  bool render_distances(const View& view, std::span<const double> distances, const RenderOptions& options, DistanceLayers out) const override {
    if (!one_pass()) return false;
    const double glow = glows(view.camera) ? out.glow_angle : 0.0;
    const auto body = [&](long long y0, long long y1) {
      for (auto y = static_cast<int>(y0); y < y1; ++y) slices_row(view.camera, y, distances, glow, out);
    };
    parallel_for(view.camera.height_px, options.threads, 1, [&body](long long y0, long long y1) { body(y0, y1); });
    return true;
  }

  // Per pixel, a row of rays in SIMD lanes: L_in = sum of sigma_s I (g(t0) - T g(end)) to each ray's
  // end, the tails' form of render_distances, surfaces' shadows cutting it into lit stretches
  // (row_layers). Where T g(end) is above kTailsCancel of g(t0) (airlight_batch.h: what the
  // difference keeps below it) the pixel takes the float64 segment path. render() takes the same rows.
  bool render_layers(const View& view, LayerSpans out, const RenderOptions& options) const override {
    if (!layers_pass()) return false;
    const auto body = [&](long long y0, long long y1) {
      for (auto y = static_cast<int>(y0); y < y1; ++y) layers_row(view, y, out);
    };
    parallel_for(view.camera.height_px, options.threads, 1, [&body](long long y0, long long y1) { body(y0, y1); });
    return true;
  }

  // Per pixel near each point light in view, the share render_distances left out: the light's
  // in-scatter along the ray to its end times glow_share, by the same kernel (tail_sums at the
  // ray's entry and end), over the pixels within the glow angle of the light.
  void add_glow(const View& view, double glow_angle, ImageSpan out, const RenderOptions& options) const override {
    const Camera& camera = view.camera;
    if (!one_pass() || !glows(camera)) return;
    struct Window {
      size_t light;
      double px, py, radius;
      int y0, y1;
    };
    thread_local std::vector<Window> kept;  // a frame allocates nothing
    std::vector<Window>& windows = kept;    // this thread's, which the loop's threads read
    windows.clear();
    long long y0 = camera.height_px, y1 = 0;  // the rows any window covers
    for (size_t l = 0; l < lights_.size(); ++l) {
      double px, py;
      if (!camera.film_position(lights_[l].position, px, py)) continue;
      // The window of pixels within the angle: its radius from the pixels' smaller angle at the
      // light, across or down (a light off the axis of a wide view sees them foreshortened).
      const Vec3 at = camera.generate_ray(px, py).direction;
      const double across = std::acos(std::clamp(glm::dot(at, camera.generate_ray(px + 1.0, py).direction), -1.0, 1.0));
      const double down = std::acos(std::clamp(glm::dot(at, camera.generate_ray(px, py + 1.0).direction), -1.0, 1.0));
      const double pixel = std::min(across, down);
      if (!(pixel > 0.0)) continue;
      const double radius = 1.25 * glow_angle / pixel + 2.0;
      // Clamped as doubles first: a light far off the film projects far outside int's range.
      const auto row = [&](double v) { return static_cast<int>(std::clamp(v, 0.0, static_cast<double>(camera.height_px))); };
      const int first = row(std::floor(py - radius)), end = row(std::ceil(py + radius));
      if (first >= end) continue;
      windows.push_back({l, px, py, radius, first, end});
      y0 = std::min<long long>(y0, first), y1 = std::max<long long>(y1, end);
    }
    // The windows' rows in one parallel loop over image rows: a row adds every window over it, so
    // that no two threads add into one pixel.
    const auto body = [&](long long r0, long long r1) {
      for (auto y = static_cast<int>(r0); y < r1; ++y)
        for (const Window& w : windows) {
          if (y < w.y0 || y >= w.y1) continue;
          const double dy = y + 0.5 - w.py, half = std::sqrt(std::max(0.0, w.radius * w.radius - dy * dy));  // the row's chord
          const auto column = [&](double v) { return static_cast<int>(std::clamp(v, 0.0, static_cast<double>(camera.width_px))); };
          const int x0 = column(std::floor(w.px - half)), x1 = column(std::ceil(w.px + half));
          if (x0 < x1) glow_row(view, w.light, glow_angle, y, x0, x1, out);
        }
    };
    parallel_for(y1 - y0, options.threads, 4, [&body, y0](long long r0, long long r1) { body(y0 + r0, y0 + r1); });
  }

 private:
  // Point lights, the SIMD kernel: render_layers' rows of tails (surfaces shadowing the airlight
  // and shaded in SIMD lanes).
  bool layers_pass() const {
    if (!airlight_ || kernel_ != &add_airlight) return false;
    return std::none_of(lights_.begin(), lights_.end(), [](const AnalyticLight& light) { return light.spot(); });
  }
  // And without surfaces: render_distances' one pass (and add_glow's).
  bool one_pass() const { return layers_pass() && scene_.surfaces.empty(); }
  // Cameras whose rays leave one eye: a light's glow is about its direction from there.
  static bool glows(const Camera& camera) {
    return camera.type == Camera::Type::pinhole || (camera.type == Camera::Type::matrices && camera.projection[2][3] != 0.0);
  }
  // The share of a light's in-scatter along a ray that passes psi from its direction (radians)
  // left to add_glow: 1 within half the glow angle, smoothly 0 at the angle.
  static double glow_share(double psi, double glow_angle) {
    if (!(glow_angle > 0.0) || psi >= glow_angle) return 0.0;
    const double u = std::min(1.0, 2.0 * (glow_angle - psi) / glow_angle);
    return u * u * (3.0 - 2.0 * u);
  }

  // Pixels [x0, x0 + count) of row y toward every light (or only light `only`): each ray's stretch
  // [t0, t1] in the medium, its geometry toward each light in float64 (t and h: row_geometry's
  // lanes where the camera has a row frame), and with a glow angle each light's share per ray
  // (taken, or left: `left`), into the thread's kept scratch; the TailRow over them.
  struct RowRays {
    TailRow row;
    float *t0, *t1, *whole[3];  // whole: where tail_sums puts the row's sums at t0 (row.whole)
    TailLight* tails;           // the row's, tails_per_light of them per light
    size_t tails_per_light;
    float* geometry;            // per light: t, h, share (count rounded up to 16 each)
    size_t padded;
    float* share(size_t l) const { return geometry + (3 * l + 2) * padded; }
  };
  // The kernels' arrays hold whole vectors: count rounded up to 16 (airlight_batch.h).
  static size_t padded_count(size_t count) { return (count + 15) / 16 * 16; }

  RowRays ray_tails(const Camera& camera, int y, int x0, size_t count, double glow_angle, size_t only, bool left) const {
    const size_t padded = padded_count(count);
    const size_t lights = lights_.size();
    // Per thread, kept between frames: a frame allocates nothing once they have grown.
    thread_local std::vector<float> scratch;
    thread_local std::vector<TailLight> tails;
    thread_local std::vector<Ray> rays;
    scratch.resize((5 + 3 * lights) * padded);  // each part's lanes past count zeroed below, the rest written
    tails.clear();
    float* const t0 = scratch.data();
    float* const t1 = t0 + padded;
    float* const whole = t1 + padded;  // three channels
    float* const geometry = whole + 3 * padded;  // per light: t, h, share
    for (size_t part = 0; part < 5 + 3 * lights; ++part) std::fill(scratch.begin() + part * padded + count, scratch.begin() + (part + 1) * padded, 0.0f);
    const Aabb bounds = medium_->bounds();
    const size_t first = only < lights ? only : 0;  // the lights computed: all, or `only`
    const RowGeometry g{{bounds.lo.x, bounds.lo.y, bounds.lo.z}, {bounds.hi.x, bounds.hi.y, bounds.hi.z}, positions_.data() + 3 * first,
                        only < lights ? 1 : lights, t0, t1, geometry + 3 * first * padded, 3 * padded, padded};
    if (Vec3 a, b; camera.row_frame(y + 0.5, a, b)) {
      const double origin[3] = {camera.position.x, camera.position.y, camera.position.z}, a3[3] = {a.x, a.y, a.z}, b3[3] = {b.x, b.y, b.z};
      row_geometry(g, origin, a3, b3, x0 + 0.5, count);
    } else {
      rays.resize(count);
      camera.row_rays(y, x0, x0 + static_cast<int>(count), rays.data());
      row_geometry_rays(g, rays.data(), count);
    }
    // A light within the glow angle of a ray's direction: t > 0 and h < t tan(angle) (angle <= 0.5).
    const double tan_glow = std::tan(glow_angle);
    for (size_t l = 0; l < lights; ++l) {
      if (only < lights && l != only) continue;
      float* g_l = geometry + 3 * l * padded;
      for (size_t x = 0; glow_angle > 0.0 && x < count; ++x) {
        const double t = g_l[x], h = g_l[padded + x];
        const double share = t > 0.0 && h < t * tan_glow ? glow_share(std::atan2(h, t), glow_angle) : 0.0;
        g_l[2 * padded + x] = static_cast<float>(left ? share : 1.0 - share);
      }
      const bool whole_light = glow_angle == 0.0 || (!left && std::all_of(g_l + 2 * padded, g_l + 2 * padded + count, [](float s) { return s == 1.0f; }));
      for (int c = 0; c < (grey_ ? 1 : 3); ++c) {
        TailLight tail{g_l, g_l + padded, static_cast<float>(sigma_t_[c]), {}, whole_light ? nullptr : g_l + 2 * padded};
        for (int e = 0; e < 3; ++e)
          if (grey_ || e == c) tail.weight[e] = static_cast<float>(sigma_s_[e] * lights_[l].intensity[e]);
        tails.push_back(tail);
      }
    }
    TailRow row{tails.data(), tails.size(), t0, t1, {whole, whole + padded, whole + 2 * padded}, {}, count};
    for (int c = 0; c < 3; ++c) row.sigma_t[c] = static_cast<float>(sigma_t_[c]);
    return {row, t0, t1, {whole, whole + padded, whole + 2 * padded}, tails.data(), grey_ ? size_t(1) : size_t(3), geometry, padded};
  }

  // render_distances' row y: the row's rays, then its slices.
  void slices_row(const Camera& camera, int y, std::span<const double> distances, double glow_angle, DistanceLayers out) const {
    const auto width = static_cast<size_t>(camera.width_px);
    const RowRays r = ray_tails(camera, y, 0, width, glow_angle, lights_.size(), false);
    tail_sums(table_, r.row, r.t0, r.whole);
    thread_local std::vector<float> at;
    at.assign(distances.begin(), distances.end());
    const size_t rays_per_slice = width * static_cast<size_t>(camera.height_px), first = static_cast<size_t>(y) * width;
    airlight_slices(table_, r.row, at, &out.inscatter[first].x, &out.transmittance[first].x, 3 * rays_per_slice);
  }

  // The ends in the medium of a row's rays (the depth or t1; t0 where the depth is NaN or negative,
  // as the composite takes it) and where their tails are taken: an endless ray's tails at its
  // entry stand in at its end (it takes all of them: T = 0).
  struct RowEnds {
    const float* ends;
    const float* at;
    bool any_end;
  };
  static RowEnds row_ends(const float* depth, const RowRays& r, size_t count) {
    const size_t padded = padded_count(count);
    thread_local std::vector<float> kept;
    std::vector<float>& v = kept;
    v.assign(2 * padded, 0.0f);
    bool any_end = false;
    for (size_t i = 0; i < count; ++i) {
      v[i] = !(depth[i] >= 0.0f) ? r.t0[i] : std::min(r.t1[i], depth[i]);
      v[padded + i] = std::isfinite(v[i]) ? std::max(v[i], r.t0[i]) : r.t0[i];
      any_end = any_end || std::isfinite(v[i]);
    }
    return {v.data(), v.data() + padded, any_end};
  }
  // The tails of ray_tails' row r at their entries (into r.whole) and at their ends; a row of
  // endless rays (the sky in unbounded fog) skips the second sums.
  struct EndTails {
    const float* ends;
    const float* sums[3];
  };
  EndTails end_tails(const RowEnds& e, const RowRays& r, size_t count) const {
    const size_t padded = padded_count(count);
    thread_local std::vector<float> kept;
    std::vector<float>& at_end = kept;
    at_end.assign(3 * padded, 0.0f);
    float* const sums[3] = {at_end.data(), at_end.data() + padded, at_end.data() + 2 * padded};
    tail_sums(table_, r.row, r.t0, r.whole);
    if (e.any_end) tail_sums(table_, r.row, e.at, sums);
    return {e.ends, {sums[0], sums[1], sums[2]}};
  }
  // The row lattice takes a pixel's L_in from its neighbours at step s, the cubic through x - 3s,
  // x - s, x + s and x + 3s, where it differs from the linear one (their second difference, the
  // linear mean's error) by at most this share of it.
  static constexpr float kRowTolerance = 5e-4f;

  // L_in, T and redo of every pixel of the row from its tails.
  void whole_row_layers(const RowRays& r, const RowEnds& ends, size_t count, float* l_rgb, float* t_rgb, float* redo) const {
    const EndTails e = end_tails(ends, r, count);
    layers_from_tails(r.row, e.ends, e.sums, l_rgb, t_rgb, redo);
  }
  // The pixels in `set` as a row of their own (their entries, ends and each light's geometry
  // gathered) with its tails' sums at the entries (row.whole) and at the ends (at_end; 0 where no
  // ray of the row ends in the medium).
  struct SetRow {
    TailRow row;
    const float* ends;
    float* at_end[3];
  };
  SetRow set_row(const RowRays& r, const RowEnds& e, const std::vector<size_t>& set) const {
    const size_t m = set.size(), mp = padded_count(m), lights = lights_.size();
    thread_local std::vector<float> kept;
    thread_local std::vector<TailLight> kept_tails;
    std::vector<float>& f = kept;
    std::vector<TailLight>& tails = kept_tails;
    f.assign((10 + 3 * lights) * mp, 0.0f);
    float *t0 = f.data(), *ends = t0 + mp, *at = ends + mp, *whole = at + mp, *sums = whole + 3 * mp, *geometry = sums + 3 * mp;
    for (size_t k = 0; k < m; ++k) t0[k] = r.t0[set[k]], ends[k] = e.ends[set[k]], at[k] = e.at[set[k]];
    tails.assign(r.tails, r.tails + r.row.light_count);
    for (size_t j = 0; j < lights; ++j) {
      float* const g = geometry + 3 * j * mp;
      const float* const from = r.geometry + 3 * j * r.padded;
      for (size_t k = 0; k < m; ++k) g[k] = from[set[k]], g[mp + k] = from[r.padded + set[k]], g[2 * mp + k] = from[2 * r.padded + set[k]];
      for (size_t c = 0; c < r.tails_per_light; ++c) {
        TailLight& tail = tails[j * r.tails_per_light + c];
        tail.t = g, tail.h = g + mp, tail.share = tail.share ? g + 2 * mp : nullptr;
      }
    }
    SetRow out{r.row, ends, {sums, sums + mp, sums + 2 * mp}};
    out.row.lights = tails.data(), out.row.t0 = t0, out.row.count = m;
    float* const at_entry[3] = {whole, whole + mp, whole + 2 * mp};
    out.row.whole[0] = whole, out.row.whole[1] = whole + mp, out.row.whole[2] = whole + 2 * mp;
    tail_sums(table_, out.row, t0, at_entry);
    if (e.any_end) tail_sums(table_, out.row, at, out.at_end);
    return out;
  }
  // L_in, T and redo of the pixels in `set` from their tails (set_row's), scattered into the row's.
  void set_layers(const RowRays& r, const RowEnds& e, const std::vector<size_t>& set, float* l_rgb, float* t_rgb, float* redo) const {
    const SetRow s = set_row(r, e, set);
    const size_t mp = padded_count(set.size());
    thread_local std::vector<float> kept;
    std::vector<float>& f = kept;
    f.resize(7 * mp);
    float *const l = f.data(), *const t = l + 3 * mp, *const flags = t + 3 * mp;
    layers_from_tails(s.row, s.ends, s.at_end, l, t, flags);
    for (size_t k = 0; k < set.size(); ++k) {
      for (size_t c = 0; c < 3; ++c) l_rgb[3 * set[k] + c] = l[3 * k + c], t_rgb[3 * set[k] + c] = t[3 * k + c];
      redo[set[k]] = flags[k];
    }
  }
  // L_in, T and redo of every pixel of the row, the tails taken for the pixels in `set` alone (the
  // others' L_in 0): their sums scattered into the row's, layers_from_tails over all of it.
  void layers_of_set(const RowRays& r, const RowEnds& e, const std::vector<size_t>& set, float* l_rgb, float* t_rgb, float* redo) const {
    const SetRow s = set_row(r, e, set);
    const size_t padded = r.padded;
    thread_local std::vector<float> kept;
    std::vector<float>& f = kept;
    f.assign(3 * padded, 0.0f);
    float* const at_end[3] = {f.data(), f.data() + padded, f.data() + 2 * padded};
    for (size_t c = 0; c < 3; ++c) {
      std::fill_n(r.whole[c], padded, 0.0f);
      for (size_t k = 0; k < set.size(); ++k) r.whole[c][set[k]] = s.row.whole[c][k], at_end[c][set[k]] = s.at_end[c][k];
    }
    layers_from_tails(r.row, e.ends, at_end, l_rgb, t_rgb, redo);
  }

  // The view's depths along pixels [x0, x0 + count) of row y, into the thread's kept buffer.
  static const float* view_depths(const View& view, int y, int x0, size_t count) {
    thread_local std::vector<float> kept;
    std::vector<float>& depth = kept;
    depth.resize(count);
    for (size_t i = 0; i < count; ++i) depth[i] = static_cast<float>(view.max_distance(x0 + static_cast<int>(i), y));
    return depth.data();
  }

  // layers_from_tails over the row into `layers`: L_in, then T (RGB triples), then the flags of the
  // pixels to redo, each part count rounded up to 16 long.
  static void tails_to_layers(const RowRays& r, const EndTails& e, size_t count, float* layers) {
    const size_t padded = padded_count(count);
    layers_from_tails(r.row, e.ends, e.sums, layers, layers + 3 * padded, layers + 6 * padded);
  }

  // Clears ok[s - 1][x] where a light's squared distance from the ray, from its entry t0 or from
  // its end changes by over 0.12 s of itself between pixels x - s and x + s, s = 1, 2 (t, h: the
  // light's place along and off each ray; t0 or end null where it is the same for every ray: the
  // eye in the medium, no ray ending in it). Plain loops over restrict pointers, which the
  // compiler takes in lanes; `squares` holds 2 * count floats.
  static void steady_to_light(const float* __restrict t, const float* __restrict h, const float* __restrict t0, const float* __restrict end,
                              size_t count, float* __restrict ok1, float* __restrict ok2, float* __restrict squares) {
    float *const d_ray = squares, *const d_point = squares + count;
    const auto clear_moved = [&](const float* __restrict d) {
      for (size_t x = 1; x + 1 < count; ++x) ok1[x] = std::abs(d[x + 1] - d[x - 1]) > 0.12f * d[x] ? 0.0f : ok1[x];
      for (size_t x = 2; x + 2 < count; ++x) ok2[x] = std::abs(d[x + 2] - d[x - 2]) > 0.24f * d[x] ? 0.0f : ok2[x];
    };
    for (size_t i = 0; i < count; ++i) d_ray[i] = h[i] * h[i];
    clear_moved(d_ray);
    for (const float* __restrict from : {t0, end}) {
      if (!from) continue;
      for (size_t i = 0; i < count; ++i) {
        const float along = t[i] - from[i];  // an endless ray's: inf, never moved
        d_point[i] = d_ray[i] + along * along;
      }
      clear_moved(d_point);
    }
  }

  // Clears ok[s - 1][x] where v (entries or ends) does not vary smoothly over x - s, x, x + s: the
  // middle within 1e-3 of the mean of the outer two, or all three endless. In lanes, like steady_to_light.
  static void smooth_along(const float* __restrict v, size_t count, float* __restrict ok1, float* __restrict ok2) {
    const auto smooth = [](float a, float m, float b) {
      const bool finite = (std::abs(a) < INFINITY) & (std::abs(m) < INFINITY) & (std::abs(b) < INFINITY);
      const bool close = std::abs(m - 0.5f * (a + b)) <= 1e-3f * (std::abs(m) + 1e-3f);
      return (finite & close) | ((a == INFINITY) & (m == INFINITY) & (b == INFINITY));
    };
    for (size_t x = 1; x + 1 < count; ++x) ok1[x] = smooth(v[x - 1], v[x], v[x + 1]) ? ok1[x] : 0.0f;
    for (size_t x = 2; x + 2 < count; ++x) ok2[x] = smooth(v[x - 2], v[x], v[x + 2]) ? ok2[x] : 0.0f;
  }

  // A lit stretch [a, b] of ray x toward light l, where the light's shadows cut the ray.
  struct LitPiece {
    size_t x, light;
    double a, b;
  };

  // Row y's layers into the thread's kept buffer: L_in, T and the surface's radiance as RGB triples,
  // each part the row's width rounded up to 16 long. The tails at each ray's entry and end, each
  // light's share 0 on rays its shadows touch; where they cut a ray, its lit stretches' tails
  // added light by light; pixels whose difference of tails would cancel (airlight_batch.h) by the
  // float64 path; the surfaces' radiance by shade_points, surface by surface.
  const float* row_layers(const View& view, int y) const {
    const Camera& camera = view.camera;
    const auto width = static_cast<size_t>(camera.width_px);
    const size_t padded = padded_count(width), lights = lights_.size();
    const std::vector<Surface>& surfaces = scene_.surfaces;
    const RowRays r = ray_tails(camera, y, 0, width, 0.0, lights, false);
    struct Hit {
      const Surface* surface;
      double t;
      Vec3 normal;
    };
    thread_local std::vector<Hit> kept_hits;
    thread_local std::vector<Ray> kept_rays;
    thread_local std::vector<float> kept_depth, kept_layers;
    thread_local std::vector<LitPiece> kept_pieces;
    thread_local std::vector<std::pair<double, double>> kept_stretches;
    thread_local std::vector<unsigned char> kept_cut;
    std::vector<unsigned char>& cut = kept_cut;  // rays some light lights in part
    cut.assign(padded, 0);
    std::vector<Hit>& hits = kept_hits;
    std::vector<Ray>& rays = kept_rays;
    std::vector<LitPiece>& pieces = kept_pieces;
    std::vector<std::pair<double, double>>& stretches = kept_stretches;
    std::vector<float>& layers = kept_layers;
    layers.assign(10 * padded, 0.0f);
    float* const l_rgb = layers.data();
    float* const t_rgb = l_rgb + 3 * padded;
    float* const s_rgb = t_rgb + 3 * padded;
    float* const redo = s_rgb + 3 * padded;
    // Each ray's end: the view's depth, or the nearest surface before it.
    const float* depth = view_depths(view, y, 0, width);
    if (!surfaces.empty()) {
      rays.resize(width), hits.resize(width);
      camera.row_rays(y, rays.data());
      kept_depth.assign(depth, depth + width);
      for (size_t x = 0; x < width; ++x) {
        Hit& h = hits[x];
        h.surface = nearest_surface(surfaces, rays[x], view.max_distance(static_cast<int>(x), y), h.t, h.normal);
        if (h.surface) kept_depth[x] = static_cast<float>(h.t);
      }
      depth = kept_depth.data();
    }
    // Each light's shadows along the rays: its share 1 where it lights all of a ray's stretch in
    // the medium, else 0 with the lit stretches of those it lights in part.
    pieces.clear();
    if (view_shadows_ && !surfaces.empty()) {
      thread_local std::vector<double> kept_soa;
      std::vector<double>& soa = kept_soa;
      soa.assign(8 * padded, 0.0);
      const auto column = [&](size_t k) { return soa.data() + k * padded; };
      for (size_t x = 0; x < width; ++x) {
        for (int k = 0; k < 3; ++k) column(static_cast<size_t>(k))[x] = rays[x].origin[k], column(3 + static_cast<size_t>(k))[x] = rays[x].direction[k];
        column(6)[x] = static_cast<double>(r.t0[x]);
        column(7)[x] = !(depth[x] >= 0.0f) ? static_cast<double>(r.t0[x]) : std::min(static_cast<double>(r.t1[x]), static_cast<double>(depth[x]));
      }
      const ShadowRays stretch_rays{{column(0), column(1), column(2)}, {column(3), column(4), column(5)}, column(6), column(7), width};
      float* const seen = redo;  // the classes, before redo is written
      for (size_t l = 0; l < lights; ++l) {
        float* const share = r.share(l);
        classify_stretches(shadows_[l], stretch_rays, seen);
        bool whole = true;
        for (size_t x = 0; x < width; ++x) {
          share[x] = seen[x] == 0.0f ? 1.0f : 0.0f;  // lit, dark or partial: 0, 1, 2
          whole = whole && seen[x] == 0.0f;
          if (seen[x] != 2.0f) continue;
          cut[x] = 1;
          stretches.clear();
          if (shadows_[l].meshes()) lit_stretches(surfaces, rays[x], column(6)[x], column(7)[x], lights_[l].position, stretches);
          else lit_pieces(shadows_[l], rays[x], column(6)[x], column(7)[x], stretches);
          for (const auto& [a, b] : stretches) pieces.push_back({x, l, a, b});
        }
        for (size_t k = 0; k < r.tails_per_light; ++k) r.tails[l * r.tails_per_light + k].share = whole ? nullptr : share;
      }
    }
    // The row lattice, in two levels: pixels x = 2 mod 4 from x - 6, x - 2, x + 2 and x + 6, then
    // the odd ones from x - 3, x - 1, x + 1 and x + 3 (their neighbours exact or of the first
    // level), where the pixels between x - s and x + s end on the same surface (or none), at
    // entries and ends varying smoothly, are seen alike by every light and lie away from each;
    // their L_in is the cubic through the four where it is sure to kRowTolerance, the others'
    // their own tails.
    const RowEnds ends = row_ends(depth, r, width);
    thread_local std::vector<size_t> kept_own, kept_between[2];
    std::vector<size_t>& own = kept_own;
    std::vector<size_t>* const between = kept_between;  // [s - 1]: the pixels at step s
    own.clear(), between[0].clear(), between[1].clear();
    // Away from each light: the light's distance from the ray, from its entry and from its end
    // change by at most 3% a pixel (L_in goes as 1 / h along a ray passing the light, the
    // scattering at either end as 1 / d^2: the mean's error is second order in that change;
    // compared squared, steady_to_light).
    thread_local std::vector<float> kept_steady;
    std::vector<float>& steady = kept_steady;  // 1: steady, at steps 1 and 2; 2 rows of squares after them
    steady.assign(4 * width, 1.0f);
    float* const ok[2] = {steady.data(), steady.data() + width};
    const bool one_entry = std::all_of(r.t0, r.t0 + width, [&](float t0) { return t0 == r.t0[0]; });
    const bool endless = std::all_of(ends.ends, ends.ends + width, [](float end) { return end == INFINITY; });
    for (size_t l = 0; l < lights; ++l) {
      const float* const t = r.geometry + 3 * l * r.padded;
      steady_to_light(t, t + r.padded, one_entry ? nullptr : r.t0, endless ? nullptr : ends.ends, width, ok[0], ok[1], ok[1] + width);
    }
    smooth_along(r.t0, width, ok[0], ok[1]), smooth_along(ends.ends, width, ok[0], ok[1]);
    const bool shares = view_shadows_ && !surfaces.empty();
    const auto alike = [&](size_t x, size_t s) {
      if (x < 3 * s || x + 3 * s >= width || ok[s - 1][x] == 0.0f) return false;
      for (size_t i = x - s; i <= x + s && !surfaces.empty(); ++i) {
        if (cut[i] || hits[i].surface != hits[x].surface) return false;
        for (size_t l = 0; l < lights && shares; ++l)
          if (r.share(l)[i] != r.share(l)[x]) return false;
      }
      return true;
    };
    for (size_t x = 0; x < width; ++x) {
      const size_t s = x % 4 == 2 ? 2 : x % 2 == 1 ? 1 : 0;
      (s > 0 && alike(x, s) ? between[s - 1] : own).push_back(x);
    }
    if (between[0].empty() && between[1].empty()) {
      whole_row_layers(r, ends, width, l_rgb, t_rgb, redo);
    } else {
      layers_of_set(r, ends, own, l_rgb, t_rgb, redo);
    }
    add_lit_pieces(r, pieces, l_rgb, redo);
    const auto exact = [&](size_t x) {
      const Rgb l = exact_airlight(camera.pixel_ray(static_cast<int>(x), y), static_cast<double>(r.t0[x]), static_cast<double>(ends.ends[x]));
      for (int c = 0; c < 3; ++c) l_rgb[3 * x + c] = static_cast<float>(l[c]);
    };
    for (size_t x : own)
      if (redo[x] != 0.0f) exact(x);
    for (size_t s : {2, 1}) {
      own.clear();  // now: the pixels at step s whose estimate is too uncertain
      for (size_t x : between[s - 1]) {
        bool close = true;
        for (size_t c = 0; c < 3; ++c) {
          const float* l = l_rgb + c;
          const float a = l[3 * (x - 3 * s)], b = l[3 * (x - s)], d = l[3 * (x + s)], e = l[3 * (x + 3 * s)];
          const float cubic = (9.0f * (b + d) - (a + e)) / 16.0f, curvature = std::abs(a - b - d + e) / 16.0f;  // cubic - linear
          l_rgb[3 * x + c] = std::max(0.0f, cubic);
          close = close & (curvature <= kRowTolerance * cubic);
        }
        if (!close) own.push_back(x);
      }
      if (!own.empty()) {
        set_layers(r, ends, own, l_rgb, t_rgb, redo);
        for (size_t x : own)
          if (redo[x] != 0.0f) exact(x);
      }
    }
    // The surfaces: the background where nothing ends the ray, the host's (0) behind its depth.
    for (size_t x = 0; x < width; ++x) {
      const bool open = std::isinf(view.max_distance(static_cast<int>(x), y)) && (surfaces.empty() || !hits[x].surface);
      for (int c = 0; c < 3; ++c) s_rgb[3 * x + c] = open ? static_cast<float>(scene_.background[c]) : 0.0f;
    }
    for (const Surface& surface : surfaces) shade_row(surface, rays, hits, s_rgb);
    return layers.data();
  }

  // The lit pieces' airlight added light by light: per piece e^(-sigma_t (a - t0)) S(a) - e^(-sigma_t
  // (b - t0)) S(b), S the light's tails; a piece whose difference would cancel flags its ray.
  void add_lit_pieces(const RowRays& r, const std::vector<LitPiece>& pieces, float* l_rgb, float* redo) const {
    thread_local std::vector<float> kept;
    std::vector<float>& scratch = kept;
    for (size_t l = 0; l < lights_.size(); ++l) {
      size_t count = 0;
      for (const LitPiece& p : pieces) count += p.light == l;
      if (count == 0) continue;
      const size_t padded = padded_count(count);
      scratch.assign(26 * padded, 0.0f);
      float *t = scratch.data(), *h = t + padded, *a = h + padded, *b = a + padded, *sa = b + padded, *sb = sa + 3 * padded;
      float *t0 = sb + 3 * padded, *ta = t0 + padded, *tb = ta + 3 * padded, *b_at = tb + 3 * padded, *unused = b_at + padded;
      size_t k = 0;
      for (const LitPiece& p : pieces) {
        if (p.light != l) continue;
        t[k] = r.geometry[3 * l * r.padded + p.x], h[k] = r.geometry[(3 * l + 1) * r.padded + p.x], t0[k] = r.t0[p.x];
        a[k] = static_cast<float>(p.a), b[k] = std::isfinite(p.b) ? static_cast<float>(p.b) : INFINITY;
        ++k;
      }
      TailLight tails[3];
      for (size_t c = 0; c < r.tails_per_light; ++c) {
        tails[c] = r.tails[l * r.tails_per_light + c];
        tails[c].t = t, tails[c].h = h, tails[c].share = nullptr;
      }
      TailRow row{tails, r.tails_per_light, nullptr, nullptr, {}, {}, count};
      float* const at_a[3] = {sa, sa + padded, sa + 2 * padded};
      float* const at_b[3] = {sb, sb + padded, sb + 2 * padded};
      tail_sums(table_, row, a, at_a);
      for (size_t i = 0; i < count; ++i) b_at[i] = std::isfinite(b[i]) ? b[i] : a[i];  // an endless piece: T = 0 takes its tails
      tail_sums(table_, row, b_at, at_b);
      // e^(-sigma_t (a - t0)) and e^(-sigma_t (b - t0)) per channel in lanes: layers_from_tails'
      // transmittance from t0 to a and to b (its L_in, from zero tails, unused).
      row.t0 = t0, row.whole[0] = row.whole[1] = row.whole[2] = unused;
      for (size_t c = 0; c < 3; ++c) row.sigma_t[c] = static_cast<float>(sigma_t_[c]);
      layers_from_tails(row, a, row.whole, unused, ta, unused);
      layers_from_tails(row, b, row.whole, unused, tb, unused);
      k = 0;
      for (const LitPiece& p : pieces) {
        if (p.light != l) continue;
        for (size_t c = 0; c < 3; ++c) {
          const float near = ta[3 * k + c] * at_a[c][k], far = tb[3 * k + c] * at_b[c][k];
          if (far > kTailsCancel * near) redo[p.x] = 1.0f;
          l_rgb[3 * p.x + c] += std::max(0.0f, near - far);
        }
        ++k;
      }
    }
  }

  // The row's pixels that hit `surface`, shaded in SIMD lanes into s_rgb (RGB triples).
  template <class Hits>
  void shade_row(const Surface& surface, const std::vector<Ray>& rays, const Hits& hits, float* s_rgb) const {
    const size_t lights = lights_.size();
    thread_local std::vector<size_t> kept_at;
    thread_local std::vector<float> kept;
    std::vector<size_t>& at = kept_at;
    at.clear();
    for (size_t x = 0; x < hits.size(); ++x)
      if (hits[x].surface == &surface) at.push_back(x);
    if (at.empty()) return;
    const size_t padded = padded_count(at.size());
    std::vector<float>& f = kept;
    f.assign((10 + lights + 3) * padded, 0.0f);
    const auto part = [&](size_t k) { return f.data() + k * padded; };
    const Aabb bounds = medium_->bounds();
    thread_local std::vector<double> kept_points;
    std::vector<double>& points64 = kept_points;
    points64.assign(3 * padded, 0.0);
    const double* const x64[3] = {points64.data(), points64.data() + padded, points64.data() + 2 * padded};
    for (size_t i = 0; i < at.size(); ++i) {
      const auto& h = hits[at[i]];
      const Ray& ray = rays[at[i]];
      const Vec3 p = ray.at(h.t);
      for (size_t e = 0; e < 3; ++e) {
        part(e)[i] = static_cast<float>(p[static_cast<int>(e)]), part(3 + e)[i] = static_cast<float>(h.normal[static_cast<int>(e)]);
        part(6 + e)[i] = static_cast<float>(ray.direction[static_cast<int>(e)]);
      }
      part(9)[i] = surface_airlight_ && bounds.contains(off_surface(p, h.normal)) ? 1.0f : 0.0f;
      for (size_t e = 0; e < 3; ++e) points64[e * padded + i] = p[static_cast<int>(e)];
    }
    // Whether each light is hidden (shade_points takes it where the normal faces it).
    for (size_t l = 0; l < lights; ++l) light_visible(shadows_[l], x64, at.size(), nullptr, part(10 + l));
    thread_local std::vector<ShadingLight> kept_lights;
    std::vector<ShadingLight>& shading = kept_lights;
    shading.clear();
    for (size_t l = 0; l < lights; ++l) {
      const AnalyticLight& light = lights_[l];
      shading.push_back({{static_cast<float>(light.position.x), static_cast<float>(light.position.y), static_cast<float>(light.position.z)},
                         {static_cast<float>(light.intensity.r), static_cast<float>(light.intensity.g), static_cast<float>(light.intensity.b)},
                         part(10 + l)});
    }
    const ShadingMaterial material{{static_cast<float>(surface.kd.r), static_cast<float>(surface.kd.g), static_cast<float>(surface.kd.b)},
                                   {static_cast<float>(surface.ks.r), static_cast<float>(surface.ks.g), static_cast<float>(surface.ks.b)},
                                   static_cast<float>(surface.shininess),
                                   surface_airlight_ && lambert_ && surface.kd != Rgb(0.0) ? &*lambert_ : nullptr,
                                   surface_airlight_ && surface.ks != Rgb(0.0) ? &phong_.at(surface.shininess) : nullptr};
    const ShadingPoints points{{part(0), part(1), part(2)}, {part(3), part(4), part(5)}, {part(6), part(7), part(8)}, part(9), at.size()};
    float* const radiance = part(10 + lights);
    shade_points(shading_medium_, material, shading.data(), lights, points, radiance);
    for (size_t i = 0; i < at.size(); ++i) std::copy_n(radiance + 3 * i, 3, s_rgb + 3 * at[i]);
  }

  // render_layers' row y, copied into the caller's spans.
  void layers_row(const View& view, int y, LayerSpans out) const {
    const auto width = static_cast<size_t>(view.camera.width_px);
    const size_t padded = padded_count(width);
    const float* const rgb = row_layers(view, y);
    const auto copy_row = [&](const float* from, ImageSpan to) {
      if (!to.data) return;
      if (to.channels == 3) {
        std::copy_n(from, 3 * width, to.pixel(0, y));
        return;
      }
      for (size_t x = 0; x < width; ++x) std::copy_n(from + 3 * x, 3, to.pixel(static_cast<int>(x), y));
    };
    copy_row(rgb, out.inscatter), copy_row(rgb + 3 * padded, out.transmittance), copy_row(rgb + 6 * padded, out.surface);
  }

  // The point lights' airlight along [t0, end] of a ray by the float64 segment path, over the
  // stretches each light lights.
  Rgb exact_airlight(const Ray& ray, double t0, double end) const {
    const Ray entry{ray.at(t0), ray.direction};
    thread_local std::vector<std::pair<double, double>> kept;
    std::vector<std::pair<double, double>>& stretches = kept;
    Rgb sum(0.0);
    for (const auto& light : lights_) {
      const Vec3& p = light.position;
      stretches.clear();
      if (!view_shadows_ || scene_.surfaces.empty()) stretches.emplace_back(0.0, end - t0);
      else lit_stretches(scene_.surfaces, entry, 0.0, end - t0, p, stretches);
      for (const auto& [a, b] : stretches) {
        const Vec3 o = entry.at(a);
        const float ox = static_cast<float>(o.x), oy = static_cast<float>(o.y), oz = static_cast<float>(o.z);
        const float dx = static_cast<float>(ray.direction.x), dy = static_cast<float>(ray.direction.y), dz = static_cast<float>(ray.direction.z);
        const float length = std::isfinite(b) ? static_cast<float>(b - a) : INFINITY;
        const SegmentBatch segment{&ox, &oy, &oz, &dx, &dy, &dz, &length, 1};
        for (int c = 0; c < (grey_ ? 1 : 3); ++c) {
          float v = 0.0f;
          add_airlight_float64(table_, {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z), static_cast<float>(sigma_t_[c]),
                                        static_cast<float>(sigma_s_[c]), grey_ ? 1.0f : static_cast<float>(light.intensity[c])},
                               segment, &v);
          if (grey_) sum += std::exp(-sigma_t_[c] * a) * static_cast<double>(v) * light.intensity;
          else sum[c] += std::exp(-sigma_t_[c] * a) * static_cast<double>(v);
        }
      }
    }
    return sum;
  }

  // add_glow's pixels [x0, x1) of row y for light l: L_in = share (S(t0) - T(end) S(end)) per
  // channel, S the light's tails, `end` the ray's end in the medium (the view's depth or t1).
  void glow_row(const View& view, size_t l, double glow_angle, int y, int x0, int x1, ImageSpan out) const {
    const auto count = static_cast<size_t>(x1 - x0);
    const RowRays r = ray_tails(view.camera, y, x0, count, glow_angle, l, true);
    thread_local std::vector<float> kept;
    std::vector<float>& layers = kept;
    layers.resize(7 * padded_count(count));
    tails_to_layers(r, end_tails(row_ends(view_depths(view, y, x0, count), r, count), r, count), count, layers.data());  // no float64 redo here
    for (size_t i = 0; i < count; ++i) {
      float* pixel = out.pixel(x0 + static_cast<int>(i), y);
      for (int c = 0; c < 3; ++c) pixel[c] += layers[3 * i + static_cast<size_t>(c)];
    }
  }

  // A point light's airlight over `batch` into `unit`, then accumulate(scale): unit times scale is
  // the RGB airlight. Grey media take one batch at unit intensity scaled per channel (the airlight
  // is linear in I), others one batch per channel.
  template <class Accumulate>
  void light_airlight(AirlightKernel add_airlight, const AnalyticLight& light, const SegmentBatch& batch, std::vector<float>& unit,
                      Accumulate accumulate) const {
    const Vec3& p = light.position;
    auto add = [&](int c, float intensity, const Rgb& scale) {
      unit.assign(batch.count, 0.0f);
      add_airlight(table_, {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z), static_cast<float>(sigma_t_[c]),
                            static_cast<float>(sigma_s_[c]), intensity},
                   batch, unit.data());
      accumulate(scale);
    };
    if (grey_) {
      add(0, 1.0f, light.intensity);
      return;
    }
    for (int c = 0; c < 3; ++c) {
      if (sigma_s_[c] == 0.0 || light.intensity[c] == 0.0) continue;
      Rgb only(0.0);
      only[c] = 1.0;
      add(c, static_cast<float>(light.intensity[c]), only);
    }
  }

  const Scene scene_;
  const std::vector<AnalyticLight> lights_;
  std::vector<double> positions_;  // the lights' positions, xyz each (RowGeometry::lights)
  std::vector<LightShadows> shadows_;  // per light, over scene_.surfaces
  ShadingMedium shading_medium_;
  const std::unique_ptr<Medium> medium_;
  const Rgb sigma_t_, sigma_s_;
  const bool grey_, airlight_, surface_airlight_, view_shadows_;
  const AirlightKernel kernel_;
  const AirlightTable table_;
  const std::optional<SurfaceAirlightTable> lambert_;
  const std::map<double, SurfaceAirlightTable> phong_;
};

class AnalyticMethod final : public Method {
 public:
  // Tables stay with this object between renders: reuse one object (haze::create_method) to
  // change g, lights or the camera every frame without rebuilding or rereading them.
  template <class T, class Make>
  std::shared_ptr<const T> memo(const std::string& key, bool& reused, Make make) const {
    std::lock_guard lock(mutex_);
    if (auto it = tables_.find(key); it != tables_.end()) return std::static_pointer_cast<const T>(it->second);
    bool hit = false;  // read from the disk cache
    auto value = std::make_shared<const T>(make(hit));
    reused &= hit;
    tables_[key] = value;
    return value;
  }

  std::unique_ptr<MethodSolution> prepare(const Scene& scene, const RenderOptions& options) const override {
    Settings settings(options.settings, kAnalyticName);
    const int a_samples = static_cast<int>(settings.integer("table_a"));
    const int eta_samples = static_cast<int>(settings.integer("table_eta"));
    const bool surface_airlight = settings.integer("surface_airlight") == 1;
    const bool airlight = settings.integer("airlight") == 1;
    const bool view_shadows = settings.integer("view_shadows") == 1;
    // Dynamic g (seed 002 sec. 4.3): > 0 builds g-independent Legendre tables (cached) and sums
    // them for the scene's g with enough orders for this relative tolerance.
    const double dynamic_g = settings.number("dynamic_g_tolerance");
    const bool simd_kernel = settings.choice("kernel") == "simd";
    settings.reject_unknown();

    if (!scene.medium) throw Error("medium", "missing", "a homogeneous medium for the analytic method");
    const MediumDesc& desc = *scene.medium;
    const auto* constant = std::get_if<ConstantDensity>(&desc.density);
    if (!constant) throw Error("medium.density.type", "heterogeneous", "\"constant\" for the analytic method (use propagation or reference)");
    std::vector<AnalyticLight> lights;
    for (size_t i = 0; i < scene.lights.size(); ++i) {
      if (auto* p = std::get_if<PointLight>(&scene.lights[i])) {
        lights.push_back({*p, p->position, p->intensity});
      } else if (auto* sp = std::get_if<SpotLight>(&scene.lights[i])) {
        lights.push_back({*sp, sp->position, sp->intensity});
      } else {
        throw Error("lights[" + std::to_string(i) + "].type", "a directional or sky light",
                    "point or spot lights for the analytic method");
      }
    }

    const Stopwatch watch;
    auto medium = make_medium(desc);
    const Rgb sigma_t = desc.sigma_t * constant->value;
    const Rgb sigma_s = desc.albedo * sigma_t;
    // A grey medium (the same coefficients in every channel) needs one airlight evaluation per light.
    const bool grey = is_grey(sigma_t) && is_grey(sigma_s);
    // Tables come from this object's memory when an earlier render made them, else from
    // options.cache_dir when it is set and holds them, else they are built.
    const bool use_cache = !options.cache_dir.empty();
    bool all_reused = true;
    const std::string sizes = std::to_string(a_samples) + "x" + std::to_string(eta_samples);
    auto airlight_table = [&] {
      return memo<AirlightTable>("airlight " + desc.phase.key() + " " + sizes, all_reused, [&](bool& hit) {
        if (!use_cache) return AirlightTable(desc.phase, a_samples, eta_samples, options.threads);
        return AirlightTable::cached(desc.phase, options.cache_dir, a_samples, eta_samples, options.threads, &hit);
      });
    };
    // Dynamic g: g-independent Legendre tables (airlight and surface), summed for the scene's g.
    int legendre_terms = 0;
    double truncation_bound = 0.0;
    std::shared_ptr<const LegendreAirlightTables> legendre;
    double g = 0.0;
    if (dynamic_g > 0.0) {
      const auto* hg = desc.phase.parameters<PhaseFunction::HenyeyGreenstein>();
      if (!hg) throw Error("medium.phase.type", "\"" + desc.phase.name() + "\"", "\"hg\" for method.dynamic_g_tolerance");
      g = hg->g;
      legendre_terms = LegendreAirlightTables::terms_for(g, dynamic_g, 64);
      truncation_bound = LegendreAirlightTables::truncation_bound(g, legendre_terms);
      // Orders in steps of 16, so nearby g and tolerances share tables.
      const int orders = (legendre_terms + 15) / 16 * 16;
      legendre = memo<LegendreAirlightTables>("legendre " + std::to_string(orders) + " " + sizes, all_reused, [&](bool& hit) {
        if (!use_cache) return LegendreAirlightTables(orders, a_samples, eta_samples, options.threads);
        return LegendreAirlightTables::cached(orders, options.cache_dir, a_samples, eta_samples, options.threads, &hit);
      });
    }
    const AirlightTable table = legendre ? legendre->combine_hg(g, legendre_terms) : *airlight_table();
    auto surface_table = [&](double exponent) {
      const std::string n = " n=" + to_text(exponent);
      if (legendre) {
        return memo<LegendreSurfaceTables>(legendre->key() + n, all_reused, [&](bool& hit) {
                 if (!use_cache) return LegendreSurfaceTables(*legendre, exponent, 64, 64, options.threads);
                 return LegendreSurfaceTables::cached(*legendre, exponent, options.cache_dir, 64, 64, options.threads, &hit);
               })
            ->combine_hg(g, legendre_terms);
      }
      return *memo<SurfaceAirlightTable>(table.key() + n, all_reused, [&](bool& hit) {
        if (!use_cache) return SurfaceAirlightTable(table, exponent, 64, 64, options.threads);
        return SurfaceAirlightTable::cached(table, exponent, options.cache_dir, 64, 64, options.threads, &hit);
      });
    };
    // J1 for diffuse surfaces and one J_n per Phong exponent in the scene.
    std::optional<SurfaceAirlightTable> lambert;
    std::map<double, SurfaceAirlightTable> phong;
    if (surface_airlight) {
      for (const auto& s : scene.surfaces) {
        if (s.kd != Rgb(0.0) && !lambert) lambert.emplace(surface_table(0.0));
        if (s.ks != Rgb(0.0) && !phong.count(s.shininess)) phong.emplace(s.shininess, surface_table(s.shininess));
      }
    }
    auto solution = std::make_unique<AnalyticSolution>(scene, std::move(lights), std::move(medium), sigma_t, sigma_s, grey, airlight,
                                                       surface_airlight, view_shadows, simd_kernel ? &add_airlight : &add_airlight_float64, table, std::move(lambert), std::move(phong));
    solution->stats = {{"table_seconds", watch.seconds()},
                       {"airlight_path", simd_kernel ? "simd" : "float64"},
                       {"tables_reused", all_reused},
                       {"table", {a_samples, eta_samples}},
                       {"legendre_terms", legendre_terms},
                       {"truncation_bound", truncation_bound}};
    return solution;
  }

 private:
  mutable std::mutex mutex_;
  mutable std::map<std::string, std::shared_ptr<const void>> tables_;
};

}  // namespace

MethodInfo analytic_info() {
  MethodInfo info;
  info.name = kAnalyticName;
  info.summary = "closed-form single scattering, homogeneous medium, point and spot lights (seed 002; the airlight unshadowed)";
  info.create = [] { return std::make_unique<AnalyticMethod>(); };
  info.handles = {"constant density (bounded or not)", "point, spot",
                  "planes, spheres and meshes lit by unscattered light and the airlight, with shadows (not of the airlight onto them)", false};
  info.settings = {SettingInfo::integer("table_a", 256, 16, 4096, "airlight table samples along A = T_sv sin(gamma)"),
                   SettingInfo::integer("table_eta", 512, 16, 4096, "airlight table samples along the angle eta"),
                   SettingInfo::integer("surface_airlight", 1, 0, 1, "1: surfaces also receive the airlight (tables J1 and J_n)"),
                   SettingInfo::integer("airlight", 1, 0, 1, "0: leave out the view ray's airlight (surfaces only)"),
                   SettingInfo::integer("view_shadows", 1, 0, 1,
                                        "0: surfaces do not shadow the view rays' airlight, as the thesis renders (its sec. 6.2.2 leaves volumetric shadows to future work)"),
                   SettingInfo::number("dynamic_g_tolerance", 0.0, 0.0, 0.5,
                                       "> 0: sum g-independent Legendre tables for the scene's HG g to this relative tolerance"),
                   SettingInfo::choice("kernel", "simd", {"simd", "float64"},
                                       "the view rays' airlight: float32 Highway lanes (within 1e-3 of quadrature), or the table evaluated in float64")};
  for (auto [a, eta] : {std::pair{64, 128}, {128, 256}, {256, 512}}) info.trade_sweep.push_back({{"table_a", a}, {"table_eta", eta}});
  info.offer = [](const SceneFeatures& f, double tolerance) {
    if (!single_scattering_suffices(f, tolerance)) return AutoOffer{false, {}, 0.0, "multiple scattering matters"};
    if (!f.homogeneous || f.sky || f.directional) return AutoOffer{false, {}, 0.0, "needs a homogeneous medium and point or spot lights"};
    return AutoOffer{true, {{"table_a", 128}, {"table_eta", 256}}, 0.003, "homogeneous medium, point and spot lights (thin_haze: 0.0027 s)"};
  };
  info.single_scattering = true;
  return info;
}

void register_methods() { register_method(analytic_info()); }

}  // namespace haze::analytic
