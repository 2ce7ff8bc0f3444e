// render_network's splat (network.h, NetworkRender::splat): each particle's radiance toward the eye,
// then its footprint on a lattice of camera rays, front to back, in SIMD lanes (splat.h).
#include <haze/particles/splat.h>

#include "network_internal.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace haze::particles::network_internal {

namespace {

constexpr int kTile = 16;  // lattice nodes on a tile's side: rows of 16 lanes
// The direct light's log-slope across a particle is held to this per width.
constexpr double kMaxSlope = 4.0;

// The mean and variance, in widths h, of where a Gaussian's light toward the start of a ray
// through its centre comes from, when its optical depth along the ray is x: the weight
// rho(t) e^(-x F(t)) (F the share of the Gaussian before t), tabulated over x once.
struct DepthMoments {
  double mean, variance;
};
DepthMoments depth_moments(double x) {
  static constexpr int kEntries = 128;
  static constexpr double kEnd = 32.0;  // past it, the value at kEnd
  static const std::array<DepthMoments, kEntries + 1> table = [] {
    std::array<DepthMoments, kEntries + 1> t{};
    constexpr int kSteps = 600;
    for (int e = 0; e <= kEntries; ++e) {
      const double depth = e * (kEnd / kEntries);
      double sum = 0.0, first = 0.0, second = 0.0;
      for (int i = 0; i < kSteps; ++i) {  // midpoints over [-kCut, kCut] widths
        const double u = -kCut + (i + 0.5) * (2.0 * kCut / kSteps);
        const double weight = std::exp(-u * u - depth * 0.5 * (1.0 + std::erf(u)));
        sum += weight, first += weight * u, second += weight * u * u;
      }
      const double mean = first / sum;
      t[static_cast<size_t>(e)] = {mean, second / sum - mean * mean};
    }
    return t;
  }();
  const double a = std::clamp(x, 0.0, kEnd) * (kEntries / kEnd);
  const auto k = std::min(static_cast<size_t>(a), static_cast<size_t>(kEntries - 1));
  const double f = a - static_cast<double>(k);
  return {(1 - f) * table[k].mean + f * table[k + 1].mean, (1 - f) * table[k].variance + f * table[k + 1].variance};
}

// The particles, structure of arrays (splat.h).
struct Particles {
  std::vector<float> x, y, z, h, amplitude, source[3], direct[3], gx, gy, gz, max_log, shift, spread;
  explicit Particles(size_t n) : x(n), y(n), z(n), h(n), amplitude(n), gx(n), gy(n), gz(n), max_log(n), shift(n), spread(n) {
    for (int c = 0; c < 3; ++c) source[c].resize(n), direct[c].resize(n);
  }
  void set(size_t p, const Vec3& centre, double width, double line_integral, const Rgb& scattered, const Rgb& direct_light, const Vec3& gradient,
           double bound, double mean, double half_variance) {
    x[p] = static_cast<float>(centre.x), y[p] = static_cast<float>(centre.y), z[p] = static_cast<float>(centre.z);
    h[p] = static_cast<float>(width), amplitude[p] = static_cast<float>(line_integral);
    for (int c = 0; c < 3; ++c) source[c][p] = static_cast<float>(scattered[c]), direct[c][p] = static_cast<float>(direct_light[c]);
    gx[p] = static_cast<float>(gradient.x), gy[p] = static_cast<float>(gradient.y), gz[p] = static_cast<float>(gradient.z);
    max_log[p] = static_cast<float>(bound), shift[p] = static_cast<float>(mean), spread[p] = static_cast<float>(half_variance);
  }
  SplatParticles view(const std::vector<uint32_t>& order) const {
    return {x.data(),  y.data(),  z.data(),     h.data(),      amplitude.data(), {source[0].data(), source[1].data(), source[2].data()},
            {direct[0].data(), direct[1].data(), direct[2].data()}, gx.data(), gy.data(), gz.data(), max_log.data(), shift.data(), spread.data(),
            order.data(), order.size()};
  }
};

// The film positions the rays pass through: node (i, j) at ((i s + 0.5), (j s + 0.5)) for i < nx, j < ny.
// s = 1: the pixels' centres; s > 1: a coarser lattice the image is interpolated from, nodes
// reaching past the last pixel.
struct Lattice {
  int s, nx, ny;
  Lattice(int step, int width, int height)
      : s(step), nx(step == 1 ? width : (width - 1) / step + 2), ny(step == 1 ? height : (height - 1) / step + 2) {}
};

// A tile's rays, kTile x kTile nodes (those past the lattice repeat its last), in structure of
// arrays for splat_rays, and what it writes.
struct TileRays {
  static constexpr size_t kRays = kTile * kTile;
  static_assert(kTile % kSplatPad == 0);
  std::array<Ray, kRays> ray;
  std::array<Rgb, kRays> leaving;
  std::array<float, kRays> ox, oy, oz, dx, dy, dz, t_end;
  std::array<float, kRays> radiance[3], transmittance[3];

  void fill(const Camera& cam, const Lattice& lattice, int x0, int x1, int y0, int y1) {
    for (int y = 0; y < kTile; ++y) {
      Ray* row = &ray[static_cast<size_t>(y * kTile)];
      const int j = std::min(y0 + y, y1 - 1);
      if (lattice.s == 1) cam.row_rays(j, x0, x1, row);
      else
        for (int i = x0; i < x1; ++i) row[i - x0] = cam.generate_ray(i * lattice.s + 0.5, j * lattice.s + 0.5);
      std::fill(row + (x1 - x0), row + kTile, row[x1 - x0 - 1]);
    }
    for (size_t j = 0; j < kRays; ++j) {
      ox[j] = static_cast<float>(ray[j].origin.x), oy[j] = static_cast<float>(ray[j].origin.y), oz[j] = static_cast<float>(ray[j].origin.z);
      dx[j] = static_cast<float>(ray[j].direction.x), dy[j] = static_cast<float>(ray[j].direction.y), dz[j] = static_cast<float>(ray[j].direction.z);
    }
    t_end.fill(std::numeric_limits<float>::infinity());
  }
  SplatRays rays(bool ends) {
    return {ox.data(), oy.data(), oz.data(), dx.data(), dy.data(), dz.data(), ends ? t_end.data() : nullptr,
            {radiance[0].data(), radiance[1].data(), radiance[2].data()}, {transmittance[0].data(), transmittance[1].data(), transmittance[2].data()}, kRays};
  }
};

}  // namespace

int splat_network(const SplatInputs& in, std::span<const uint32_t> front_to_back, const PixelSink& sink, const RenderOptions& options) {
  const ParticleField& field = in.field;
  const MaterialDesc& material = field.particles().material;
  const Camera& cam = in.camera;
  const size_t n = field.size();
  // Each particle's radiance toward the eye: its scattered light, and the direct light at its
  // centre with the gradient of its logarithm (central differences over half a width), at most
  // the light unattenuated (no medium, no surfaces; a point light's as at one width nearer).
  const auto unattenuated = [&](const Vec3& x, const Vec3& w, double h) {
    Rgb s(0.0);
    for (const LightDepthMap& map : in.solution.light_maps) {
      LightArrival a;
      if (!arrival(map.light(), x, a)) continue;
      const double nearer = std::isinf(a.distance) ? 1.0 : a.distance / std::max(a.distance - h, in.nearest);
      s += material.phase.eval(glm::dot(-a.to_light, w)) * a.irradiance * nearer * nearer;
    }
    return material.albedo * s;
  };
  const auto luminance = [](const Rgb& c) { return c.r + c.g + c.b; };
  Particles particles(n);
  const double sigma_mean = (material.sigma_t.r + material.sigma_t.g + material.sigma_t.b) / 3.0;
  parallel_for(static_cast<long long>(n), options.threads, 64, [&](long long p0, long long p1) {
    for (auto p = static_cast<size_t>(p0); p < static_cast<size_t>(p1); ++p) {
      const Vec3 x = field.position(p), w = in.toward_eye(x);
      const double h = field.h(p), amplitude = field.weight(p) * std::sqrt(kPi) * h;
      const Rgb centre = in.direct(x, w);
      Vec3 gradient(0.0);
      double max_log = 0.0;
      if (const double at = luminance(centre); at > 0.0) {
        for (int a = 0; a < 3; ++a) {
          Vec3 e(0.0);
          e[a] = 0.5 * h;
          const double ahead = luminance(in.direct(x + e, w)), behind = luminance(in.direct(x - e, w));
          gradient[a] = std::clamp(std::log(std::max(ahead, 1e-30) / std::max(behind, 1e-30)) / h, -kMaxSlope / h, kMaxSlope / h);
        }
        max_log = std::log(std::max(luminance(unattenuated(x, w, h)) / at, 1.0));
      }
      const DepthMoments moments = depth_moments(sigma_mean * amplitude);
      particles.set(p, x, h, amplitude, in.scattered[p], centre, gradient, max_log, moments.mean * h, 0.5 * moments.variance * h * h);
    }
  });

  // The lattice: a node per kSplatNodesPerWidth of the narrowest footprint's width h in pixels,
  // where no ray ends early (no surfaces, no host depth) and the camera has a film to project on;
  // else the pixels themselves.
  const FilmProjection project{cam};
  int step = 1;
  if (!in.end_of && cam.type != Camera::Type::matrices) {
    double narrowest = kInfinity;
    for (const uint32_t p : front_to_back) {
      double px, py, radius;
      if (project(field.position(p), kCut * field.h(p), px, py, radius)) narrowest = std::min(narrowest, (radius - 1.0) / kCut);
    }
    if (std::isfinite(narrowest)) step = std::clamp(static_cast<int>(narrowest / kSplatNodesPerWidth), 1, std::max(cam.width_px, cam.height_px));
  }
  const Lattice lattice(step, cam.width_px, cam.height_px);
  // Particles binned to tiles of nodes by their footprints, each tile's front to back.
  const int tiles_x = (lattice.nx + kTile - 1) / kTile, tiles_y = (lattice.ny + kTile - 1) / kTile;
  std::vector<std::vector<uint32_t>> tiles(static_cast<size_t>(tiles_x) * static_cast<size_t>(tiles_y));
  for (const uint32_t p : front_to_back) {
    double px, py, radius;
    if (!project(field.position(p), kCut * field.h(p), px, py, radius)) continue;
    px = (px - 0.5) / step, py = (py - 0.5) / step, radius /= step;
    const int x0 = std::max(0, static_cast<int>(std::floor((px - radius) / kTile))), x1 = std::min(tiles_x - 1, static_cast<int>(std::floor((px + radius) / kTile)));
    const int y0 = std::max(0, static_cast<int>(std::floor((py - radius) / kTile))), y1 = std::min(tiles_y - 1, static_cast<int>(std::floor((py + radius) / kTile)));
    for (int ty = y0; ty <= y1; ++ty)
      for (int tx = x0; tx <= x1; ++tx) tiles[static_cast<size_t>(ty * tiles_x + tx)].push_back(p);
  }

  const float sigma_t[3] = {static_cast<float>(material.sigma_t.r), static_cast<float>(material.sigma_t.g), static_cast<float>(material.sigma_t.b)};
  const int channels = sigma_t[0] == sigma_t[1] && sigma_t[1] == sigma_t[2] ? 1 : 3;
  const auto nodes = static_cast<size_t>(lattice.nx) * static_cast<size_t>(lattice.ny);
  std::array<std::vector<float>, 3> node_radiance, node_transmittance;  // the lattice's, when interpolated
  if (step > 1)
    for (int c = 0; c < 3; ++c) node_radiance[static_cast<size_t>(c)].resize(nodes), node_transmittance[static_cast<size_t>(c)].resize(nodes);
  ProgressTracker progress(options.progress, static_cast<long long>(tiles.size()));
  parallel_for(static_cast<long long>(tiles.size()), options.threads, 1, [&](long long t0, long long t1) {
    thread_local TileRays buffer;
    TileRays& rays = buffer;
    for (auto t = t0; t < t1 && !progress.cancelled(); ++t) {
      const int x0 = static_cast<int>(t % tiles_x) * kTile, y0 = static_cast<int>(t / tiles_x) * kTile;
      const int x1 = std::min(lattice.nx, x0 + kTile), y1 = std::min(lattice.ny, y0 + kTile);
      rays.fill(cam, lattice, x0, x1, y0, y1);
      if (in.end_of)
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x) {
            const size_t j = static_cast<size_t>((y - y0) * kTile + (x - x0));
            double t_end;
            rays.leaving[j] = in.end_of(x, y, rays.ray[j], t_end);
            rays.t_end[j] = static_cast<float>(t_end);
          }
      splat_rays(particles.view(tiles[static_cast<size_t>(t)]), sigma_t, channels, rays.rays(in.end_of != nullptr));
      for (int y = y0; y < y1; ++y) {
        PixelLayers run[kTile];
        for (int x = x0; x < x1; ++x) {
          const size_t j = static_cast<size_t>((y - y0) * kTile + (x - x0));
          if (step == 1) {
            const Rgb leaving = in.end_of ? rays.leaving[j] : in.background;
            run[x - x0] = {Rgb(rays.radiance[0][j], rays.radiance[1][j], rays.radiance[2][j]),
                           Rgb(rays.transmittance[0][j], rays.transmittance[1][j], rays.transmittance[2][j]), leaving};
          } else {
            const size_t node = static_cast<size_t>(y) * static_cast<size_t>(lattice.nx) + static_cast<size_t>(x);
            for (size_t c = 0; c < 3; ++c) node_radiance[c][node] = rays.radiance[c][j], node_transmittance[c][node] = rays.transmittance[c][j];
          }
        }
        if (step == 1) sink(y, x0, {run, static_cast<size_t>(x1 - x0)});
      }
      progress.advance();
    }
  });
  progress.throw_if_cancelled();
  if (step == 1) return step;
  // Each pixel bilinear between its lattice's nodes, in float32: each row's nodes blended between
  // their node rows, then each pixel between two of those; into the caller's layers, or the sink.
  const auto nx = static_cast<size_t>(lattice.nx);
  parallel_for(cam.height_px, options.threads, 16, [&](long long y0, long long y1) {
    thread_local std::vector<float> kept_mixed;  // [layer][node]: L_in's channels, then T's
    thread_local std::vector<PixelLayers> kept_row;  // a row's, handed to the sink at once
    std::vector<float>& mixed = kept_mixed;
    std::vector<PixelLayers>& row = kept_row;
    mixed.resize(6 * nx);
    if (!in.layers) row.resize(static_cast<size_t>(cam.width_px));
    for (auto y = static_cast<int>(y0); y < static_cast<int>(y1); ++y) {
      const auto j = static_cast<size_t>(y / step);
      const float fy = static_cast<float>(y % step) / static_cast<float>(step);
      for (size_t c = 0; c < 6; ++c) {
        const float* v = (c < 3 ? node_radiance[c] : node_transmittance[c - 3]).data() + j * nx;
        float* m = mixed.data() + c * nx;
        for (size_t i = 0; i < nx; ++i) m[i] = v[i] + fy * (v[i + nx] - v[i]);
      }
      // The row's pixels in the caller's layers, held in locals: stores through the spans' own
      // pointers would reload them after each (they might alias).
      float* const to[3] = {in.layers ? in.layers->inscatter.pixel(0, y) : nullptr, in.layers ? in.layers->transmittance.pixel(0, y) : nullptr,
                            in.layers && in.layers->surface.data ? in.layers->surface.pixel(0, y) : nullptr};
      const size_t channels[3] = {in.layers ? static_cast<size_t>(in.layers->inscatter.channels) : 0,
                                  in.layers ? static_cast<size_t>(in.layers->transmittance.channels) : 0,
                                  to[2] ? static_cast<size_t>(in.layers->surface.channels) : 0};
      const float behind[3] = {static_cast<float>(in.background.r), static_cast<float>(in.background.g), static_cast<float>(in.background.b)};
      for (int x = 0; x < cam.width_px; ++x) {
        const auto i = static_cast<size_t>(x / step);
        const float fx = static_cast<float>(x % step) / static_cast<float>(step);
        float layer[6];
        for (size_t c = 0; c < 6; ++c) {
          const float* m = mixed.data() + c * nx + i;
          layer[c] = m[0] + fx * (m[1] - m[0]);
        }
        if (to[0]) {
          const auto at = static_cast<size_t>(x);
          std::copy(layer, layer + 3, to[0] + at * channels[0]);
          std::copy(layer + 3, layer + 6, to[1] + at * channels[1]);
          if (to[2]) std::copy(behind, behind + 3, to[2] + at * channels[2]);
        } else {
          row[static_cast<size_t>(x)] = {Rgb(layer[0], layer[1], layer[2]), Rgb(layer[3], layer[4], layer[5]), in.background};
        }
      }
      if (!in.layers) sink(y, 0, row);
    }
  });
  return step;
}

}  // namespace haze::particles::network_internal
