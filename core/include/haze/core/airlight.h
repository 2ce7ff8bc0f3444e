// Single-scattered airlight from a point light along a view segment in a homogeneous medium
// (seed 002 sec. 4.2.1, the angle-formulated airlight integral, eq. 4.3-4.8).
//
// In Haze's conventions (DESIGN.md) the thesis' C0 = kappa_t I0 e^(-kappa_t t) / h becomes
// sigma_s I e^(-sigma_t t) / h: the thesis writes kappa_t where sigma_s = albedo sigma_t belongs,
// and its p integrates to 1 over the sphere as Haze's does. With theta the angle of the light's
// emission direction from the perpendicular to the ray, x = t + h tan(theta) and r = h / cos(theta):
//   L_a = sigma_s I / h  integral_{theta0}^{thetad} e^(-sigma_t (x + r)) p(-sin theta) dtheta,
// theta0 = gamma - pi/2, thetad = atan((d_vp - t) / h), t = d_sv cos(gamma), h = d_sv sin(gamma).
#pragma once

#include <haze/core/phase.h>

namespace haze {

// One view segment and one point light (thesis table 4.1).
struct AirlightSegment {
  double d_sv = 1.0;        // viewer to light
  double gamma = 0.5;       // between the view direction and the direction to the light, [0, pi]
  double d_vp = kInfinity;  // viewer to the end of the segment (a surface), or infinite

  // From positions: the viewer, the unit view direction, the light, the segment length.
  static AirlightSegment from_points(const Vec3& viewer, const Vec3& direction, const Vec3& light, double length);
};

// The medium and the light's strength: L_a is proportional to sigma_s I.
struct AirlightMedium {
  double sigma_t = 1.0;
  double sigma_s = 1.0;
  double intensity = 1.0;
};

// The yardstick: adaptive Gauss-Kronrod quadrature of the angle-formulated integral to rel_tol.
// The segment must not touch the light (h > 0 and d_sv > 0).
double airlight_quadrature(const PhaseFunction& phase, const AirlightMedium& medium, const AirlightSegment& segment,
                           double rel_tol = 1e-10);

// Seed 004 / BEYOND.md: isotropic phase and no extinction,
// L = sigma_s I / (4 pi h) [atan((d_vp - t) / h) - atan(-t / h)]. A segment through the light is
// evaluated at h = 1e-9 d_sv (and d_sv >= 1e-12): large, finite, never NaN.
double airlight_no_extinction(const AirlightMedium& medium, const AirlightSegment& segment);

}  // namespace haze
