// ParticleDensity (field.h): the particles' Gaussians binned into a uniform grid of cell lists,
// each cell with its majorant, for the path tracer's lookups and delta tracking.
#include <haze/core/majorant.h>
#include <haze/particles/field.h>
#include <haze/particles/gaussian_sum.h>

#include <algorithm>
#include <cmath>

namespace haze::particles {

namespace {
#ifndef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
constexpr int kMaxCells = 128;            // a side
constexpr size_t kMaxEntries = 1u << 23;  // list entries (20 bytes each) before cells grow
#else  // the long fuzz runs (scripts/fuzz-offline): the same code with smaller zero-fills
constexpr int kMaxCells = 16;
constexpr size_t kMaxEntries = 1u << 16;
#endif
}  // namespace

ParticleDensity::ParticleDensity(ParticleSet set, int neighbours) : set_(std::move(set)), field_(set_.view(), neighbours) {
  if (field_.size() == 0) return;
  const Aabb b = field_.bounds();
  origin_ = b.lo;
  const Vec3 extent = b.extent();
  // The cells of each Gaussian's support box whose nearest point to its centre lies in the support.
  auto for_support = [&](size_t p, const auto& f) {
    const Vec3 x = field_.position(p);
    const double h = field_.h(p), reach = kCut * h;
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::clamp(static_cast<int>(std::floor((x[a] - reach - origin_[a]) / cell_[a])), 0, n_[static_cast<size_t>(a)] - 1);
      hi[a] = std::clamp(static_cast<int>(std::floor((x[a] + reach - origin_[a]) / cell_[a])), 0, n_[static_cast<size_t>(a)] - 1);
    }
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) {
          const Vec3 cell_lo = origin_ + Vec3(i, j, k) * cell_;
          const Vec3 d = x - glm::clamp(x, cell_lo, cell_lo + cell_);
          const double r2 = glm::dot(d, d) / (h * h);
          if (r2 < kCut * kCut) f(cell_index(i, j, k), r2);
        }
  };
  // Cells about the mean width; larger while the lists would pass kMaxEntries.
  std::vector<size_t> count;
  for (double side = field_.mean_h();; side *= 1.5) {
    for (int a = 0; a < 3; ++a) {
      n_[static_cast<size_t>(a)] = static_cast<int>(std::clamp(std::ceil(extent[a] / side), 1.0, static_cast<double>(kMaxCells)));
      cell_[a] = extent[a] / n_[static_cast<size_t>(a)];
    }
    count.assign(static_cast<size_t>(n_[0]) * static_cast<size_t>(n_[1]) * static_cast<size_t>(n_[2]), 0);
    for (size_t p = 0; p < field_.size(); ++p) for_support(p, [&](size_t c, double) { ++count[c]; });
    size_t entries = 0;
    for (size_t& c : count) entries += c = (c + kGaussianPad - 1) / kGaussianPad * kGaussianPad;
    if (entries <= kMaxEntries || (n_[0] == 1 && n_[1] == 1 && n_[2] == 1)) break;
  }
  start_.assign(count.size() + 1, 0);
  for (size_t c = 0; c < count.size(); ++c) start_[c + 1] = start_[c] + count[c];
  for (auto* v : {&x_, &y_, &z_, &inv_h2_, &w_}) v->assign(start_.back(), 0.0f);  // padding: w = 0
  majorant_.assign(count.size(), 0.0);
  std::vector<size_t> fill(start_.begin(), start_.end() - 1);
  for (size_t p = 0; p < field_.size(); ++p) {
    const Vec3 x = field_.position(p);
    const double h = field_.h(p), w = field_.weight(p);
    for_support(p, [&](size_t c, double r2) {
      const size_t e = fill[c]++;
      x_[e] = static_cast<float>(x.x), y_[e] = static_cast<float>(x.y), z_[e] = static_cast<float>(x.z);
      inv_h2_[e] = static_cast<float>(1.0 / (h * h)), w_[e] = static_cast<float>(w);
      majorant_[c] += w * std::exp(-r2);
    });
  }
  for (double& m : majorant_) m *= 1.0 + 1e-5;  // float32 sums may pass the float64 bound by a few roundings
  majorants_ = std::make_shared<MajorantGrid>(b, n_, majorant_);
}

double ParticleDensity::density(const Vec3& x) const {
  if (field_.size() == 0) return 0.0;
  int c[3];
  for (int a = 0; a < 3; ++a) {
    const double u = (x[a] - origin_[a]) / cell_[a];
    if (!(u >= 0.0 && u < n_[static_cast<size_t>(a)])) return 0.0;
    c[a] = std::min(static_cast<int>(u), n_[static_cast<size_t>(a)] - 1);
  }
  const size_t cell = cell_index(c[0], c[1], c[2]), e = start_[cell];
  const GaussianList list{x_.data() + e, y_.data() + e, z_.data() + e, inv_h2_.data() + e, w_.data() + e, start_[cell + 1] - e};
  if (list.count == 0) return 0.0;
  return gaussian_sum(list, static_cast<float>(x.x), static_cast<float>(x.y), static_cast<float>(x.z), static_cast<float>(kCut * kCut));
}

double ParticleDensity::max_density(const Aabb& region) const {
  if (field_.size() == 0) return 0.0;
  int lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    const double u0 = (region.lo[a] - origin_[a]) / cell_[a], u1 = (region.hi[a] - origin_[a]) / cell_[a];
    if (!(u1 >= 0.0) || !(u0 < n_[static_cast<size_t>(a)])) return 0.0;
    lo[a] = std::max(0, static_cast<int>(std::floor(u0)));
    hi[a] = std::min(n_[static_cast<size_t>(a)] - 1, static_cast<int>(std::floor(u1)));
  }
  double bound = 0.0;
  for (int k = lo[2]; k <= hi[2]; ++k)
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int i = lo[0]; i <= hi[0]; ++i) bound = std::max(bound, majorant_[cell_index(i, j, k)]);
  return bound;
}

Aabb ParticleDensity::bounds() const { return field_.size() ? field_.bounds() : Aabb{Vec3(-1.0), Vec3(1.0)}; }

// Exact for the Gaussians as ParticleField::density_integral, from the lists of the cells the
// segment crosses: each Gaussian counted once, in the cell holding the segment's point nearest its
// centre (where its support, if it reaches the segment, is listed).
std::optional<double> ParticleDensity::density_integral(const Vec3& a, const Vec3& b) const {
  const double length = glm::length(b - a);
  if (length == 0.0 || field_.size() == 0) return 0.0;
  const Ray ray{a, (b - a) / length};
  double s0 = 0.0, s1 = length;  // the part of the segment inside the grid
  if (!field_.bounds().clip(ray, s0, s1) || !(s1 > s0)) return 0.0;
  double sum = 0.0;
  auto walk = majorants_->walk(ray, s0, s1);
  MajorantSegment g;
  while (walk.next(g)) {
    if (g.density <= 0.0) continue;
    const bool last = g.t1 >= s1;
    for (size_t e = start_[g.cell]; e < start_[g.cell + 1]; ++e) {
      if (w_[e] == 0.0f) continue;  // padding
      const Vec3 d = Vec3(Vec3f(x_[e], y_[e], z_[e])) - a;
      const double t = glm::dot(d, ray.direction), tc = std::clamp(t, s0, s1);
      if (tc < g.t0 || (tc >= g.t1 && !last)) continue;  // counted in another cell
      const double inv_h2 = inv_h2_[e], h = 1.0 / std::sqrt(inv_h2);
      const Vec3 near = d - tc * ray.direction;
      if (glm::dot(near, near) * inv_h2 >= kCut * kCut) continue;
      const double perp2 = std::max(0.0, glm::dot(d, d) - t * t);
      // integral over s in [s0, s1] of w exp(-(perp^2 + (s - t)^2) / h^2)
      sum += static_cast<double>(w_[e]) * std::exp(-perp2 * inv_h2) * 0.5 * std::sqrt(kPi) * h * (std::erf((s1 - t) / h) - std::erf((s0 - t) / h));
    }
  }
  return sum;
}

}  // namespace haze::particles
