// The optical depth toward a light through the particles' continuous density, tabulated in the
// light's frame: a deep shadow map (Lokovic and Veach 2000) whose texels are rays from the light,
// each holding the exact line integral of rho (field.h) at depth nodes along it. Direct light at
// any point is then one trilinear lookup instead of a line integral over the particles, so the
// network takes direct light at every particle in O(N) and the renderer at every ray step, where
// the light changes within a particle's Gaussian (seed 001 evaluates it at particle centres only).
#pragma once

#include <haze/core/light.h>
#include <haze/particles/field.h>

#include <vector>

namespace haze::particles {

class LightDepthMap {
 public:
  // A directional light: one orthographic map over the particles' support. A point or spot light:
  // one perspective map when it is outside that support, a cube map of six when inside. Texels
  // and depth nodes are spaced half the mean particle width (at the support's centre, for
  // perspective maps). Throws haze::Error for a sky light.
  LightDepthMap(const ParticleField& field, const Light& light, int threads);

  // integral of rho from x toward the light (to its position, or to infinity for a directional one).
  double depth(const Vec3& x) const;
  // core's arrival() at x with the irradiance attenuated by exp(-sigma_t depth(x)) and, within
  // `nearest` of a point or spot light, held at its value at that distance.
  bool arrival(const Vec3& x, const Rgb& sigma_t, double nearest, LightArrival& out) const;

  int resolution() const { return resolution_; }
  int nodes() const { return nodes_; }
  size_t bytes() const;

 private:
  struct Face {
    Vec3 axis, t1, t2;  // the face's central ray direction and the image-plane frame
    std::vector<float> depth;  // [(j * M + i) * K + k]
  };
  Light light_;
  bool directional_ = false;
  Vec3 origin_{0.0};  // the light's position; for a directional light, the window's centre
  double extent_ = 0.0;   // directional: half the window's width; perspective: tan of the half-angle
  double s0_ = 0.0, ds_ = 0.0;  // depth of node k: s0 + k ds (along the ray, from origin_)
  int resolution_ = 0, nodes_ = 0;
  std::vector<Face> faces_;

  // x in face f's texel coordinates (continuous, texel centres at integers) and depth s.
  int locate(const Vec3& x, double& u, double& v, double& s) const;
  // Texel (i, j)'s ray on face f: its origin and unit direction.
  void texel_ray(const Face& f, int i, int j, Vec3& o, Vec3& d) const;
  void splat(Face& f, const ParticleField& field, int threads);
};

}  // namespace haze::particles
