#include <haze/core/error.h>
#include <haze/froxels/froxels.h>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/trigonometric.hpp>

#include <algorithm>
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

Froxels build_froxels(const Solution& solution, const Camera& camera, const FroxelGrid& grid, const RenderOptions& options) {
  check(grid);
  Froxels out;
  out.grid = grid;
  const size_t columns = static_cast<size_t>(grid.nx) * static_cast<size_t>(grid.ny);
  out.inscatter.resize(columns * static_cast<size_t>(grid.nz));
  out.transmittance.resize(out.inscatter.size());
  std::vector<double> boundaries;
  for (int k = 0; k < grid.nz; ++k) boundaries.push_back(grid.boundary(k));
  const std::vector<PixelLayers> layers = solution.render_distances(View{column_camera(camera, grid.nx, grid.ny)}, boundaries, options);
  const auto nz = static_cast<size_t>(grid.nz);
  for (size_t column = 0; column < columns; ++column)
    for (size_t k = 0; k < nz; ++k) {
      const PixelLayers& p = layers[column * nz + k];
      out.inscatter[k * columns + column] = Vec3f(p.inscatter), out.transmittance[k * columns + column] = Vec3f(p.transmittance);
    }
  return out;
}

Image composite_froxels(const Froxels& froxels, const Image& host_colour, std::span<const float> depth) {
  const int w = host_colour.width(), h = host_colour.height();
  if (depth.size() != static_cast<size_t>(w) * static_cast<size_t>(h))
    throw Error("depth", std::to_string(depth.size()) + " values", "one per pixel of the colour, " + std::to_string(w) + " x " + std::to_string(h));
  Image out(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const PixelLayers p = froxels.sample((x + 0.5) / w, (y + 0.5) / h, depth[static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x)]);
      out.set(x, y, p.inscatter + p.transmittance * host_colour.at(x, y));
    }
  return out;
}

}  // namespace haze
