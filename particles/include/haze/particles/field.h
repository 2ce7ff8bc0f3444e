// The continuous density a particle set stands for, so that the same particles can be rendered by
// the network, the reference path tracer and the grid methods. One Gaussian per particle:
//   rho(x) = sum_p w_p exp(-|x - x_p|^2 / h_p^2),  h_p = delta_s_p,  w_p = rho_p / (6 sqrt(pi)),
// so a particle's integral, w_p pi^(3/2) h_p^3, is rho_p pi delta_s_p^3 / 6: its sphere's volume
// times its density. Each Gaussian is cut at 3 h_p (e^-9 = 1.2e-4 of its peak). Neighbourhoods
// come from a FLANN kd-tree: k nearest neighbours for the sizes, radius queries for rho(x).
#pragma once

#include <haze/core/medium.h>
#include <haze/particles/particle_set.h>

#include <array>
#include <memory>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::particles {

struct KdTree;  // internal

inline constexpr double kCut = 3.0;  // each Gaussian ends at kCut h

class ParticleField {
 public:
  // Where diameters are not given, delta_s_p = 2 r_k / k^(1/3) from the distance r_k to the k-th
  // nearest neighbour (the diameter of a sphere holding 1/k of that neighbourhood's volume), at
  // least 1e-3 of the set's bounding radius. Throws haze::Error when no size can follow (one
  // particle, or all at one point, without diameters). `particles` must outlive the field.
  explicit ParticleField(const ParticleView& particles, int neighbours = 8);
  ~ParticleField();
  ParticleField(const ParticleField&) = delete;
  ParticleField& operator=(const ParticleField&) = delete;

  size_t size() const { return h_.size(); }
  const ParticleView& particles() const { return view_; }
  Vec3 position(size_t p) const { return Vec3(view_.positions[p]); }
  double h(size_t p) const { return h_[p]; }          // the Gaussian's width, delta_s_p
  double weight(size_t p) const { return w_[p]; }     // its peak density w_p
  const std::vector<double>& diameters() const { return h_; }
  double mean_h() const { return h_mean_; }
  double max_h() const { return h_max_; }
  // The bounding sphere of the positions, and the box holding every particle's support.
  Vec3 centre() const { return centre_; }
  double radius() const { return radius_; }
  Aabb bounds() const { return bounds_; }

  double density(const Vec3& x) const;
  // The particles within `radius` of x (a FLANN radius query), in no particular order.
  std::vector<size_t> within(const Vec3& x, double radius) const;
  std::vector<float> density_at_particles(int threads) const;
  // integral of rho from x along the unit direction over length (may be infinite): exact for the
  // Gaussians (erf), summed over the particles whose support the segment meets.
  double density_integral(const Vec3& x, const Vec3& direction, double length) const;

 private:
  ParticleView view_;
  std::vector<double> h_, w_;
  double h_max_ = 0.0, h_mean_ = 0.0;
  Vec3 centre_{0.0};
  double radius_ = 0.0;
  Aabb bounds_;
  std::unique_ptr<KdTree> tree_;

  // FLANN's radius search around x (one query; unsorted), for density() and within().
  void radius_query(const Vec3& x, double radius, std::vector<std::vector<size_t>>& found, std::vector<std::vector<float>>& dist2) const;
};

// The particles' own density as core's DensityField (it owns the set and its field): what every
// method but the network renders a particle scene with. The reference and quadrature read the
// Gaussians themselves (line integrals in closed form); the grid methods sample them at
// `grid_resolution` cells along the longest side.
class ParticleDensity final : public DensityField {
 public:
  ParticleDensity(ParticleSet set, int neighbours = 8);
  const ParticleSet& set() const { return set_; }
  const ParticleField& field() const { return field_; }
  Aabb bounds() const override;
  // rho(x) as ParticleField::density, from a uniform grid over bounds() (cells about the mean
  // width, at most 128 a side) whose cells list, in float32, the Gaussians whose support meets
  // them: one cell a lookup, summed in SIMD lanes (simd/gaussian_sum.h), no allocation.
  double density(const Vec3& x) const override;
  // The largest majorant among the cells the region meets.
  double max_density(const Aabb& region) const override;
  double feature_size() const override { return field_.size() ? field_.mean_h() : 1.0; }
  std::optional<double> density_integral(const Vec3& a, const Vec3& b) const override;
  // The same cells, each bounded by its Gaussians at their largest in it (at the cell's point
  // nearest each centre): what the path tracer's delta tracking walks.
  std::shared_ptr<const MajorantGrid> majorants() const override { return majorants_; }

 private:
  ParticleSet set_;
  ParticleField field_;  // views set_
  Vec3 origin_{0.0}, cell_{1.0};
  std::array<int, 3> n_{1, 1, 1};
  // Cell c lists entries start_[c] .. start_[c + 1] (padded to kGaussianPad).
  std::vector<size_t> start_;
  std::vector<float> x_, y_, z_, inv_h2_, w_;
  std::vector<double> majorant_;  // per cell
  std::shared_ptr<const MajorantGrid> majorants_;
  size_t cell_index(int i, int j, int k) const {
    return (static_cast<size_t>(k) * static_cast<size_t>(n_[1]) + static_cast<size_t>(j)) * static_cast<size_t>(n_[0]) + static_cast<size_t>(i);
  }
};

// The medium of a particle set with its material: a FieldDensity over a ParticleDensity.
MediumDesc particle_medium(ParticleSet set, int grid_resolution = 96, int neighbours = 8);

}  // namespace haze::particles

#pragma GCC visibility pop
