// Internal: the DOM solution's scattered light arriving at a point, by marching rays through the
// solved moments (render_dom's camera gather, and the surfaces' light in dom_surfaces.cpp).
#pragma once

#include <haze/core/scene.h>
#include <haze/grids/dom.h>

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
  Rgb along(const Ray& ray, double t_end, const Eigen::VectorXd& c, Rgb& transmittance, double cone = 0.0) const;

  // The light arriving at a surface point from the hemisphere about `normal`, over the K
  // Fibonacci directions w_j (4 pi / K each), weighted:
  //   sum_j (4 pi / K) max(0, n . w_j) weight(w_j) [L_j + T_j L_e],
  // L_j, T_j from along() toward w_j up to the next surface; L_e the sky where no surface is hit,
  // else, given `surfaces`, what the surface hit reflects (SurfaceLight::reflected), or nothing.
  template <class Weight>
  Rgb around(const Vec3& point, const Vec3& normal, const Rgb& sky, const Weight& weight) const {
    Rgb sum(0.0);
    for (int j = 0; j < around_.size(); ++j) {
      const double cos_i = glm::dot(normal, around_[j]);
      if (cos_i <= 0.0) continue;
      sum += around_.weight(j) * cos_i * weight(around_[j]) * arriving(point, j, sky);
    }
    return sum;
  }

 private:
  Rgb arriving(const Vec3& point, int j, const Rgb& sky) const;

  const Scene& delta_;
  const ExtinctionVolume& volume_;
  const std::vector<DenseGrid>& depths_;
  const DomSolution& solution_;
  const SurfaceLight* surfaces_;
  std::vector<DenseGrid> visibility_;
  double step_, cone_ = 0.0;
  Rgb sigma_t_, albedo_, single_albedo_;
  DirectionSet around_;
  std::vector<Eigen::VectorXd> around_weights_;
};

}  // namespace haze::grids::dom
