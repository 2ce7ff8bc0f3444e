#include <haze/core/error.h>
#include <haze/grids/propagation.h>
#include <haze/grids/rbf.h>

#include <algorithm>
#include <cmath>

namespace haze::grids {

namespace {

// `resolution` cells along the longest side, the others in proportion (at least 2).
std::array<int, 3> cells_for(const Aabb& bounds, int resolution) {
  const Vec3 e = bounds.extent();
  const double longest = std::max({e.x, e.y, e.z});
  std::array<int, 3> n{};
  for (int a = 0; a < 3; ++a) n[static_cast<size_t>(a)] = std::max(2, static_cast<int>(std::lround(resolution * e[a] / longest)));
  return n;
}

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

ExtinctionVolume make_extinction_volume(const Scene& scene, int resolution, double cutoff, int threads, VolumeReport* report) {
  if (!scene.medium) throw Error("medium", "missing", "a medium for the propagation method");
  if (resolution < 2 || resolution > 1024) throw Error("resolution", to_text(resolution), "an integer in [2, 1024]");
  const MediumDesc& desc = *scene.medium;
  Aabb bounds = desc.bounds;
  ExtinctionVolume volume{DenseGrid({1, 1, 1}, {Vec3(0), Vec3(1)}), desc.sigma_t, desc.albedo, desc.phase};
  if (const auto* rbf = std::get_if<RbfDensity>(&desc.density)) {
    if (!bounds.bounded()) {
      // Unbounded: the blobs' supports at the injection cutoff.
      bounds = {Vec3(kInfinity), Vec3(-kInfinity)};
      const double c = injection_cutoff(rbf->blobs, cutoff);
      for (const auto& b : rbf->blobs) {
        Aabb support = blob_support(b, c);
        bounds.lo = glm::min(bounds.lo, support.lo), bounds.hi = glm::max(bounds.hi, support.hi);
      }
      if (!bounds.bounded()) throw Error("medium.density.blobs", "weights all below the cutoff", "a blob above the injection cutoff");
    }
    bounds = clip_to_planes(bounds, scene);
    volume.density = DenseGrid(cells_for(bounds, resolution), bounds);
    InjectionReport injected = inject_rbf(rbf->blobs, volume.density, cutoff, threads);
    if (report) report->truncation_bound = injected.truncation_bound;
  } else if (const auto* field = std::get_if<FieldDensity>(&desc.density)) {
    if (!field->field) throw Error("medium.density", "a " + field->type + " field without data", "a density field");
    const GridDensity grid = sample_grid(*field->field, field->grid_resolution > 0 ? field->grid_resolution : resolution, threads);
    volume.density = DenseGrid(grid.resolution, field->field->bounds());
    volume.density.values() = grid.values;
  } else if (const auto* grid = std::get_if<GridDensity>(&desc.density)) {
    volume.density = DenseGrid(grid->resolution, bounds);
    volume.density.values().assign(grid->samples().begin(), grid->samples().end());
  } else {
    const auto& constant = std::get<ConstantDensity>(desc.density);
    if (!bounds.bounded()) throw Error("medium.bounds", "unbounded", "bounds for a constant density in the propagation method");
    bounds = clip_to_planes(bounds, scene);
    volume.density = DenseGrid(cells_for(bounds, resolution), bounds);
    std::fill(volume.density.values().begin(), volume.density.values().end(), static_cast<float>(constant.value));
  }
  return volume;
}

MediumDesc ExtinctionVolume::medium() const {
  MediumDesc m;
  m.bounds = density.bounds();
  m.density = GridDensity::viewing(density.resolution(), density.values());
  m.sigma_t = sigma_t_scale, m.albedo = albedo, m.phase = phase;
  return m;
}

}  // namespace haze::grids
