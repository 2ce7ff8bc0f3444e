#include <haze/core/error.h>
#include <haze/particles/neighbours.h>

#include "kd_tree.h"

namespace haze::particles {

Neighbourhoods nearest_neighbours(const std::vector<Vec3f>& positions, int k) {
  const size_t n = positions.size();
  if (k < 1 || static_cast<size_t>(k) >= n)
    throw Error("k", to_text(k), "a neighbour count in [1, particles - 1] with " + to_text(n) + " particles");
  for (size_t i = 0; i < n; ++i)
    if (!std::isfinite(positions[i].x + positions[i].y + positions[i].z))
      throw Error("positions[" + std::to_string(i) + "]", "not finite", "finite coordinates");
  return nearest_neighbours(KdTree(positions), k);
}

Neighbourhoods nearest_neighbours(const KdTree& tree, int k) {
  const size_t n = tree.data.rows;
  // Ask for k + 1 and drop the particle itself; among duplicates at distance 0 it may be missing,
  // and then the first k are kept.
  const size_t kk = static_cast<size_t>(k) + 1;
  std::vector<size_t> found(n * kk);
  std::vector<float> dist(n * kk);
  flann::Matrix<size_t> found_m(found.data(), n, kk);
  flann::Matrix<float> dist_m(dist.data(), n, kk);
  flann::SearchParams params(flann::FLANN_CHECKS_UNLIMITED);
  params.cores = 1;  // deterministic; callers parallelize above this
  tree.index.knnSearch(tree.data, found_m, dist_m, kk, params);

  Neighbourhoods out;
  out.k = k;
  out.indices.reserve(n * static_cast<size_t>(k));
  out.distances2.reserve(n * static_cast<size_t>(k));
  for (size_t i = 0; i < n; ++i) {
    int kept = 0;
    for (size_t j = 0; j < kk && kept < k; ++j) {
      if (found[i * kk + j] == i) continue;
      out.indices.push_back(static_cast<int>(found[i * kk + j]));
      out.distances2.push_back(dist[i * kk + j]);
      ++kept;
    }
  }
  return out;
}

}  // namespace haze::particles
