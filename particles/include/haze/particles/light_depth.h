// The optical depth toward a light through the particles' continuous density, tabulated in the
// light's frame: a deep shadow map (Lokovic and Veach 2000) whose texels are rays from the light,
// each holding the exact line integral of rho (field.h) at depth nodes along it. Direct light at
// any point is then one trilinear lookup instead of a line integral over the particles, so the
// network takes direct light at every particle in O(N) and the renderer at every ray step, where
// the light changes within a particle's Gaussian (seed 001 evaluates it at particle centres only).
#pragma once

#include <haze/core/light.h>
#include <haze/particles/field.h>

#include <span>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::particles {

// One particle's Gaussian (field.h): centre, width h and peak density w.
struct Gaussian {
  Vec3 x{0.0};
  double h = 0.0, w = 0.0;
};

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

  // Particles moved, resized or re-weighted (`before` and `after`, one Gaussian each, in the same
  // order): subtracts each old Gaussian's line integrals and adds the new one's, in the texels
  // they reach, instead of splatting every particle again. Returns false, changing nothing, when
  // a new Gaussian's support leaves the sphere the map was built over; then build a new map.
  // Each update adds float rounding of the order of 1e-7 of the depths it changes.
  bool update(std::span<const Gaussian> before, std::span<const Gaussian> after, int threads);
  // Whether the last update() changed any texel that depth(x) reads.
  bool touched(const Vec3& x) const;

  const Light& light() const { return light_; }
  int resolution() const { return resolution_; }
  int nodes() const { return nodes_; }
  size_t bytes() const;

 private:
  struct Face {
    Vec3 axis, t1, t2;  // the face's central ray direction and the image-plane frame
    std::vector<float> depth;  // [(j * M + i) * K + k]
    std::vector<unsigned char> touched;  // [j * M + i]: changed by the last update()
  };
  Light light_;
  bool directional_ = false;
  Vec3 origin_{0.0};  // the light's position; for a directional light, the window's centre
  Vec3 centre_{0.0};  // the sphere holding every particle's support when the map was built
  double radius_ = 0.0;
  double extent_ = 0.0;   // directional: half the window's width; perspective: tan of the half-angle
  double s0_ = 0.0, ds_ = 0.0;  // depth of node k: s0 + k ds (along the ray, from origin_)
  int resolution_ = 0, nodes_ = 0;
  std::vector<Face> faces_;

  // x in face f's texel coordinates (continuous, texel centres at integers) and depth s.
  int locate(const Vec3& x, double& u, double& v, double& s) const;
  // Texel (i, j)'s ray on face f: its origin and unit direction.
  void texel_ray(const Face& f, int i, int j, Vec3& o, Vec3& d) const;
  // Adds the Gaussians' line integrals to the face's nodes; `running` sums the part past each
  // Gaussian with one prefix sum over every texel (a whole map), else node by node (a few).
  void splat(Face& f, std::span<const Gaussian> gaussians, bool running, int threads);
  // One Gaussian's part of splat() for a directional light, to the texels [i0, i1] x [j0, j1]; the
  // whole Gaussian past its last node into `tail` (running), else into every node past it.
  void splat_parallel(Face& f, const Vec3& x, double h, double w, int i0, int i1, int j0, int j1, float* tail) const;
};

}  // namespace haze::particles

#pragma GCC visibility pop
