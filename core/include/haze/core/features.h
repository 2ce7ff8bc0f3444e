// The features of a scene that method "auto" and each method's auto rule (MethodInfo::offer) look
// at, computed once from the scene alone.
#pragma once

#include <haze/core/scene.h>

#include <string>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

// What the choice looks at.
struct SceneFeatures {
  // "constant", "rbf", "grid", or the type of a module's density field (FieldDensity::type,
  // "particles"), whose optical diameter is not estimated.
  std::string density;
  bool homogeneous = false;  // constant density
  bool bounded = false;      // the medium has finite bounds
  bool surfaces = false;
  bool sky = false, directional = false;  // light types besides point and spot
  double optical_diameter = 0.0;          // largest density integral through the medium's centre along x, y or z, times the largest sigma_t
  double albedo = 0.0;                    // largest channel
  // The share of the image's light scattered more than once, estimated as albedo (1 - e^(-tau / 2)):
  // the chance that light scattered once meets the medium again before it leaves.
  double multiple_share = 0.0;
};
inline bool field_density(const SceneFeatures& f) { return !f.density.empty() && f.density != "constant" && f.density != "rbf" && f.density != "grid"; }

// Single scattering is enough when the multiple-scattering share is under half the tolerance (for
// a module's field the share is not estimated: never).
inline bool single_scattering_suffices(const SceneFeatures& f, double tolerance) { return field_density(f) ? false : f.multiple_share < 0.5 * tolerance; }

}  // namespace haze

#pragma GCC visibility pop
