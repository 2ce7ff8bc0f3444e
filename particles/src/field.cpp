// The particles' continuous density (field.h): sizes from FLANN's nearest neighbours, density by
// FLANN radius queries, line integrals in closed form.
#include <haze/core/error.h>
#include <haze/core/progress.h>
#include <haze/particles/field.h>

#include "kd_tree.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace haze::particles {

ParticleField::ParticleField(const ParticleView& particles, int neighbours) : view_(particles) {
  validate(particles);
  const size_t n = particles.positions.size();
  if (n == 0) return;
  Aabb box{Vec3(kInfinity), Vec3(-kInfinity)};
  for (const Vec3f& x : particles.positions) box.lo = glm::min(box.lo, Vec3(x)), box.hi = glm::max(box.hi, Vec3(x));
  centre_ = 0.5 * (box.lo + box.hi);
  tree_ = std::make_unique<KdTree>(particles.positions);
  for (const Vec3f& x : particles.positions) radius_ = std::max(radius_, glm::length(Vec3(x) - centre_));
  if (!particles.diameters.empty()) {
    for (float ds : particles.diameters) h_.push_back(static_cast<double>(ds));
  } else {
    if (n < 2 || !(radius_ > 0.0))
      throw Error("particles.diameter", "missing", "diameters: " + std::string(n < 2 ? "a single particle" : "particles all at one point") +
                                                       " have no neighbours to size them by");
    const int k = std::min(neighbours, static_cast<int>(n) - 1);
    const Neighbourhoods nb = nearest_neighbours(*tree_, k);
    const double floor = 1e-3 * radius_, scale = 2.0 / std::cbrt(static_cast<double>(k));
    h_.resize(n);
    for (size_t p = 0; p < n; ++p)
      h_[p] = std::max(floor, scale * std::sqrt(static_cast<double>(nb.distances2[p * static_cast<size_t>(k) + static_cast<size_t>(k) - 1])));
  }
  w_.resize(n);
  for (size_t p = 0; p < n; ++p) w_[p] = (particles.density.empty() ? 1.0 : static_cast<double>(particles.density[p])) / (6.0 * std::sqrt(kPi));
  h_max_ = *std::max_element(h_.begin(), h_.end());
  h_mean_ = std::accumulate(h_.begin(), h_.end(), 0.0) / static_cast<double>(n);
  bounds_ = {box.lo - Vec3(kCut * h_max_), box.hi + Vec3(kCut * h_max_)};
}

ParticleField::~ParticleField() = default;

void ParticleField::radius_query(const Vec3& x, double radius, std::vector<std::vector<size_t>>& found, std::vector<std::vector<float>>& dist2) const {
  float q[3] = {static_cast<float>(x.x), static_cast<float>(x.y), static_cast<float>(x.z)};
  flann::SearchParams params(flann::FLANN_CHECKS_UNLIMITED);
  params.sorted = false;
  tree_->index.radiusSearch(flann::Matrix<float>(q, 1, 3), found, dist2, static_cast<float>(radius * radius), params);
}

double ParticleField::density(const Vec3& x) const {
  if (!tree_) return 0.0;
  std::vector<std::vector<size_t>> found;
  std::vector<std::vector<float>> dist2;
  radius_query(x, kCut * h_max_, found, dist2);
  double rho = 0.0;
  for (size_t j = 0; j < found[0].size(); ++j) {
    const size_t p = found[0][j];
    const double h2 = h_[p] * h_[p], d2 = static_cast<double>(dist2[0][j]);
    if (d2 < kCut * kCut * h2) rho += w_[p] * std::exp(-d2 / h2);
  }
  return rho;
}

std::vector<size_t> ParticleField::within(const Vec3& x, double radius) const {
  if (!tree_) return {};
  std::vector<std::vector<size_t>> found;
  std::vector<std::vector<float>> dist2;
  radius_query(x, radius, found, dist2);
  return std::move(found[0]);
}

std::vector<float> ParticleField::density_at_particles(int threads) const {
  std::vector<float> out(size());
  parallel_for(static_cast<long long>(size()), threads, 256, [&](long long p0, long long p1) {
    for (auto p = static_cast<size_t>(p0); p < static_cast<size_t>(p1); ++p) out[p] = static_cast<float>(density(position(p)));
  });
  return out;
}

double ParticleField::density_integral(const Vec3& x, const Vec3& direction, double length) const {
  double sum = 0.0;
  for (size_t p = 0; p < size(); ++p) {
    const Vec3 d = position(p) - x;
    const double h = h_[p], t = glm::dot(d, direction);
    if (t < -kCut * h || t > length + kCut * h) continue;
    const double perp2 = std::max(0.0, glm::dot(d, d) - t * t);
    if (perp2 >= kCut * kCut * h * h) continue;
    // integral over s in [0, length] of exp(-(perp^2 + (s - t)^2) / h^2)
    const double far = std::isfinite(length) ? std::erf((length - t) / h) : 1.0;
    sum += w_[p] * std::exp(-perp2 / (h * h)) * 0.5 * std::sqrt(kPi) * h * (far + std::erf(t / h));
  }
  return sum;
}

MediumDesc particle_medium(ParticleSet set, int grid_resolution, int neighbours) {
  MediumDesc m;
  m.sigma_t = set.material.sigma_t, m.albedo = set.material.albedo, m.phase = set.material.phase;
  auto density = std::make_shared<ParticleDensity>(std::move(set), neighbours);
  m.bounds = density->bounds();
  m.density = FieldDensity{"particles", std::move(density), grid_resolution};
  return m;
}

}  // namespace haze::particles
