// Method "auto": the cheapest method and settings expected to stay under a relative error
// tolerance, chosen from the scene alone (never from a reference image). Each registered method
// bids through its MethodInfo::offer, whose thresholds and expected times come from the trade
// measurements (docs/TRADEOFFS.md, `haze bench trade`); the reference takes what nothing offers.
// Module auto/ (target haze::auto), above core: it chooses among whatever is registered.
#pragma once

#include <haze/core/features.h>
#include <haze/core/method.h>

#include <string>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

struct AutoChoice {
  std::string method;
  nlohmann::json settings = nlohmann::json::object();
  double expected_seconds = 0.0;  // the offer's (0 for the reference: it renders to its noise target)
  std::vector<std::string> why;  // the features, the chosen offer, then every other method's bid, one line each
};

// The lowest expected time among the registered methods' offers, else the reference with
// target_noise 0.75 T. Throws haze::Error for a tolerance outside (0, 1).
AutoChoice choose_method(const Scene& scene, double tolerance);
// What the offers look at, computed from the scene alone.
SceneFeatures scene_features(const Scene& scene);

// The registry's entry for method "auto", and its registration (haze::register_all calls it).
MethodInfo auto_info();
void register_auto();

}  // namespace haze

#pragma GCC visibility pop
