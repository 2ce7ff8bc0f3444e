// Lights (docs/SCENES.md, "lights"): point (radiant intensity I, irradiance I / d^2), spot
// (I0 cos^n(theta) inside the cone half-angle), directional (irradiance E), sky (radiance from
// outside the medium, the same in every direction).
#pragma once

#include <haze/core/math.h>

#include <span>
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

// Equiangular nodes (Kulla and Fajardo 2012) for an integral over t in [t0, t1] along the ray of a
// function that peaks like 1 / d^2, d the distance from ray.at(t) to `centre`: with t_c the ray's
// closest approach, at distance b, t = t_c + b tan(theta) for theta at the midpoints of `count`
// equal parts of the stretch's angle, each weighted d^2 / b dtheta, so that
//   integral f dt ~ sum_n weight_n f(t_n)
// is exact for f = 1 / d^2. count = ceil(angle / max_angle), at most t.size(); writes the nodes
// and returns count (0 for an empty stretch).
int equiangular_nodes(const Ray& ray, const Vec3& centre, double t0, double t1, double max_angle, std::span<double> t,
                      std::span<double> weight);

}  // namespace haze

#pragma GCC visibility pop
