#include <haze/core/error.h>
#include <haze/core/majorant.h>
#include <haze/core/medium.h>

#include <algorithm>
#include <string>

namespace haze {

MajorantGrid::MajorantGrid(const DensityField& medium, int cells) : bounds_(medium.bounds()) {
  if (medium.homogeneous() || !bounds_.bounded()) {
    density_.assign(1, medium.max_density(bounds_));
    return;
  }
  n_ = {cells, cells, cells};
  density_.resize(static_cast<size_t>(cells) * static_cast<size_t>(cells) * static_cast<size_t>(cells));
  Vec3 size = bounds_.extent() / static_cast<double>(cells);
  for (int z = 0; z < cells; ++z)
    for (int y = 0; y < cells; ++y)
      for (int x = 0; x < cells; ++x) {
        Vec3 lo = bounds_.lo + Vec3(x, y, z) * size;
        density_[(static_cast<size_t>(z) * static_cast<size_t>(cells) + static_cast<size_t>(y)) * static_cast<size_t>(cells) + static_cast<size_t>(x)] =
            medium.max_density({lo, lo + size});
      }
}

MajorantGrid::MajorantGrid(const Aabb& bounds, const std::array<int, 3>& n, std::vector<double> density)
    : bounds_(bounds), n_(n), density_(std::move(density)) {
  if (density_.size() != static_cast<size_t>(n[0]) * static_cast<size_t>(n[1]) * static_cast<size_t>(n[2]) || !bounds.bounded())
    throw Error("majorants", std::to_string(density_.size()) + " values", "bounded bounds and one value per cell");
}

}  // namespace haze
