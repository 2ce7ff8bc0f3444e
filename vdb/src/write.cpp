// write_fields: a solution's fluence and per-light transmittance sampled on a grid and written as
// OpenVDB vec3s grids.
#include <haze/core/error.h>
#include <haze/core/progress.h>
#include <haze/core/scene.h>
#include <haze/vdb/vdb.h>

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <functional>

namespace haze::vdb {

std::vector<std::string> write_fields(const std::filesystem::path& file, const Solution& solution, int resolution, int threads) {
  [[maybe_unused]] static const bool initialized = (openvdb::initialize(), true);
  const Scene& scene = solution.scene();
  if (resolution < 2 || resolution > 1024) throw Error("fields.resolution", to_text(resolution), "an integer in [2, 1024]");
  if (!scene.medium) throw Error("fields", "a scene without a medium", "a medium whose fields to write");
  const Aabb bounds = medium_bounds(*scene.medium);
  if (!bounds.bounded()) throw Error("fields", "an unbounded medium", "a bounded medium (its bounds are the fields' grid)");
  const Vec3 e = bounds.extent();
  const double h = std::max({e.x, e.y, e.z}) / resolution;
  std::array<int, 3> n{};
  for (int a = 0; a < 3; ++a) n[a] = std::max(1, static_cast<int>(std::ceil(e[a] / h - 1e-9)));

  // Voxel (i, j, k) centred at lo + (ijk + 0.5) h.
  auto transform = openvdb::math::Transform::createLinearTransform(h);
  transform->postTranslate(openvdb::Vec3d(bounds.lo.x + 0.5 * h, bounds.lo.y + 0.5 * h, bounds.lo.z + 0.5 * h));
  openvdb::GridPtrVec grids;
  std::vector<std::string> names;
  auto sample = [&](const std::string& name, const std::function<Rgb(const Vec3&)>& field) {
    std::vector<Rgb> values(static_cast<size_t>(n[0]) * static_cast<size_t>(n[1]) * static_cast<size_t>(n[2]));
    parallel_for(n[2], threads, 1, [&](long long k0, long long k1) {
      for (auto k = static_cast<int>(k0); k < k1; ++k)
        for (int j = 0; j < n[1]; ++j)
          for (int i = 0; i < n[0]; ++i)
            values[(static_cast<size_t>(k) * static_cast<size_t>(n[1]) + static_cast<size_t>(j)) * static_cast<size_t>(n[0]) + static_cast<size_t>(i)] =
                field(bounds.lo + (Vec3(i, j, k) + 0.5) * h);
    });
    auto grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    grid->setName(name);
    grid->setTransform(transform->copy());
    grid->setGridClass(openvdb::GRID_UNKNOWN);
    auto accessor = grid->getAccessor();
    for (int k = 0; k < n[2]; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i) {
          const Rgb& v = values[(static_cast<size_t>(k) * static_cast<size_t>(n[1]) + static_cast<size_t>(j)) * static_cast<size_t>(n[0]) + static_cast<size_t>(i)];
          if (v.r != 0.0 || v.g != 0.0 || v.b != 0.0)
            accessor.setValue(openvdb::Coord(i, j, k), openvdb::Vec3s(static_cast<float>(v.r), static_cast<float>(v.g), static_cast<float>(v.b)));
        }
    grids.push_back(grid);
    names.push_back(name);
  };
  sample("fluence", [&](const Vec3& x) { return solution.fluence(x); });
  for (size_t l = 0; l < scene.lights.size(); ++l)
    if (!std::holds_alternative<SkyLight>(scene.lights[l]))
      sample("transmittance_" + std::to_string(l), [&](const Vec3& x) { return solution.transmittance(l, x); });

  try {
    openvdb::io::File(file.string()).write(grids);
  } catch (const std::exception& e) {
    throw Error("fields", file.string(), std::string("a file OpenVDB can write (") + e.what() + ")");
  }
  return names;
}

}  // namespace haze::vdb
