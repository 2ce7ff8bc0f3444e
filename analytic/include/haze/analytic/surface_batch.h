// The analytic method's surface shading over batches of surface points in float32 lanes, Highway
// runtime dispatch. ISA-free header: per-target code in analytic/src/surface_batch-inl.h.
//
// Per point and point light, seed 002 eq. 4.9-4.15 in Haze's energy-normalized BRDFs: the direct
// light f(wi, wo) I / d^2 cos(theta_i) e^(-sigma_t d_in) (d_in the light's path inside the medium's
// box) where the light is visible, plus, where the point is in the medium, the airlight onto it
// sigma_s I e^(-T) / d [kd J1(T, theta_s) + ks J_n(T, theta'_s) max(0, n . R)], T = sigma_t d
// (SurfaceAirlightTable). The float64 form is the method's own per-pixel path (analytic.cpp).
#pragma once

#include <haze/analytic/airlight.h>

#include <cstddef>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::analytic {

// Points of one surface (structure of arrays, count rounded up to 16 long: whole vectors are read).
struct ShadingPoints {
  const float* p[3];       // positions
  const float* n[3];       // unit normals, facing the viewer
  const float* v[3];       // unit view directions, eye to point
  const float* in_medium;  // 1 where the point receives the airlight (inside the medium), else 0
  size_t count;
};
// The surface's material and its J tables (null where its kd or ks is zero, or no airlight).
struct ShadingMaterial {
  float kd[3], ks[3], shininess;
  const SurfaceAirlightTable* lambert;
  const SurfaceAirlightTable* phong;
};
// A point light and, per point, whether it sees it (1) or a surface hides it (0).
struct ShadingLight {
  float position[3];
  float intensity[3];
  const float* visible;
};
// The homogeneous medium: its box (infinite faces where unbounded) and coefficients.
struct ShadingMedium {
  double lo[3], hi[3];
  float sigma_t[3], sigma_s[3];
};

// radiance[3 i + c] = point i's radiance toward the viewer (best compiled target this CPU supports).
void shade_points(const ShadingMedium& medium, const ShadingMaterial& material, const ShadingLight* lights, size_t light_count,
                  const ShadingPoints& points, float* radiance);
// The scalar reference: the same float32 formulas, one point at a time.
void shade_points_reference(const ShadingMedium& medium, const ShadingMaterial& material, const ShadingLight* lights, size_t light_count,
                            const ShadingPoints& points, float* radiance);

}  // namespace haze::analytic

#pragma GCC visibility pop
