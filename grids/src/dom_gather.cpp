#include "dom_gather.h"

#include "dom_internal.h"
#include "dom_surfaces.h"

#include <haze/core/grid_walk.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace haze::grids::dom {

namespace {
constexpr int kSurfaceDirections = 64;  // over the sphere: the hemisphere above a surface point gets about half
// A step whose midpoint lies within kNearLight steps of a point or spot light (so that it spans
// more than about 1 / kNearLight radians as seen from it) integrates that light's single scattering
// over equiangular nodes, each at most kNodeAngle radians.
constexpr double kNearLight = 4.0, kNodeAngle = 0.1;
constexpr int kMostNodes = 32;
// A point or spot light's glow about its direction: s(psi) = 1 up to kGlowInner, smoothly 0 at
// kGlowOuter (radians), taken over kGlowRings x kGlowSpokes polar nodes (Gather::around).
constexpr double kGlowInner = 0.3, kGlowOuter = 0.9;
constexpr int kGlowRings = 3, kGlowSpokes = 4;
constexpr size_t kMostGlows = 64;  // lights whose glow is taken apart, at most
// Their rays carry one light's single scattering, smooth but near it (where the equiangular nodes
// take over): steps kGlowStep times the gather's.
constexpr double kGlowStep = 4.0;
// A sphere that covers at least this solid angle seen from a step replaces the medium's scattered
// light arriving through it with what it reflects (Gather::sphere_correction).
constexpr double kSphereSolidAngle = 0.02;
// Gather::glossy's nodes over the Phong lobe.
constexpr int kLobeRings = 4, kLobeSpokes = 6;

double glow_share(double psi) {
  if (psi <= kGlowInner) return 1.0;
  if (psi >= kGlowOuter) return 0.0;
  const double x = (kGlowOuter - psi) / (kGlowOuter - kGlowInner);
  return x * x * (3.0 - 2.0 * x);
}
}

Gather::Gather(const Scene& delta, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths, const DomSolution& solution,
               double step_cells, int threads, const SurfaceLight* surfaces)
    : delta_(delta),
      volume_(volume),
      depths_(depths),
      solution_(solution),
      surfaces_(surfaces),
      visibility_(surface_visibility(volume.density, delta.lights, delta.surfaces, threads)),
      around_(DirectionSet::fibonacci(kSurfaceDirections)) {
  const Vec3 h = volume.density.cell_size();
  step_ = step_cells * std::min({h.x, h.y, h.z});
  const double f = solution.delta_m_fraction;
  sigma_t_ = delta_m_sigma_t(volume.sigma_t_scale, volume.albedo, f);
  albedo_ = delta_m_albedo(volume.albedo, f);
  single_albedo_ = volume.albedo / (Rgb(1.0) - volume.albedo * f);
  cone_ = cone_tangent(kSurfaceDirections);
  if (!delta.surfaces.empty())
    for (int j = 0; j < around_.size(); ++j) around_weights_.push_back(inscatter_weights(solution, -around_[j]));
  // The scattered radiance's mean over directions from the moments: sum_d (1 / D) L_d.
  const DirectionSet& set = *solution.directions;
  Eigen::VectorXd uniform = Eigen::VectorXd::Constant(set.size(), 1.0 / set.size());
  mean_radiance_ = solution.separable->basis().transpose() * uniform;
  for (const Surface& s : delta.surfaces)
    if (std::holds_alternative<Sphere>(s.shape)) spheres_.push_back(&s);
  // Midpoints in psi over [0, kGlowOuter] and in phi; sin psi dpsi dphi is the solid angle.
  const double d_psi = kGlowOuter / kGlowRings, d_phi = 2.0 * kPi / kGlowSpokes;
  for (int r = 0; r < kGlowRings; ++r)
    for (int k = 0; k < kGlowSpokes; ++k) {
      const double psi = (r + 0.5) * d_psi, phi = (k + 0.5) * d_phi;
      glow_.push_back({Vec3(std::sin(psi) * std::cos(phi), std::sin(psi) * std::sin(phi), std::cos(psi)), std::sin(psi) * d_psi * d_phi * glow_share(psi)});
    }
}

void Gather::only_planes(int first, int last) {
  const auto& n = volume_.density.resolution();
  first_plane_ = first, last_plane_ = last;
  moment_offset_ = static_cast<size_t>(solution_.first_plane) * static_cast<size_t>(n[0]) * static_cast<size_t>(n[1]);
}

Rgb Gather::along(const Ray& ray, double t_end, const Eigen::VectorXd& c, Rgb& transmittance, double cone) const {
  return along(ray, 0.0, t_end, &c, nullptr, kAll, transmittance, cone);
}

Rgb Gather::along_stretch(const Ray& ray, double t_start, double t_end, const Eigen::VectorXd& c, Rgb& transmittance, double least_step) const {
  return along(ray, t_start, t_end, &c, nullptr, kAll, transmittance, 0.0, least_step);
}

Rgb Gather::along(const Ray& ray, double t_start, double t_end, const Eigen::VectorXd* c, const double* share, size_t only,
                  Rgb& transmittance, double cone, double least_step) const {
  const DenseGrid& density = volume_.density;
  Rgb radiance(0.0);
  transmittance = Rgb(1.0);
  double t0 = t_start, t1 = t_end;
  if (!density.bounds().clip(ray, t0, t1) || !(t1 > t0)) return radiance;
  const auto n = static_cast<size_t>(solution_.terms());
  std::array<double, 64> small;  // the moments at a step: no allocation for up to 64 terms
  std::vector<double> large(n > small.size() ? n : 0);
  double* m = n > small.size() ? large.data() : small.data();
  const double step = std::max(only == kAll ? step_ : kGlowStep * step_, least_step);
  const int steps = static_cast<int>(std::ceil((t1 - t0) / step));
  const double dt = (t1 - t0) / steps;
  const bool beside_spheres = c && surfaces_ && cone == 0.0 && !spheres_.empty();  // camera rays: sphere_correction
  LightArrival a;
  for (int s = 0; s < steps; ++s) {
    const Vec3 p = ray.at(t0 + (s + 0.5) * dt);
    if (first_plane_ > 0 || last_plane_ < density.resolution()[2]) {
      const double z = (p.z - density.bounds().lo.z) / density.cell_size().z;
      const int plane = std::clamp(static_cast<int>(std::floor(z)), 0, density.resolution()[2] - 1);
      if (plane < first_plane_ || plane >= last_plane_) continue;
    }
    const TrilinearStencil stencil(density.bounds(), density.resolution(), p);
    const double rho = stencil.apply(density.values().data());
    if (rho <= 0.0) continue;
    // The moments and the depth to each light keep their slope into the outer half cells
    // (clamped there, the top half cell of a slab under a grazing sun would be lit as deep as its
    // centre, and a grazing view would see the centre's in-scattering up to the face).
    const TrilinearStencil outer(density.bounds(), density.resolution(), p, true);
    Rgb inscattered(0.0), mean_scattered(0.0);
    for (int ch = 0; c && ch < solution_.channels; ++ch) {
      std::fill(m, m + n, 0.0);
      const float* moments = solution_.moments[static_cast<size_t>(ch)].data();
      for (int e = 0; e < 8; ++e) {
        const float* cell = moments + (outer.offset[e] - moment_offset_) * n;
        for (size_t k = 0; k < n; ++k) m[k] += outer.weight[e] * static_cast<double>(cell[k]);
      }
      double j = 0.0;
      for (size_t k = 0; k < n; ++k) j += (*c)(static_cast<int>(k)) * m[k];
      inscattered[ch] = std::max(0.0, j);
      for (size_t k = 0; beside_spheres && k < n; ++k) mean_scattered[ch] += mean_radiance_(static_cast<int>(k)) * m[k];
    }
    if (solution_.channels == 1) inscattered = Rgb(inscattered[0]), mean_scattered = Rgb(mean_scattered[0]);
    if (beside_spheres) inscattered -= sphere_correction(p, ray.direction, mean_scattered);
    Rgb single(0.0);
    const double radius = cone * (t0 + (s + 0.5) * dt);
    for (size_t l = 0; l < delta_.lights.size(); ++l) {
      if ((only != kAll && l != only) || (share && share[l] == 0.0) || !arrival(delta_.lights[l], p, a)) continue;
      // A camera ray near a point or spot light: the step's 1 / d^2 peak integrated over
      // equiangular nodes (the midpoint alone misses it), depth and visibility at the midpoint.
      Rgb q = volume_.phase.eval(-a.to_light, -ray.direction) * a.irradiance;
      if (cone == 0.0 && std::isfinite(a.distance) && a.distance < kNearLight * dt) {
        std::array<double, kMostNodes> t, w;
        const int count = equiangular_nodes(ray, p + a.distance * a.to_light, t0 + s * dt, t0 + (s + 1) * dt, kNodeAngle, t, w);
        if (count > 1) {
          q = Rgb(0.0);
          for (int i = 0; i < count; ++i) {
            LightArrival b;
            if (arrival(delta_.lights[l], ray.at(t[i]), b)) q += w[i] / dt * volume_.phase.eval(-b.to_light, -ray.direction) * b.irradiance;
          }
        }
      }
      if (q == Rgb(0.0)) continue;
      if (a.distance < radius) q *= (a.distance / radius) * (a.distance / radius);
      const double depth = std::max(0.0, outer.apply(depths_[l].values().data()));
      const double visible = visibility_.empty() ? 1.0 : stencil.apply(visibility_[l].values().data());
      single += (share ? share[l] : 1.0) * q * visible * glm::exp(-volume_.sigma_t_scale * depth);
    }
    const Rgb step_transmittance = glm::exp(-sigma_t_ * rho * dt);
    radiance += transmittance * (Rgb(1.0) - step_transmittance) * (albedo_ * inscattered + single_albedo_ * single);
    transmittance *= step_transmittance;
  }
  return radiance;
}

Rgb Gather::sphere_correction(const Vec3& x, const Vec3& direction, const Rgb& mean) const {
  Rgb out(0.0);
  for (const Surface* s : spheres_) {
    const auto& sphere = std::get<Sphere>(s->shape);
    const Vec3 to_centre = sphere.center - x;
    const double d = glm::length(to_centre);
    const double along_ray = glm::dot(to_centre, direction);
    if (!(d > sphere.radius) || (along_ray > 0.0 && d * d - along_ray * along_ray < sphere.radius * sphere.radius)) continue;
    const double sin2 = (sphere.radius / d) * (sphere.radius / d), solid_angle = 2.0 * kPi * (1.0 - std::sqrt(1.0 - sin2));
    if (solid_angle < kSphereSolidAngle) continue;
    const Vec3 w = to_centre / d, n = -w;
    const Rgb seen = surfaces_->reflected(*s, sphere.center + sphere.radius * n, n, n);
    // Light arriving from w, scattered toward the eye (-direction), under the delta-M scaled phase.
    const double phase = volume_.phase.eval(-w, -direction) / (1.0 - solution_.delta_m_fraction);
    out += solid_angle * phase * (mean - seen);
  }
  return out;
}

void Gather::glow_directions(const Vec3& point, std::vector<Vec3>& out) const {
  out.assign(delta_.lights.size(), Vec3(0.0));
  if (out.size() > kMostGlows) return;  // every light's glow over the K directions then
  LightArrival a;
  for (size_t l = 0; l < delta_.lights.size(); ++l)
    if (arrival(delta_.lights[l], point, a) && std::isfinite(a.distance) && a.distance > 0.0) out[l] = a.to_light;
}

Rgb Gather::arriving(const Vec3& point, int j, const Rgb& sky, const std::vector<Vec3>& to_light) const {
  std::array<double, kMostGlows> share;
  const bool shared = to_light.size() <= share.size();  // else no light's glow is taken apart
  for (size_t l = 0; shared && l < to_light.size(); ++l)
    share[l] = to_light[l] == Vec3(0.0) ? 1.0 : 1.0 - glow_share(std::acos(std::clamp(glm::dot(to_light[l], around_[j]), -1.0, 1.0)));
  return arriving(point, around_[j], around_weights_[static_cast<size_t>(j)], sky, shared ? share.data() : nullptr, cone_);
}

Rgb Gather::arriving(const Vec3& point, const Vec3& w, const Eigen::VectorXd& c, const Rgb& sky, const double* share, double cone) const {
  const Ray up{point, w};
  double t_next = kInfinity;
  Vec3 n;
  const Surface* hit = nearest_surface(delta_.surfaces, up, kInfinity, t_next, n);
  Rgb t_up;
  const Rgb radiance = along(up, 0.0, t_next, &c, share, kAll, t_up, cone);
  if (!hit) return radiance + t_up * sky;
  return surfaces_ ? radiance + t_up * surfaces_->reflected(*hit, up.at(t_next), n, -w, false) : radiance;
}

Rgb Gather::glossy(const Vec3& point, const Vec3& normal, const Vec3& wo, const Surface& surface, const Rgb& sky) const {
  if (surface.ks == Rgb(0.0)) return Rgb(0.0);
  const Vec3 r = 2.0 * glm::dot(wo, normal) * normal - wo;
  const double n = surface.shininess, weight = (n + 2.0) / (n + 1.0) / (kLobeRings * kLobeSpokes);
  // Each node stands for an equal share of the lobe's solid angle, about 2 pi / (n + 1).
  const double cone = cone_tangent(2 * static_cast<int>(std::ceil(n + 1.0)) * kLobeRings * kLobeSpokes);
  Rgb sum(0.0);
  for (int i = 0; i < kLobeRings; ++i) {
    const double cos_alpha = std::pow((i + 0.5) / kLobeRings, 1.0 / (n + 1.0));
    for (int k = 0; k < kLobeSpokes; ++k) {
      const Vec3 w = direction_around(r, cos_alpha, (k + 0.5) * 2.0 * kPi / kLobeSpokes);
      const double cos_i = glm::dot(normal, w);
      if (cos_i <= 0.0) continue;
      sum += weight * cos_i * arriving(point, w, inscatter_weights(solution_, -w), sky, nullptr, cone);
    }
  }
  return surface.ks * sum;
}

Rgb Gather::single(const Vec3& point, const Vec3& w, size_t l) const {
  const Ray up{point, w};
  double t_next = kInfinity;
  Vec3 n;
  nearest_surface(delta_.surfaces, up, kInfinity, t_next, n);
  Rgb unused;
  return along(up, 0.0, t_next, nullptr, nullptr, l, unused, 0.0);
}

}  // namespace haze::grids::dom
