#include <haze/core/blackbody.h>
#include <haze/core/error.h>
#include <haze/core/grid_walk.h>
#include <haze/core/limits.h>
#include <haze/core/majorant.h>
#include <haze/core/medium.h>
#include <haze/core/progress.h>

#include <algorithm>

namespace haze {

Medium::Medium(std::shared_ptr<const DensityField> field, const MediumDesc& desc)
    : field_(std::move(field)), sigma_t_(desc.sigma_t), albedo_(desc.albedo), phase_(desc.phase), emission_(desc.emission) {
  if (!field_) throw Error("medium.density", "a field without data", "a density field");
}

double Medium::density_integral(const Vec3& a, const Vec3& b) const {
  if (const std::optional<double> exact = field_->density_integral(a, b)) return *exact;
  double length = glm::length(b - a);
  if (length == 0.0) return 0.0;
  Ray ray{a, (b - a) / length};
  double t0 = 0.0, t1 = length;
  if (!bounds().clip(ray, t0, t1)) return 0.0;
  // Composite Simpson over an even number of steps no longer than feature_size() / 4.
  int n = 2 * std::max(1, static_cast<int>(std::ceil((t1 - t0) / (0.5 * feature_size()))));
  n = std::min(n, 1 << 16);
  double h = (t1 - t0) / n;
  double sum = density(ray.at(t0)) + density(ray.at(t1));
  for (int i = 1; i < n; ++i) sum += (i % 2 ? 4.0 : 2.0) * density(ray.at(t0 + i * h));
  return sum * h / 3.0;
}

std::shared_ptr<const DensityField> DensityField::sibling(const std::string& name, const std::string& field) const {
  throw Error(field, "\"" + name + "\"", "no grid name: this density has no other grids (a vdb density's file has)");
}

Rgb emitted_radiance(const Emission& emission, const Vec3& x, double density) {
  Rgb e(0.0);
  if (emission.strength > 0.0) e += emission.strength * emission.color * (emission.grid ? emission.grid->density(x) : density);
  if (emission.blackbody_intensity > 0.0) {
    const double T = emission.temperature * (emission.temperature_grid ? emission.temperature_grid->density(x) : 1.0);
    if (T > 0.0) e += emission.blackbody_intensity * emission.blackbody_tint * blackbody_color(T) * (kBlackbodySigma * T * T * T * T);
  }
  return e;
}

Rgb Medium::emission(const Vec3& x) const {
  if (!emission_.emits() || !bounds().contains(x)) return Rgb(0.0);
  return emitted_radiance(emission_, x, emission_.strength > 0.0 && !emission_.grid ? density(x) : 0.0);
}

const MajorantGrid& Medium::majorants() const {
  std::call_once(majorants_once_, [&] {
    majorants_ = field_->majorants();
    if (!majorants_) majorants_ = std::make_shared<MajorantGrid>(*field_);
  });
  return *majorants_;
}

Rgb Medium::transmittance(const Vec3& a, const Vec3& b) const {
  return glm::exp(-sigma_t_ * density_integral(a, b));
}

Rgb Medium::transmittance_along(const Vec3& x, const Vec3& direction, double distance) const {
  double t0 = 0.0, t1 = distance;
  if (!bounds().clip({x, direction}, t0, t1) || !(t1 > t0)) return Rgb(1.0);
  if (std::isfinite(t1)) return transmittance(x + direction * t0, x + direction * t1);
  Rgb out(1.0);
  if (max_density(bounds()) > 0.0)
    for (int c = 0; c < 3; ++c)
      if (sigma_t_[c] > 0.0) out[c] = 0.0;
  return out;
}

namespace {

class ConstantField final : public DensityField {
 public:
  ConstantField(const Aabb& bounds, double value) : bounds_(bounds), value_(value) {}
  Aabb bounds() const override { return bounds_; }
  double density(const Vec3& x) const override { return bounds_.contains(x) ? value_ : 0.0; }
  double max_density(const Aabb&) const override { return value_; }
  double feature_size() const override { return kInfinity; }
  bool homogeneous() const override { return true; }
  std::optional<double> density_integral(const Vec3& a, const Vec3& b) const override {
    double length = glm::length(b - a);
    if (length == 0.0) return 0.0;
    double t0 = 0.0, t1 = length;
    if (!bounds_.clip({a, (b - a) / length}, t0, t1)) return 0.0;
    return value_ * (t1 - t0);
  }

 private:
  Aabb bounds_;
  double value_;
};

// Evaluates the RBF sum directly (seed 003 eq. 2); grids/ injects it into a grid for speed.
class RbfField final : public DensityField {
 public:
  RbfField(const MediumDesc& desc, const RbfDensity& rbf) : blobs_(rbf.blobs) {
    bounds_ = medium_bounds(desc);
    feature_ = kInfinity;
    for (const auto& b : blobs_) {
      max_ += b.weight;
      feature_ = std::min(feature_, 1.0 / b.sharpness);
    }
  }
  Aabb bounds() const override { return bounds_; }
  double density(const Vec3& x) const override {
    if (!bounds_.contains(x)) return 0.0;
    double rho = 0.0;
    for (const auto& b : blobs_) {
      Vec3 d = x - b.center;
      rho += b.weight * std::exp(-b.sharpness * b.sharpness * glm::dot(d, d));
    }
    return rho;
  }
  // Each blob is at most weight * exp(-a^2 d^2) in the region, d its centre's distance to the box.
  double max_density(const Aabb& region) const override {
    double bound = 0.0;
    for (const auto& b : blobs_) {
      Vec3 nearest = glm::clamp(b.center, region.lo, region.hi);
      Vec3 d = b.center - nearest;
      bound += b.weight * std::exp(-b.sharpness * b.sharpness * glm::dot(d, d));
    }
    return std::min(bound, max_);
  }
  double feature_size() const override { return feature_; }
  // Exact: along the segment each Gaussian is w e^(-s^2 d^2) e^(-s^2 (t - tc)^2), d the centre's
  // distance from the line and tc its foot, whose integral is an erf difference (taken as an erfc
  // difference on either tail, where the erfs cancel). O(blobs), where Simpson's steps of 1/4 of
  // the sharpest blob took seconds per ray past sharpness 1000.
  std::optional<double> density_integral(const Vec3& a, const Vec3& b) const override {
    const double length = glm::length(b - a);
    if (!(length > 0.0)) return 0.0;
    const Ray ray{a, (b - a) / length};
    double t0 = 0.0, t1 = length;
    if (!bounds_.clip(ray, t0, t1) || !(t1 > t0)) return 0.0;
    double sum = 0.0;
    for (const auto& blob : blobs_) {
      const double tc = glm::dot(blob.center - a, ray.direction), s = blob.sharpness;
      const Vec3 off = blob.center - ray.at(tc);
      const double u0 = s * (t0 - tc), u1 = s * (t1 - tc);
      const double span = u0 >= 0.0 ? std::erfc(u0) - std::erfc(u1) : u1 <= 0.0 ? std::erfc(-u1) - std::erfc(-u0) : std::erf(u1) - std::erf(u0);
      sum += blob.weight * std::exp(-s * s * glm::dot(off, off)) * (0.5 * std::sqrt(kPi) / s) * span;
    }
    return sum;
  }

 private:
  std::vector<RbfBlob> blobs_;
  Aabb bounds_;
  double max_ = 0.0, feature_ = kInfinity;
};

class GridField final : public DensityField {
 public:
  // A grid's own values are copied; a view of the caller's memory is only viewed.
  GridField(const MediumDesc& desc, const GridDensity& grid) : bounds_(desc.bounds), resolution_(grid.resolution), owned_(grid.values) {
    values_ = grid.view.data() ? grid.view : std::span<const float>(owned_);
    if (!bounds_.bounded()) throw Error("medium.bounds", "unbounded", "bounds for a grid density");
    const size_t cells = static_cast<size_t>(resolution_[0]) * static_cast<size_t>(resolution_[1]) * static_cast<size_t>(resolution_[2]);
    if (values_.size() != cells) throw Error("medium.density.values", to_text(values_.size()) + " values", to_text(cells) + " values");
    max_ = values_.empty() ? 0.0 : static_cast<double>(*std::max_element(values_.begin(), values_.end()));
    Vec3 cell = bounds_.extent() / Vec3(resolution_[0], resolution_[1], resolution_[2]);
    feature_ = std::min({cell.x, cell.y, cell.z});
  }
  Aabb bounds() const override { return bounds_; }
  // Trilinear between cell centres, clamped to the outermost centres inside the bounds.
  double density(const Vec3& x) const override {
    if (!bounds_.contains(x)) return 0.0;
    return TrilinearStencil(bounds_, resolution_, x).apply(values_.data());
  }
  // The largest sample among the cells whose centres the region's trilinear lookups can touch.
  double max_density(const Aabb& region) const override {
    const auto& r = resolution_;
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      double scale = r[a] / bounds_.extent()[a];
      double u0 = (region.lo[a] - bounds_.lo[a]) * scale - 0.5, u1 = (region.hi[a] - bounds_.lo[a]) * scale - 0.5;
      lo[a] = static_cast<int>(std::clamp(std::floor(u0), 0.0, r[a] - 1.0));
      hi[a] = static_cast<int>(std::clamp(std::ceil(u1), 0.0, r[a] - 1.0));
      if (!(u1 >= u0)) return max_;  // NaN or an empty region: the global bound
    }
    float bound = 0.0f;
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int x = lo[0]; x <= hi[0]; ++x)
          bound = std::max(bound, values_[(static_cast<size_t>(z) * static_cast<size_t>(r[1]) + static_cast<size_t>(y)) * static_cast<size_t>(r[0]) + static_cast<size_t>(x)]);
    return static_cast<double>(bound);
  }
  double feature_size() const override { return feature_; }

 private:
  Aabb bounds_;
  std::array<int, 3> resolution_;
  std::vector<float> owned_;
  std::span<const float> values_;
  double max_ = 0.0, feature_ = 1.0;
};

}  // namespace

Aabb medium_bounds(const MediumDesc& desc) {
  if (const auto* f = std::get_if<FieldDensity>(&desc.density); f && f->field) return f->field->bounds();
  const auto* rbf = std::get_if<RbfDensity>(&desc.density);
  if (!rbf || desc.bounds.bounded() || rbf->blobs.empty()) return desc.bounds;
  // Beyond 6 / sharpness a blob's density is below weight * e^-36: treat it as zero.
  Aabb box{Vec3(kInfinity), Vec3(-kInfinity)};
  for (const auto& b : rbf->blobs) {
    box.lo = glm::min(box.lo, b.center - Vec3(6.0 / b.sharpness));
    box.hi = glm::max(box.hi, b.center + Vec3(6.0 / b.sharpness));
  }
  return box;
}

GridDensity sample_grid(const DensityField& field, int resolution, int threads) {
  const Aabb bounds = field.bounds();
  const Vec3 e = bounds.extent();
  const double cell = std::max({e.x, e.y, e.z}) / resolution;
  std::array<int, 3> r{};
  for (int a = 0; a < 3; ++a) r[static_cast<size_t>(a)] = std::max(2, static_cast<int>(std::ceil(e[a] / cell)));
  GridDensity grid{r, std::vector<float>(static_cast<size_t>(r[0]) * static_cast<size_t>(r[1]) * static_cast<size_t>(r[2]), 0.0f)};
  const Vec3 size = e / Vec3(r[0], r[1], r[2]);
  parallel_for(r[2], threads, 1, [&](long long k0, long long k1) {
    for (auto k = static_cast<int>(k0); k < k1; ++k)
      for (int j = 0; j < r[1]; ++j)
        for (int i = 0; i < r[0]; ++i)
          grid.values[(static_cast<size_t>(k) * static_cast<size_t>(r[1]) + static_cast<size_t>(j)) * static_cast<size_t>(r[0]) + static_cast<size_t>(i)] =
              static_cast<float>(field.density(bounds.lo + (Vec3(i, j, k) + 0.5) * size));
  });
  return grid;
}

std::shared_ptr<const DensityField> density_field(const MediumDesc& desc) {
  if (const auto* c = std::get_if<ConstantDensity>(&desc.density)) return std::make_shared<ConstantField>(desc.bounds, c->value);
  if (const auto* r = std::get_if<RbfDensity>(&desc.density)) return std::make_shared<RbfField>(desc, *r);
  if (const auto* f = std::get_if<FieldDensity>(&desc.density)) {
    if (!f->field) throw Error("medium.density", "a " + f->type + " field without data", "a density field");
    return f->field;
  }
  return std::make_shared<GridField>(desc, std::get<GridDensity>(desc.density));
}

std::unique_ptr<Medium> make_medium(const MediumDesc& desc) { return std::make_unique<Medium>(density_field(desc), desc); }

}  // namespace haze
