// Media: one density field (DensityField: the scene's constant, RBF and grid densities, and the
// modules' fields) times the coefficients, sigma_t(x) = sigma_t_scale * density(x) per RGB channel,
// sigma_s = albedo * sigma_t (docs/SCENES.md, "medium"); and the media a scene file describes.
#pragma once

#include <haze/core/math.h>
#include <haze/core/phase.h>

#include <array>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

class MajorantGrid;

struct ConstantDensity {
  double value = 1.0;
};

// A Gaussian RBF: weight * exp(-sharpness^2 |x - center|^2) (seed 003 eq. 2).
struct RbfBlob {
  Vec3 center{0.0};
  double weight = 1.0;
  double sharpness = 1.0;
};
struct RbfDensity {
  std::vector<RbfBlob> blobs;
};

// Cell-centred samples over the medium's bounds, x fastest, then y, then z; trilinear in between.
// The samples are the grid's own (`values`) or a view of the caller's memory (`view`, used when
// set): a view is never copied, so it must outlive every medium made from it and every Solution
// whose scene holds it, which is until an update hands that solution a new medium (the grid
// methods sample it into their own grids at prepare and update; the others read it as they render).
struct GridDensity {
  std::array<int, 3> resolution{1, 1, 1};
  std::vector<float> values;
  std::span<const float> view = {};

  std::span<const float> samples() const { return view.data() ? view : std::span<const float>(values); }
  // A grid over the caller's nx * ny * nz floats (checked when a medium or solution is made).
  static GridDensity viewing(const std::array<int, 3>& resolution, std::span<const float> samples) { return {resolution, {}, samples}; }
};

// A density field: the one interface every medium's density answers through, the scene's own
// (constant, RBF and grid: make_medium makes them fields) and a module's (the particles' Gaussians,
// a VDB grid: FieldDensity). Core renders any of them through Medium; the grid methods sample a
// module's at their cells' centres.
class DensityField {
 public:
  virtual ~DensityField() = default;
  // Where the density may be non-zero: finite, but for a constant density without bounds.
  virtual Aabb bounds() const = 0;
  virtual double density(const Vec3& x) const = 0;
  virtual double max_density(const Aabb& region) const = 0;  // an upper bound over the region
  virtual double feature_size() const = 0;                   // a length over which it changes little
  // Constant within its bounds.
  virtual bool homogeneous() const { return false; }
  // integral along a -> b; by default Medium's composite Simpson.
  virtual std::optional<double> density_integral(const Vec3& /*a*/, const Vec3& /*b*/) const { return std::nullopt; }
  // Its own majorant grid (Medium::majorants); by default built from max_density.
  virtual std::shared_ptr<const MajorantGrid> majorants() const { return nullptr; }
  // Another grid of the same data by name (a VDB file's "flame" or "temperature"), for emission;
  // by default there is none: throws haze::Error naming `field`.
  virtual std::shared_ptr<const DensityField> sibling(const std::string& name, const std::string& field) const;
};
struct FieldDensity {
  std::string type;  // what supplies it, for messages ("particles")
  std::shared_ptr<const DensityField> field;
  // Cells along the longest side when a grid method samples it (0: the method's own resolution,
  // but no more than max_resolution where that is set: the data's own voxels, say).
  int grid_resolution = 0;
  int max_resolution = 0;
};

using Density = std::variant<ConstantDensity, RbfDensity, GridDensity, FieldDensity>;

// Emission (docs/SCENES.md, "medium.emission", after Blender Cycles' Principled Volume): radiance per unit
// length added to the transfer equation's source, unaffected by albedo, inside the medium's bounds:
//   L_e(x) = strength color g(x) + blackbody_intensity tint blackbody_color(T) sigma T^4,
// g the emission grid where given, else the medium's density; T = temperature times the
// temperature grid where given (kelvin, Cycles' convention); sigma = kBlackbodySigma (blackbody.h).
struct Emission {
  double strength = 0.0;
  Rgb color{1.0};
  std::shared_ptr<const DensityField> grid;
  double blackbody_intensity = 0.0;
  Rgb blackbody_tint{1.0};
  double temperature = 1000.0;
  std::shared_ptr<const DensityField> temperature_grid;

  bool emits() const { return strength > 0.0 || blackbody_intensity > 0.0; }
  // Whether L_e may be non-zero where the density is zero (a grid of its own, or blackbody).
  bool beyond_density() const { return (strength > 0.0 && grid) || blackbody_intensity > 0.0; }
};

// L_e at x where the medium's density is `density` (Emission's formula).
Rgb emitted_radiance(const Emission& emission, const Vec3& x, double density);

struct MediumDesc {
  Aabb bounds;  // unbounded unless given; a grid density needs bounds
  Density density = ConstantDensity{};
  Rgb sigma_t{1.0};
  Rgb albedo{0.8};
  PhaseFunction phase;
  Emission emission;
};

// A medium: one density field times the coefficients (sigma_t(x) = sigma_t_scale density(x),
// sigma_s = albedo sigma_t), its phase function and emission. Made by make_medium.
class Medium {
 public:
  Medium(std::shared_ptr<const DensityField> field, const MediumDesc& desc);

  // Where the density may be non-zero; unbounded media return the default Aabb.
  Aabb bounds() const { return field_->bounds(); }
  double density(const Vec3& x) const { return field_->density(x); }
  // An upper bound of density over region (intersected with bounds()): a majorant.
  double max_density(const Aabb& region) const { return field_->max_density(region); }
  // A length over which the density changes little: the step numerical quadrature should use.
  double feature_size() const { return field_->feature_size(); }
  bool homogeneous() const { return field_->homogeneous(); }
  // integral of density along the segment a -> b, clipped to bounds(): the field's own where it
  // has one (exact for constant and RBF densities), else composite Simpson with steps of at most
  // feature_size() / 4.
  double density_integral(const Vec3& a, const Vec3& b) const;
  // The majorant iterator along a ray (pbrt-v4's SampleT_maj over a DDA majorant grid): segments
  // of the ray with an upper bound of the density on each. The field's own, or built on first use
  // from max_density (16^3 cells; one for homogeneous or unbounded media); thread-safe.
  const MajorantGrid& majorants() const;
  const DensityField& field() const { return *field_; }

  const Rgb& sigma_t_scale() const { return sigma_t_; }
  const Rgb& albedo() const { return albedo_; }
  const PhaseFunction& phase() const { return phase_; }
  Rgb sigma_t(const Vec3& x) const { return sigma_t_ * density(x); }
  Rgb sigma_s(const Vec3& x) const { return albedo_ * sigma_t(x); }
  // L_e(x), the emitted radiance per unit length (Emission); 0 outside bounds().
  Rgb emission(const Vec3& x) const;
  const Emission& emission_desc() const { return emission_; }
  bool emits() const { return emission_.emits(); }
  // exp(-optical depth) between a and b, per channel.
  Rgb transmittance(const Vec3& a, const Vec3& b) const;
  // From x along the unit direction over distance, which may be infinite (directional lights, the
  // sky): an unbounded medium then absorbs every channel it extinguishes.
  Rgb transmittance_along(const Vec3& x, const Vec3& direction, double distance) const;

 private:
  std::shared_ptr<const DensityField> field_;
  Rgb sigma_t_, albedo_;
  PhaseFunction phase_;
  Emission emission_;
  mutable std::once_flag majorants_once_;
  mutable std::shared_ptr<const MajorantGrid> majorants_;
};

// The field's density at the cell centres of `resolution` cells along the longest side of its
// bounds (each axis ceil(extent / cell), at least 2), x fastest: what the grid methods solve on.
GridDensity sample_grid(const DensityField& field, int resolution, int threads = 0);

// Checks what a caller built in code as Scene::from_json checks a file: bounds, coefficients,
// phase, and the density (a grid's sample count against its resolution, every sample finite and
// >= 0; RBF blobs finite with weight >= 0 and sharpness > 0). Throws haze::Error naming
// `path`.<field>, the value and what was expected.
void check_medium(const MediumDesc& desc, const std::string& path = "medium");

// The density a scene describes as a field: constant (within the bounds), the RBF sum evaluated
// directly (seed 003 eq. 2), the grid trilinear between cell centres (its own values copied, a
// view only viewed), or the module's field. Only a grid's sample count is checked here.
std::shared_ptr<const DensityField> density_field(const MediumDesc& desc);
// The medium a scene describes: Medium(density_field(desc), desc). haze::prepare checks it first
// (check_medium).
std::unique_ptr<Medium> make_medium(const MediumDesc& desc);

// make_medium(desc)->bounds() without building the medium: desc.bounds, or for an RBF density
// without them the box beyond which every blob is below e^-36 of its weight.
Aabb medium_bounds(const MediumDesc& desc);

}  // namespace haze

#pragma GCC visibility pop
