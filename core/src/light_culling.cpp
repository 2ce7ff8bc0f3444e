// Lights that reach nothing (core/light_culling.h): zero power, or a spot cone that misses the
// medium and every surface.
#include <haze/core/light_culling.h>

#include <haze/core/medium.h>

#include <algorithm>
#include <cmath>
#include <optional>

namespace haze {

namespace {

bool dark(const Rgb& c) { return !(c.r > 0.0 || c.g > 0.0 || c.b > 0.0); }

// Does the cone (apex p, unit axis a, half-angle theta) meet the ball (centre c, radius r)? True
// when unsure.
bool cone_meets_ball(const Vec3& p, const Vec3& a, double theta, const Vec3& c, double r) {
  const Vec3 v = c - p;
  const double distance = glm::length(v);
  if (distance <= r) return true;
  const double angle = std::acos(std::clamp(glm::dot(v, a) / distance, -1.0, 1.0));
  return angle <= theta + std::asin(r / distance) + 1e-9;
}

// Does a ray of the cone reach the plane through q with unit normal n (either side)? The cone's
// ray closest in angle to the direction toward the plane, m, is max(angle(a, m) - theta, 0) away
// from it, and it reaches the plane when that is under 90 degrees.
bool cone_meets_plane(const Vec3& p, const Vec3& a, double theta, const Vec3& q, const Vec3& n) {
  const double side = glm::dot(p - q, n);
  if (side == 0.0) return true;
  const Vec3 m = side > 0.0 ? -n : n;
  const double angle = std::acos(std::clamp(glm::dot(a, m), -1.0, 1.0));
  return angle - theta < 0.5 * kPi - 1e-9;
}

}  // namespace

std::vector<CulledLight> culled_lights(const Scene& scene) {
  std::vector<CulledLight> culled;
  std::optional<Aabb> medium_bounds;  // built on the first spot light that needs it
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& light = scene.lights[i];
    if (const auto* point = std::get_if<PointLight>(&light)) {
      if (dark(point->intensity)) culled.push_back({i, "point light of zero intensity"});
    } else if (const auto* sun = std::get_if<DirectionalLight>(&light)) {
      if (dark(sun->irradiance)) culled.push_back({i, "directional light of zero irradiance"});
    } else if (const auto* sky = std::get_if<SkyLight>(&light)) {
      if (dark(sky->radiance)) culled.push_back({i, "sky light of zero radiance"});
    } else if (const auto* spot = std::get_if<SpotLight>(&light)) {
      if (dark(spot->intensity)) {
        culled.push_back({i, "spot light of zero intensity"});
        continue;
      }
      if (!scene.particles.is_null()) continue;
      const double length = glm::length(spot->direction);
      if (!(length > 0.0) || !std::isfinite(length)) continue;  // the methods report it
      const Vec3 axis = spot->direction / length;
      const double theta = std::clamp(spot->cone_deg, 0.0, 180.0) * kPi / 180.0;
      if (scene.medium) {
        if (!medium_bounds) medium_bounds = make_medium(*scene.medium)->bounds();
        if (!medium_bounds->bounded()) continue;
        const Vec3 centre = 0.5 * (medium_bounds->lo + medium_bounds->hi);
        if (cone_meets_ball(spot->position, axis, theta, centre, 0.5 * glm::length(medium_bounds->extent()))) continue;
      }
      const bool lights_a_surface = std::any_of(scene.surfaces.begin(), scene.surfaces.end(), [&](const Surface& s) {
        if (const auto* ball = std::get_if<Sphere>(&s.shape)) return cone_meets_ball(spot->position, axis, theta, ball->center, ball->radius);
        const auto& plane = std::get<Plane>(s.shape);
        return cone_meets_plane(spot->position, axis, theta, plane.point, plane.normal);
      });
      if (!lights_a_surface) culled.push_back({i, "spot light whose cone misses the medium and every surface"});
    }
  }
  return culled;
}

}  // namespace haze
