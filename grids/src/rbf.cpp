#include <haze/core/error.h>
#include <haze/core/progress.h>
#include <haze/grids/rbf.h>

#include <algorithm>
#include <atomic>
#include <cmath>

namespace haze::grids {

namespace {

void validate(const std::vector<RbfBlob>& blobs) {
  if (blobs.empty()) throw Error("blobs", "an empty list", "at least one RBF blob");
  for (size_t i = 0; i < blobs.size(); ++i) {
    const RbfBlob& b = blobs[i];
    const std::string at = "blobs[" + std::to_string(i) + "].";
    if (!std::isfinite(b.center.x + b.center.y + b.center.z)) throw Error(at + "center", "not finite", "a finite position");
    if (!(std::isfinite(b.weight) && b.weight >= 0.0)) throw Error(at + "weight", to_text(b.weight), "a finite number >= 0");
    if (!(std::isfinite(b.sharpness) && b.sharpness > 0.0)) throw Error(at + "sharpness", to_text(b.sharpness), "a finite number > 0");
  }
}

double support_radius(const RbfBlob& b, double cutoff) {
  return b.weight > cutoff ? std::sqrt(std::log(b.weight / cutoff)) / b.sharpness : -1.0;
}

// Adds every blob's contribution to the cells with index in [lo, hi) (inclusive-exclusive per axis).
size_t inject_box(const std::vector<RbfBlob>& blobs, DenseGrid& grid, double cutoff, std::array<int, 3> lo, std::array<int, 3> hi) {
  const Vec3 h = grid.cell_size(), origin = grid.bounds().lo;
  std::vector<float> ex, ey, ez;
  size_t updates = 0;
  for (const auto& b : blobs) {
    double r = support_radius(b, cutoff);
    if (r < 0.0) continue;
    std::array<int, 3> c0{}, c1{};
    bool empty = false;
    for (int a = 0; a < 3; ++a) {
      // Cells whose centre lies within r of the blob's centre along this axis.
      double first = std::ceil((b.center[a] - r - origin[a]) / h[a] - 0.5), last = std::floor((b.center[a] + r - origin[a]) / h[a] - 0.5);
      // Clamped in double: a blob far outside the grid is billions of cells away, past int.
      const double l = lo[static_cast<size_t>(a)], u = hi[static_cast<size_t>(a)];
      c0[static_cast<size_t>(a)] = static_cast<int>(std::clamp(first, l, u));
      c1[static_cast<size_t>(a)] = static_cast<int>(std::clamp(last + 1.0, l, u));
      empty |= c0[static_cast<size_t>(a)] >= c1[static_cast<size_t>(a)];
    }
    if (empty) continue;
    const double s2 = b.sharpness * b.sharpness;
    auto factors = [&](int a, std::vector<float>& e) {
      e.clear();
      for (int i = c0[static_cast<size_t>(a)]; i < c1[static_cast<size_t>(a)]; ++i) {
        double d = origin[a] + (i + 0.5) * h[a] - b.center[a];
        e.push_back(static_cast<float>(std::exp(-s2 * d * d)));
      }
    };
    factors(0, ex), factors(1, ey), factors(2, ez);
    const float w = static_cast<float>(b.weight);
    for (int k = c0[2]; k < c1[2]; ++k)
      for (int j = c0[1]; j < c1[1]; ++j) {
        const float wyz = w * ez[static_cast<size_t>(k - c0[2])] * ey[static_cast<size_t>(j - c0[1])];
        float* row = &grid.at(c0[0], j, k);
        const size_t n = ex.size();
        for (size_t i = 0; i < n; ++i) row[i] += wyz * ex[i];
        updates += n;
      }
  }
  return updates;
}

// z-slices [k0, k1) of the box [lo, hi) split over threads; each slab sums its blobs in order.
size_t inject_parallel(const std::vector<RbfBlob>& blobs, DenseGrid& grid, double cutoff, std::array<int, 3> lo,
                       std::array<int, 3> hi, int threads) {
  std::atomic<size_t> updates{0};
  parallel_for(hi[2] - lo[2], threads, 4, [&](long long k0, long long k1) {
    std::array<int, 3> a = lo, b = hi;
    a[2] = lo[2] + static_cast<int>(k0), b[2] = lo[2] + static_cast<int>(k1);
    updates += inject_box(blobs, grid, cutoff, a, b);
  });
  return updates.load();
}

}  // namespace

double injection_cutoff(const std::vector<RbfBlob>& blobs, double cutoff) {
  if (std::isnan(cutoff)) throw Error("cutoff", "NaN", "a density >= 0 (0: 1e-4 of the largest weight)");
  if (cutoff > 0.0) return cutoff;
  double largest = 0.0;
  for (const auto& b : blobs) largest = std::max(largest, b.weight);
  return largest > 0.0 ? 1e-4 * largest : 1.0;
}

Aabb blob_support(const RbfBlob& blob, double cutoff) {
  double r = support_radius(blob, cutoff);
  if (r < 0.0) return {Vec3(kInfinity), Vec3(-kInfinity)};
  return {blob.center - Vec3(r), blob.center + Vec3(r)};
}

InjectionReport inject_rbf(const std::vector<RbfBlob>& blobs, DenseGrid& grid, double cutoff, int threads) {
  validate(blobs);
  InjectionReport report;
  report.cutoff = injection_cutoff(blobs, cutoff);
  const auto& n = grid.resolution();
  report.cell_updates = inject_parallel(blobs, grid, report.cutoff, {0, 0, 0}, n, threads);
  // A blob contributes less than cutoff to each cell it skips: the bound counts every blob.
  report.truncation_bound = report.cutoff * static_cast<double>(blobs.size());
  return report;
}

size_t reinject_region(const std::vector<RbfBlob>& blobs, DenseGrid& grid, const Aabb& region, double cutoff, int brick_size,
                       int threads) {
  validate(blobs);
  if (brick_size < 1) throw Error("brick_size", to_text(brick_size), "an integer >= 1");
  cutoff = injection_cutoff(blobs, cutoff);
  const Vec3 h = grid.cell_size(), origin = grid.bounds().lo;
  std::array<int, 3> lo{}, hi{};
  for (int a = 0; a < 3; ++a) {
    const int n = grid.resolution()[static_cast<size_t>(a)];
    double first = std::floor((region.lo[a] - origin[a]) / h[a]), last = std::floor((region.hi[a] - origin[a]) / h[a]);
    first = std::clamp(first, 0.0, static_cast<double>(n)), last = std::clamp(last + 1.0, 0.0, static_cast<double>(n));
    // Whole bricks: the cells a solver's cache blocks hold.
    lo[static_cast<size_t>(a)] = static_cast<int>(first) / brick_size * brick_size;
    hi[static_cast<size_t>(a)] = std::min(n, (static_cast<int>(last) + brick_size - 1) / brick_size * brick_size);
    if (lo[static_cast<size_t>(a)] >= hi[static_cast<size_t>(a)]) return 0;
  }
  for (int k = lo[2]; k < hi[2]; ++k)
    for (int j = lo[1]; j < hi[1]; ++j) std::fill_n(&grid.at(lo[0], j, k), hi[0] - lo[0], 0.0f);
  inject_parallel(blobs, grid, cutoff, lo, hi, threads);
  return static_cast<size_t>(hi[0] - lo[0]) * static_cast<size_t>(hi[1] - lo[1]) * static_cast<size_t>(hi[2] - lo[2]);
}

}  // namespace haze::grids
