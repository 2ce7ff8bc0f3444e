#include <haze/core/error.h>
#include <haze/core/progress.h>
#include <haze/froxels/froxels.h>

#include <haze/froxels/composite_row.h>

#include "build.h"

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/trigonometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

namespace haze {

namespace froxels_detail {

Camera column_camera(const Camera& c, int nx, int ny) {
  const double aspect = static_cast<double>(c.width_px) / c.height_px;
  switch (c.type) {
    case Camera::Type::pinhole:
      return Camera::from_matrices(glm::lookAt(c.position, c.look_at, c.up), glm::perspective(glm::radians(c.fov_y_deg), aspect, 0.1, 100.0), nx, ny);
    case Camera::Type::orthographic: {
      const double half = 0.5 * c.height;
      return Camera::from_matrices(glm::lookAt(c.position, c.look_at, c.up), glm::ortho(-half * aspect, half * aspect, -half, half, -1.0, 1.0), nx, ny);
    }
    case Camera::Type::matrices: {
      Camera out = c;
      out.width_px = nx, out.height_px = ny;
      return out;
    }
    case Camera::Type::rays: break;
  }
  auto rays = std::make_shared<std::vector<Ray>>();
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) rays->push_back(c.generate_ray((i + 0.5) * c.width_px / nx, (j + 0.5) * c.height_px / ny));
  return Camera::from_rays(rays, nx, ny);
}

}  // namespace froxels_detail

namespace {

void check(const FroxelGrid& g) {
  for (const auto& [name, n] : {std::pair{"nx", g.nx}, std::pair{"ny", g.ny}, std::pair{"nz", g.nz}})
    if (n < 1 || n > 4096) throw Error(std::string("froxels.") + name, std::to_string(n), "an integer in [1, 4096]");
  if (!(g.far > 0.0 && std::isfinite(g.far))) throw Error("froxels.far", to_text(g.far), "a finite distance > 0");
  if (!(g.near > 0.0 && g.near < g.far)) throw Error("froxels.near", to_text(g.near), "a distance in (0, far = " + to_text(g.far) + ")");
  if (!(g.glow_columns >= 0.0 && g.glow_columns <= 16.0)) throw Error("froxels.glow_columns", to_text(g.glow_columns), "a number of columns in [0, 16]");
}

}  // namespace

double FroxelGrid::boundary(int k) const { return near * std::pow(far / near, static_cast<double>(k + 1) / nz); }

double FroxelGrid::slice(double d) const {
  if (!(d > near)) return -1.0;
  return nz * std::log(d / near) / std::log(far / near) - 1.0;
}

PixelLayers Froxels::sample(double u, double v, double d) const {
  const FroxelGrid& g = grid;
  const double x = std::clamp(u * g.nx - 0.5, 0.0, g.nx - 1.0), y = std::clamp(v * g.ny - 0.5, 0.0, g.ny - 1.0);
  const double z = std::min(g.slice(d), g.nz - 1.0);
  const int i = std::min(static_cast<int>(x), std::max(g.nx - 2, 0)), j = std::min(static_cast<int>(y), std::max(g.ny - 2, 0));
  const int k = static_cast<int>(std::floor(z));
  const double a = g.nx > 1 ? x - i : 0.0, b = g.ny > 1 ? y - j : 0.0, c = z - k;
  auto column = [&](int kk, Rgb& l, Rgb& t) {
    l = Rgb(0.0), t = Rgb(0.0);
    if (kk < 0) {  // near: nothing in-scattered yet
      t = Rgb(1.0);
      return;
    }
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        const double w = (dx ? a : 1.0 - a) * (dy ? b : 1.0 - b);
        if (w == 0.0) continue;
        const size_t at = (static_cast<size_t>(kk) * static_cast<size_t>(g.ny) + static_cast<size_t>(j + dy)) * static_cast<size_t>(g.nx) + static_cast<size_t>(i + dx);
        l += w * Rgb(inscatter[at]), t += w * Rgb(transmittance[at]);
      }
  };
  PixelLayers out;
  Rgb l0, t0, l1, t1;
  column(k, l0, t0);
  if (c > 0.0 && k + 1 < g.nz) {
    column(k + 1, l1, t1);
    out.inscatter = (1.0 - c) * l0 + c * l1, out.transmittance = (1.0 - c) * t0 + c * t1;
  } else {
    out.inscatter = l0, out.transmittance = t0;
  }
  return out;
}

void froxels_detail::build(const Solution& solution, const Camera& camera, Froxels& out, const FroxelGrid& grid, double jitter,
                           const RenderOptions& options) {
  check(grid);
  out.grid = grid;
  const size_t froxels = static_cast<size_t>(grid.nx) * static_cast<size_t>(grid.ny) * static_cast<size_t>(grid.nz);
  out.inscatter.resize(froxels);
  out.transmittance.resize(froxels);
  std::array<double, 4096> boundaries;
  for (int k = 0; k < grid.nz; ++k) boundaries[static_cast<size_t>(k)] = grid.near * std::pow(grid.far / grid.near, (k + 1 + jitter) / grid.nz);
  const Camera columns = column_camera(camera, grid.nx, grid.ny);
  // The glow angle: glow_columns times the angle between the middle column and its neighbour.
  out.glow_angle = 0.0;
  if (grid.glow_columns > 0.0) out.glow_angle = std::min(grid.glow_columns * columns.pixel_angle(), 0.5);
  solution.render_distances(View{columns}, std::span<const double>(boundaries.data(), static_cast<size_t>(grid.nz)),
                            DistanceLayers{out.inscatter, out.transmittance, out.glow_angle}, options);
}

void build_froxels(const Solution& solution, const Camera& camera, Froxels& out, const FroxelGrid& grid, const RenderOptions& options) {
  froxels_detail::build(solution, camera, out, grid, 0.0, options);
}

Froxels build_froxels(const Solution& solution, const Camera& camera, const FroxelGrid& grid, const RenderOptions& options) {
  Froxels out;
  build_froxels(solution, camera, out, grid, options);
  return out;
}

void composite_froxels(const Froxels& froxels, ConstImageSpan colour, std::span<const float> depth, ImageSpan out, int threads) {
  check_span(colour, "colour");
  check_span(out, "out");
  const int w = colour.width, h = colour.height;
  if (out.width != w || out.height != h)
    throw Error("out", to_text(out.width) + " x " + to_text(out.height), "the colour's size, " + to_text(w) + " x " + to_text(h));
  if (depth.size() != static_cast<size_t>(w) * static_cast<size_t>(h))
    throw Error("depth", std::to_string(depth.size()) + " values", "one per pixel of the colour, " + std::to_string(w) + " x " + std::to_string(h));
  const FroxelGrid& g = froxels.grid;
  const size_t nx = static_cast<size_t>(g.nx), plane = nx * static_cast<size_t>(g.ny);
  if (froxels.inscatter.size() != plane * static_cast<size_t>(g.nz) || froxels.transmittance.size() != froxels.inscatter.size())
    throw Error("froxels", to_text(froxels.inscatter.size()) + " froxels", "nx x ny x nz = " + to_text(plane * static_cast<size_t>(g.nz)));
  const froxels_detail::CompositeVolume volume{&froxels.inscatter.data()->x, &froxels.transmittance.data()->x, g.nx, g.ny, g.nz,
                                               static_cast<float>(g.near), std::log(static_cast<float>(g.near)),
                                               static_cast<float>(g.nz / std::log(g.far / g.near))};
  const auto composite_rows = [&](long long y0, long long y1) {
    for (auto py = static_cast<int>(y0); py < y1; ++py) {
      const bool ahead = py + 1 < y1;
      froxels_detail::composite_row(volume, {colour.pixel(0, py), colour.channels, depth.data() + static_cast<size_t>(py) * static_cast<size_t>(w),
                                             out.pixel(0, py), out.channels, w, h, py, ahead ? colour.pixel(0, py + 1) : nullptr,
                                             ahead ? depth.data() + static_cast<size_t>(py + 1) * static_cast<size_t>(w) : nullptr});
    }
  };
  // A body of one reference: std::function keeps it without allocating.
  parallel_for(h, threads, 8, [&composite_rows](long long y0, long long y1) { composite_rows(y0, y1); });
}

void add_glow(const Solution& solution, const Camera& camera, const Froxels& froxels, std::span<const float> depth, ImageSpan out, int threads) {
  if (froxels.glow_angle == 0.0) return;
  RenderOptions options{threads, nullptr, {}, {}, false, 0, nullptr};  // settings null: nothing allocated
  solution.add_glow(View{camera, depth}, froxels.glow_angle, out, options);
}

Image composite_froxels(const Froxels& froxels, const Image& host_colour, std::span<const float> depth, int threads) {
  Image out(host_colour.width(), host_colour.height());
  composite_froxels(froxels, ConstImageSpan{host_colour.data().data(), host_colour.width(), host_colour.height()}, depth,
                    ImageSpan{out.data().data(), out.width(), out.height()}, threads);
  return out;
}

}  // namespace haze
