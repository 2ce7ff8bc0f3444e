// Lights (DESIGN.md "Units"): point (radiant intensity I, irradiance I / d^2), spot
// (I0 cos^n(theta) inside the cone half-angle), directional (irradiance E), sky (radiance from
// outside the medium, the same in every direction).
#pragma once

#include <haze/core/math.h>

#include <variant>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

struct PointLight {
  Vec3 position{0.0};
  Rgb intensity{1.0};  // W/sr per channel
  bool operator==(const PointLight&) const = default;
};

struct SpotLight {
  Vec3 position{0.0};
  Vec3 direction{0.0, 0.0, -1.0};  // unit axis the light shines along
  Rgb intensity{1.0};              // I0, on the axis
  double exponent = 1.0;           // n in cos^n(theta)
  double cone_deg = 45.0;          // half-angle of the cone, degrees
  bool operator==(const SpotLight&) const = default;
};

struct DirectionalLight {
  Vec3 direction{0.0, 0.0, -1.0};  // unit propagation direction of the light
  Rgb irradiance{1.0};             // on a plane perpendicular to it
  bool operator==(const DirectionalLight&) const = default;
};

struct SkyLight {
  Rgb radiance{1.0};
  bool operator==(const SkyLight&) const = default;
};

using Light = std::variant<PointLight, SpotLight, DirectionalLight, SkyLight>;

// What a delta light (point, spot, directional) delivers at x, ignoring occlusion.
struct LightArrival {
  Vec3 to_light{0.0};      // unit vector from x toward the light (minus the propagation direction)
  double distance = 0.0;   // to the light; infinite for a directional light
  Rgb irradiance{0.0};     // on a plane perpendicular to to_light
};

// Whether the light's intensity, irradiance or radiance is the same in every channel.
bool is_grey(const Light& light);

// Delta lights only: a sky light has no single direction (returns false).
bool arrival(const Light& light, const Vec3& x, LightArrival& out);

// Distances t in (0, t_max) where the ray crosses the spot light's cone (its lateral surface or the
// plane of its apex), sorted: between consecutive ones the ray is wholly inside or outside.
std::vector<double> cone_crossings(const SpotLight& spot, const Ray& ray, double t_max);

}  // namespace haze

#pragma GCC visibility pop
