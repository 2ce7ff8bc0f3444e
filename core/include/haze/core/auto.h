// Method "auto": the cheapest method and settings expected to stay under a relative error
// tolerance, chosen from the scene alone (never from a reference image). The rules and their
// thresholds come from the trade measurements (docs/TRADEOFFS.md, `haze bench trade`).
#pragma once

#include <haze/core/method.h>
#include <haze/core/scene.h>

#include <string>
#include <vector>

namespace haze {

// What the choice looks at.
struct SceneFeatures {
  bool particles = false;    // a particles block and no medium
  bool homogeneous = false;  // constant density
  bool bounded = false;      // the medium has finite bounds
  bool surfaces = false;
  bool sky = false, directional = false;  // light types besides point and spot
  double optical_diameter = 0.0;  // largest density integral through the medium's centre along x, y or z, times the largest sigma_t
  double albedo = 0.0;            // largest channel
  // The share of the image's light scattered more than once, estimated as albedo (1 - e^(-tau / 2)):
  // the chance that light scattered once meets the medium again before it leaves.
  double multiple_share = 0.0;
};
SceneFeatures scene_features(const Scene& scene);

struct AutoChoice {
  std::string method;
  nlohmann::json settings = nlohmann::json::object();
  std::vector<std::string> why;  // the features and the rule that decided, one line each
};

// Throws haze::Error for a tolerance outside (0, 1). The choice may name a method of a module that
// is not registered; method "auto" then renders with the reference instead.
AutoChoice choose_method(const Scene& scene, double tolerance);

}  // namespace haze
