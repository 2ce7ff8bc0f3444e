// Lights that cannot reach anything in a scene, found before a render so that no method spends
// time (optical-depth volumes, first-collision sources, light samples) on them.
#pragma once

#include <haze/core/scene.h>

#include <string>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

struct CulledLight {
  size_t index = 0;  // in scene.lights
  std::string why;
};

// The lights of `scene` whose light reaches neither the medium nor any surface, so that they add
// nothing to any image, whatever the method or camera: lights of zero power, and spot lights
// whose cone misses the medium's bounds (a bounding sphere around them) and every surface. Light
// that reaches nothing escapes, so culling is exact. With an unbounded medium no spot light is
// culled that way.
// With `single_scattering` (a method whose image holds light scattered or reflected once, at
// points the camera sees), spot lights whose cone misses the camera's view (outside one of the
// frustum's side planes, or behind the camera) are culled too: exact for such methods.
std::vector<CulledLight> culled_lights(const Scene& scene, bool single_scattering = false);

}  // namespace haze

#pragma GCC visibility pop
