#include <haze/core/error.h>
#include <haze/grids/propagation.h>
#include <haze/grids/rbf.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace haze::grids {

namespace {

// `cells.longest` cells along the longest side, the others in proportion (at least 2), or the
// axes given.
std::array<int, 3> cells_for(const Aabb& bounds, const CellCount& cells) {
  if (cells.per_axis()) return cells.axes;
  const Vec3 e = bounds.extent();
  const double longest = std::max({e.x, e.y, e.z});
  std::array<int, 3> n{};
  for (int a = 0; a < 3; ++a) n[static_cast<size_t>(a)] = std::max(2, static_cast<int>(std::lround(cells.longest * e[a] / longest)));
  return n;
}

// With cells.per_optical_depth, the counts the grid's column optical depths ask for (never fewer
// than it has): per axis, the largest sum of density times sigma_t over a column of cells along it.
double largest(const Rgb& c) { return std::max({c.r, c.g, c.b}); }

std::array<int, 3> cells_for_depth(const DenseGrid& grid, double sigma_t, const CellCount& cells) {
  std::array<int, 3> n = grid.resolution();
  if (cells.per_axis() || !(cells.per_optical_depth > 0.0)) return n;
  const Vec3 h = grid.cell_size();
  const float* v = grid.values().data();
  std::array<double, 3> deepest{0.0, 0.0, 0.0};
  const auto nx = static_cast<size_t>(n[0]), ny = static_cast<size_t>(n[1]), nz = static_cast<size_t>(n[2]);
  std::vector<double> along_y(nx * nz, 0.0), along_z(nx * ny, 0.0);
  for (size_t k = 0; k < nz; ++k)
    for (size_t j = 0; j < ny; ++j) {
      double along_x = 0.0;
      for (size_t i = 0; i < nx; ++i) {
        const double rho = v[(k * ny + j) * nx + i];
        along_x += rho, along_y[k * nx + i] += rho, along_z[j * nx + i] += rho;
      }
      deepest[0] = std::max(deepest[0], along_x * h.x);
    }
  for (double c : along_y) deepest[1] = std::max(deepest[1], c * h.y);
  for (double c : along_z) deepest[2] = std::max(deepest[2], c * h.z);
  const int most = std::min(cells.longest, cells.most_for_depth);
  for (size_t a = 0; a < 3; ++a) {
    const double wanted = std::ceil(cells.per_optical_depth * sigma_t * deepest[a]);
    if (wanted > n[a]) n[a] = std::max(n[a], static_cast<int>(std::min<double>(wanted, most)));
  }
  return n;
}

// A grid over `bounds` at cells_for's counts, filled by fill(grid), then again at
// cells_for_depth's counts when its column optical depths ask for more.
template <class Fill>
void fitted_grid(DenseGrid& grid, const Aabb& bounds, const CellCount& cells, double sigma_t, const Fill& fill) {
  grid = DenseGrid(cells_for(bounds, cells), bounds);
  fill(grid);
  if (const std::array<int, 3> n = cells_for_depth(grid, sigma_t, cells); n != grid.resolution()) {
    grid = DenseGrid(n, bounds);
    fill(grid);
  }
}

}  // namespace

std::string CellCount::text() const {
  if (!per_axis()) return to_text(longest);
  std::string out = "[";
  for (size_t a = 0; a < 3; ++a) (out += a > 0 ? ", " : "") += to_text(axes[a]);
  return out += "]";
}

namespace {

// An infinite plane splits space into halves that exchange no light, so only the medium on the
// camera's side can be seen: bounds an axis-aligned plane cuts end at it, on the camera's side.
Aabb clip_to_planes(Aabb bounds, const Scene& scene) {
  for (const Surface& s : scene.surfaces) {
    const auto* plane = std::get_if<Plane>(&s.shape);
    if (!plane) continue;
    for (int a = 0; a < 3; ++a) {
      if (std::abs(plane->normal[a]) < 1.0 - 1e-12) continue;
      const double at = plane->point[a], eye = scene.camera.position[a];
      if (!(at > bounds.lo[a] && at < bounds.hi[a]) || eye == at) continue;
      (eye > at ? bounds.lo[a] : bounds.hi[a]) = at;
    }
  }
  return bounds;
}

}  // namespace

ExtinctionVolume make_extinction_volume(const Scene& scene, const CellCount& cells, double cutoff, int threads, VolumeReport* report) {
  if (!scene.medium) throw Error("medium", "missing", "a medium for the propagation method");
  for (int n : cells.per_axis() ? cells.axes : std::array<int, 3>{cells.longest, cells.longest, cells.longest})
    if (n < 2 || n > 1024) throw Error("resolution", cells.text(), "integers in [2, 1024]");
  const MediumDesc& desc = *scene.medium;
  Aabb bounds = desc.bounds;
  ExtinctionVolume volume{DenseGrid({1, 1, 1}, {Vec3(0), Vec3(1)}), desc.sigma_t, desc.albedo, desc.phase, desc.emission};
  if (const auto* rbf = std::get_if<RbfDensity>(&desc.density)) {
    if (!bounds.bounded()) {
      // Unbounded: the blobs' supports at the injection cutoff.
      bounds = {Vec3(kInfinity), Vec3(-kInfinity)};
      const double c = injection_cutoff(rbf->blobs, cutoff);
      double widest = 0.0;
      for (const auto& b : rbf->blobs) {
        Aabb support = blob_support(b, c);
        bounds.lo = glm::min(bounds.lo, support.lo), bounds.hi = glm::max(bounds.hi, support.hi);
        if (support.bounded()) widest = std::max(widest, support.extent().x);
      }
      if (!bounds.bounded()) throw Error("medium.density.blobs", "weights all below the cutoff", "a blob above the injection cutoff");
      // Blobs spread far apart (one 1e9 away) make cells wider than any blob: every blob would
      // fall between cell centres and the medium would vanish.
      const Vec3 e = bounds.extent();
      const std::array<int, 3> n = cells_for(bounds, cells);
      const double cell = std::max({e.x / n[0], e.y / n[1], e.z / n[2]});
      if (cell > widest)
        throw Error("medium.bounds", "unbounded, with blobs spread over " + to_text(std::max({e.x, e.y, e.z})),
                    "bounds around the blobs to solve: the grid's cells (" + to_text(cell) + ") would be wider than the widest blob (" +
                        to_text(widest) + ")");
    }
    bounds = clip_to_planes(bounds, scene);
    InjectionReport injected;
    fitted_grid(volume.density, bounds, cells, largest(desc.sigma_t), [&](DenseGrid& g) { injected = inject_rbf(rbf->blobs, g, cutoff, threads); });
    if (report) report->truncation_bound = injected.truncation_bound;
  } else if (const auto* field = std::get_if<FieldDensity>(&desc.density)) {
    if (!field->field) throw Error("medium.density", "a " + field->type + " field without data", "a density field");
    int n = cells.per_axis() ? std::ranges::max(cells.axes) : cells.longest;
    if (field->max_resolution > 0) n = std::min(n, std::max(2, field->max_resolution));
    const GridDensity grid = sample_grid(*field->field, field->grid_resolution > 0 ? field->grid_resolution : n, threads);
    volume.density = DenseGrid(grid.resolution, field->field->bounds());
    volume.density.values() = grid.values;
  } else if (const auto* grid = std::get_if<GridDensity>(&desc.density)) {
    volume.density = DenseGrid(grid->resolution, bounds);
    volume.density.values().assign(grid->samples().begin(), grid->samples().end());
  } else {
    const auto& constant = std::get<ConstantDensity>(desc.density);
    if (!bounds.bounded()) throw Error("medium.bounds", "unbounded", "bounds for a constant density on a grid (methods propagation and dom)");
    bounds = clip_to_planes(bounds, scene);
    fitted_grid(volume.density, bounds, cells, largest(desc.sigma_t),
                [&](DenseGrid& g) { std::fill(g.values().begin(), g.values().end(), static_cast<float>(constant.value)); });
  }
  return volume;
}

MediumDesc ExtinctionVolume::medium() const {
  MediumDesc m;
  m.bounds = density.bounds();
  m.density = GridDensity::viewing(density.resolution(), density.values());
  m.sigma_t = sigma_t_scale, m.albedo = albedo, m.phase = phase, m.emission = emission;
  return m;
}

}  // namespace haze::grids
