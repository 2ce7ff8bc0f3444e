// Internal: the light the scene's surfaces reflect, from the DOM solution: into the grid through
// its faces (solve_dom's DomBoundary) and toward other surfaces (render_dom's gather).
#pragma once

#include "dom_gather.h"

#include <vector>

namespace haze::grids::dom {

class SurfaceLight;
// With `surfaces`, E_s also holds what other surfaces reflect onto each texel (Gather::around).
SurfaceTexels surface_texels(const Scene& delta, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths,
                             const DomSolution& solution, const Rgb& sky, double step_cells, int threads,
                             const SurfaceLight* surfaces = nullptr);

class SurfaceLight {
 public:
  // `delta` holds the scene's point, spot and directional lights (no sky) with `depths` for them;
  // the arguments must outlive this.
  SurfaceLight(const Scene& delta, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths, const SurfaceTexels& texels,
               const Rgb& sky, double delta_m_fraction);

  // What a surface point reflects toward wo:
  //   sum_lights brdf(w_l, wo) E_l (n . w_l) V_l e^(-sigma_t' depth_l)  +  kd / pi E_s,
  // the direct light (shadowed by surfaces, through the medium with the solve's extinction) through
  // the whole BRDF and E_s through its Lambert part: from the texels on planes, pi sky past them
  // and on spheres. With `glossy` false the direct light too goes through the Lambert part only:
  // a gather's few directions would alias a glossy surface's highlight into spikes (a caustic).
  Rgb reflected(const Surface& surface, const Vec3& p, const Vec3& n, const Vec3& wo, bool glossy = true) const;
  // E_s at a surface point with unit normal n: from the texels, pi sky past them.
  Rgb irradiance(const Surface& surface, const Vec3& p, const Vec3& n) const;

  // What enters the grid at a face point along w (pointing into the grid): the sky where the ray
  // back along -w meets no surface, else what the surface hit reflects toward w.
  Rgb entering(const Vec3& point, const Vec3& w) const;

  // The boundary for solve_dom; valid while this lives.
  DomBoundary boundary() const;

 private:
  const Scene& delta_;
  const ExtinctionVolume& volume_;
  const std::vector<DenseGrid>& depths_;
  const SurfaceTexels& texels_;
  Rgb sky_, sigma_t_;
  double offset_;  // the back ray starts this far inside the face: a plane on the face is hit
};

}  // namespace haze::grids::dom
