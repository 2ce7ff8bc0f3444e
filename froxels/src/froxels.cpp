#include <haze/core/error.h>
#include <haze/core/progress.h>
#include <haze/froxels/froxels.h>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/trigonometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

namespace haze {

namespace {

// The camera whose pixels are the grid's columns: the same frustum at nx x ny.
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

void check(const FroxelGrid& g) {
  for (const auto& [name, n] : {std::pair{"nx", g.nx}, std::pair{"ny", g.ny}, std::pair{"nz", g.nz}})
    if (n < 1 || n > 4096) throw Error(std::string("froxels.") + name, std::to_string(n), "an integer in [1, 4096]");
  if (!(g.far > 0.0 && std::isfinite(g.far))) throw Error("froxels.far", to_text(g.far), "a finite distance > 0");
  if (!(g.near > 0.0 && g.near < g.far)) throw Error("froxels.near", to_text(g.near), "a distance in (0, far = " + to_text(g.far) + ")");
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

void build_froxels(const Solution& solution, const Camera& camera, Froxels& out, const FroxelGrid& grid, const RenderOptions& options) {
  check(grid);
  out.grid = grid;
  const size_t columns = static_cast<size_t>(grid.nx) * static_cast<size_t>(grid.ny), nz = static_cast<size_t>(grid.nz);
  out.inscatter.resize(columns * nz);
  out.transmittance.resize(columns * nz);
  out.layers.resize(columns * nz);
  std::array<double, 4096> boundaries;
  for (int k = 0; k < grid.nz; ++k) boundaries[static_cast<size_t>(k)] = grid.boundary(k);
  solution.render_distances(View{column_camera(camera, grid.nx, grid.ny)}, std::span<const double>(boundaries.data(), nz), out.layers, options);
  // Column-major layers to slice-major froxels, a slice's row of froxels at a time.
  const auto transpose = [&](long long k0, long long k1) {
    for (auto k = static_cast<size_t>(k0); k < static_cast<size_t>(k1); ++k)
      for (size_t column = 0; column < columns; ++column) {
        const PixelLayers& p = out.layers[column * nz + k];
        out.inscatter[k * columns + column] = Vec3f(p.inscatter), out.transmittance[k * columns + column] = Vec3f(p.transmittance);
      }
  };
  parallel_for(grid.nz, options.threads, 1, [&transpose](long long k0, long long k1) { transpose(k0, k1); });
}

Froxels build_froxels(const Solution& solution, const Camera& camera, const FroxelGrid& grid, const RenderOptions& options) {
  Froxels out;
  build_froxels(solution, camera, out, grid, options);
  out.layers = {};
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
  // Froxels::sample's lookup in float32: slice(d) = nz log(d / near) / log(far / near) - 1.
  const float near = static_cast<float>(g.near), log_near = std::log(near), slices_per_log = static_cast<float>(g.nz / std::log(g.far / g.near));
  const float last_slice = static_cast<float>(g.nz - 1);
  const Vec3f* const L = froxels.inscatter.data();
  const Vec3f* const T = froxels.transmittance.data();
  const auto composite_row = [&](int py) {
    const float y = std::clamp((static_cast<float>(py) + 0.5f) / static_cast<float>(h) * static_cast<float>(g.ny) - 0.5f, 0.0f, static_cast<float>(g.ny - 1));
    const int j = std::min(static_cast<int>(y), std::max(g.ny - 2, 0));
    const float b = g.ny > 1 ? y - static_cast<float>(j) : 0.0f;
    const float* in = colour.pixel(0, py);
    float* to = out.pixel(0, py);
    const float* row_depth = depth.data() + static_cast<size_t>(py) * static_cast<size_t>(w);
    for (int px = 0; px < w; ++px, in += colour.channels, to += out.channels) {
      const float x = std::clamp((static_cast<float>(px) + 0.5f) / static_cast<float>(w) * static_cast<float>(g.nx) - 0.5f, 0.0f, static_cast<float>(g.nx - 1));
      const int i = std::min(static_cast<int>(x), std::max(g.nx - 2, 0));
      const float a = g.nx > 1 ? x - static_cast<float>(i) : 0.0f;
      const float d = row_depth[px];
      const float z = d > near ? std::min(slices_per_log * (std::log(d) - log_near) - 1.0f, last_slice) : -1.0f;
      const int k = static_cast<int>(std::floor(z));
      const float c = z - static_cast<float>(k);
      const size_t at = static_cast<size_t>(j) * nx + static_cast<size_t>(i);
      const size_t dx = g.nx > 1 ? 1 : 0, dy = g.ny > 1 ? nx : 0;
      const float w00 = (1.0f - a) * (1.0f - b), w10 = a * (1.0f - b), w01 = (1.0f - a) * b, w11 = a * b;
      // Slice kk's bilinear L_in and T (kk < 0: near, nothing in-scattered yet).
      const auto column = [&](int kk, Vec3f& l, Vec3f& t) {
        if (kk < 0) {
          l = Vec3f(0.0f), t = Vec3f(1.0f);
          return;
        }
        const size_t o = static_cast<size_t>(kk) * plane + at;
        l = w00 * L[o] + w10 * L[o + dx] + w01 * L[o + dy] + w11 * L[o + dx + dy];
        t = w00 * T[o] + w10 * T[o + dx] + w01 * T[o + dy] + w11 * T[o + dx + dy];
      };
      Vec3f l, t;
      column(k, l, t);
      if (c > 0.0f && k + 1 < g.nz) {
        Vec3f l1, t1;
        column(k + 1, l1, t1);
        l = (1.0f - c) * l + c * l1, t = (1.0f - c) * t + c * t1;
      }
      for (int ch = 0; ch < 3; ++ch) to[ch] = l[ch] + t[ch] * in[ch];
    }
  };
  // A body of one reference: std::function keeps it without allocating.
  parallel_for(h, threads, 8, [&composite_row](long long y0, long long y1) {
    for (auto py = static_cast<int>(y0); py < y1; ++py) composite_row(py);
  });
}

Image composite_froxels(const Froxels& froxels, const Image& host_colour, std::span<const float> depth, int threads) {
  Image out(host_colour.width(), host_colour.height());
  composite_froxels(froxels, ConstImageSpan{host_colour.data().data(), host_colour.width(), host_colour.height()}, depth,
                    ImageSpan{out.data().data(), out.width(), out.height()}, threads);
  return out;
}

}  // namespace haze
