// The ranges a scene's values must lie in, so that every method's float32 and double arithmetic
// stays finite (docs/SCENES.md, "Limits"). check_scene (scene.h) enforces them.
#pragma once

#include <haze/core/math.h>

namespace haze {

// |x|, |y| and |z| of any point: camera, lights, bounds, blob centres, surfaces (a farther light is
// a directional light). Float32 keeps 1e-7 of a coordinate: at 1e9, a hundred units.
inline constexpr double kMaxCoordinate = 1e9;
inline bool within_reach(const Vec3& p) { return max_abs(p) <= kMaxCoordinate; }  // false for NaN
// Light intensity, irradiance and radiance, emission and background.
inline constexpr double kMaxRadiometric = 1e15;
// sigma_t times the density's largest value: extinction per unit length.
inline constexpr double kMaxExtinction = 1e9;
// A Phong exponent.
inline constexpr double kMaxShininess = 1e5;
// |g| of the Henyey-Greenstein and Cornette-Shanks lobes: 1e-4 rad wide at the limit.
inline constexpr double kMaxAsymmetry = 0.9999;

}  // namespace haze
