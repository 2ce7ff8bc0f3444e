// Internal: the DOM solution's scattered light arriving at a point, by marching rays through the
// solved moments (render_dom's camera gather, and the surfaces' light in dom_surfaces.cpp).
#pragma once

#include <haze/core/scene.h>
#include <haze/grids/dom.h>

#include <limits>
#include <vector>

namespace haze::grids::dom {

class SurfaceLight;

class Gather {
 public:
  // `delta` holds the scene's point, spot and directional lights (no sky) with `depths` for them;
  // the arguments must outlive the gather. Rays step `step_cells` cells.
  // With `surfaces`, around() adds the light other surfaces reflect.
  Gather(const Scene& delta, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths, const DomSolution& solution,
         double step_cells, int threads, const SurfaceLight* surfaces = nullptr);

  // Along the ray up to t_end, the formal solution of the (delta-M scaled) equation for light
  // scattered at least once:
  //   L += T' (1 - e^(-sigma_t' rho step)) [albedo' sum_k c_k(w) m_k + albedo / (1 - albedo f) q1(w)],
  //   q1(w) = sum_lights p(w_light . w) E_light V_light e^(-sigma_t depth_light)   (single scattering),
  // c = inscatter_weights(solution, -ray.direction); density, depths, visibility and moments
  // trilinear at each step's midpoint. Writes the transmittance T' over the stretch. With cone > 0
  // the ray stands for a cone of directions of that tangent of its half-angle: a light nearer
  // than the cone's radius at the step, cone t, delivers its irradiance at that radius, no more
  // (a direction passing by a point light would otherwise count its 1 / d^2 peak for the whole cone).
  // With cone 0 (a camera ray), a step near a point or spot light takes q1 over equiangular nodes
  // (equiangular_nodes) and a sphere it passes replaces the medium's light from its direction
  // (sphere_correction).
  Rgb along(const Ray& ray, double t_end, const Eigen::VectorXd& c, Rgb& transmittance, double cone = 0.0) const;
  // The same over the ray's stretch [t_start, t_end] alone, in steps of its own, at least
  // `least_step` long (a froxel column's slice between two boundaries, stepped no finer than the
  // columns' spacing there: render_distances chains them).
  Rgb along_stretch(const Ray& ray, double t_start, double t_end, const Eigen::VectorXd& c, Rgb& transmittance, double least_step = 0.0) const;

  // From now on along() takes only the steps whose midpoints lie in z planes [first, last), the
  // steps themselves unchanged, and reads moments from a solution holding planes from
  // solution.first_plane on (gather_planes: a rank's part).
  void only_planes(int first, int last);

  // The light arriving at a surface point from the hemisphere about `normal`, weighted:
  //   sum_j (4 pi / K) max(0, n . w_j) weight(w_j) [L_j + T_j L_e]
  //     + sum_lights sum_i w_i max(0, n . w_i) weight(w_i) L1_i,
  // over the K Fibonacci directions w_j; L_j, T_j from along() toward w_j up to the next surface;
  // L_e the sky where no surface is hit, else, given `surfaces`, what the surface hit reflects
  // (SurfaceLight::reflected), or nothing. A point or spot light's single scattering glows about
  // its direction u (like 1 / psi at an angle psi from it), which K directions alias: its share
  // s(psi) (1 below kGlowInner, smoothly 0 at kGlowOuter) is taken instead over a polar grid
  // about u (nodes w_i, psi uniform: the 1 / psi cancels sin psi), L1_i that light's single
  // scattering toward w_i, and the K directions carry the rest, 1 - s(psi) (for up to 64 lights;
  // with more, the K directions carry every glow whole).
  template <class Weight>
  Rgb around(const Vec3& point, const Vec3& normal, const Rgb& sky, const Weight& weight) const {
    Rgb sum(0.0);
    std::vector<Vec3> to_light;
    glow_directions(point, to_light);
    for (int j = 0; j < around_.size(); ++j) {
      const double cos_i = glm::dot(normal, around_[j]);
      if (cos_i <= 0.0) continue;
      sum += around_.weight(j) * cos_i * weight(around_[j]) * arriving(point, j, sky, to_light);
    }
    for (size_t l = 0; l < to_light.size(); ++l) {
      if (to_light[l] == Vec3(0.0)) continue;
      const Frame frame = Frame::from_z(to_light[l]);
      for (const PolarNode& node : glow_) {
        const Vec3 w = frame.to_world(node.local);
        const double cos_i = glm::dot(normal, w);
        if (cos_i <= 0.0) continue;
        sum += node.weight * cos_i * weight(w) * single(point, w, l);
      }
    }
    return sum;
  }

  // The light a glossy surface's Phong lobe (ks, shininess) reflects toward wo from the medium,
  // the sky and other surfaces, taken over the lobe: about the mirror direction r of wo, nodes at
  // the midpoints of kLobeRings parts in u = cos^(n+1)(alpha) and kLobeSpokes in phi, each of
  // weight ks (n + 2) / (n + 1) / nodes (normalized Phong, Surface::brdf, equal lobe shares), times
  // max(0, n . w) and the radiance arriving from w (as around()'s). 64 directions alias a lobe
  // narrower than their spacing (shininess 24: about 12 degrees, against 25).
  Rgb glossy(const Vec3& point, const Vec3& normal, const Vec3& wo, const Surface& surface, const Rgb& sky) const;

 private:
  struct PolarNode {
    Vec3 local;     // about +z: (sin psi cos phi, sin psi sin phi, cos psi)
    double weight;  // sin psi dpsi dphi s(psi)
  };
  // Per delta light, the unit direction from `point` to it, or 0 for a directional light.
  void glow_directions(const Vec3& point, std::vector<Vec3>& out) const;
  // K direction j's radiance: along() with each light's single scattering times 1 - s(psi).
  Rgb arriving(const Vec3& point, int j, const Rgb& sky, const std::vector<Vec3>& to_light) const;
  // The same toward any direction w, in-scattering weights c, each light's single scattering times
  // share[l] (whole without `share`), the ray standing for a cone of that tangent (along()); what a
  // surface hit reflects through its Lambert part only (SurfaceLight::reflected).
  Rgb arriving(const Vec3& point, const Vec3& w, const Eigen::VectorXd& c, const Rgb& sky, const double* share, double cone) const;
  // The sweeps let the medium's light through spheres inside the grid. At x, for a step along
  // `direction`, a sphere seen in a cone of solid angle Omega about w sends what its nearest point
  // reflects toward x (SurfaceLight::reflected, direct light through the whole BRDF), L_s, in
  // place of the medium's light there, taken as its mean over directions `mean`: the
  // in-scattering changes by Omega p'(w -> eye) (mean - L_s), returned (p' the delta-M scaled
  // phase function). Camera rays passing a sphere only: in front of a sphere a ray ends on, or
  // from a surface's own gather, the mean is too crude where it matters (the sphere fills half of
  // what the steps next to it see).
  Rgb sphere_correction(const Vec3& x, const Vec3& direction, const Rgb& mean) const;
  // Light l's single scattering arriving at `point` from direction w, up to the next surface.
  Rgb single(const Vec3& point, const Vec3& w, size_t l) const;
  // along() with the moments' in-scattering only given c, and each light's single scattering
  // times share[l] (all of it without `share`), or only light `only`'s (in longer steps), in
  // steps at least `least_step` long.
  static constexpr size_t kAll = static_cast<size_t>(-1);
  Rgb along(const Ray& ray, double t_start, double t_end, const Eigen::VectorXd* c, const double* share, size_t only, Rgb& transmittance,
            double cone, double least_step = 0.0) const;

  const Scene& delta_;
  const ExtinctionVolume& volume_;
  const std::vector<DenseGrid>& depths_;
  const DomSolution& solution_;
  const SurfaceLight* surfaces_;
  std::vector<DenseGrid> visibility_;
  double step_, cone_ = 0.0;
  int first_plane_ = 0, last_plane_ = std::numeric_limits<int>::max();
  size_t moment_offset_ = 0;  // cells before the solution's first plane
  Rgb sigma_t_, albedo_, single_albedo_;
  DirectionSet around_;
  std::vector<Eigen::VectorXd> around_weights_;
  std::vector<PolarNode> glow_;
  Eigen::VectorXd mean_radiance_;          // the moments' weights for the mean scattered radiance
  std::vector<const Surface*> spheres_;
};

}  // namespace haze::grids::dom
