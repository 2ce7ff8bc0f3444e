// Lights that reach nothing (core/light_culling.h): zero power, a spot cone that misses the
// medium and every surface, or (single scattering) one that misses the view.
#include <haze/core/light_culling.h>

#include <haze/core/camera.h>
#include <haze/core/medium.h>

#include <algorithm>
#include <cmath>

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

// Is the cone entirely outside the half-space n . x >= d (n unit)? Its apex is outside and none of
// its rays turns toward the inside: angle(a, n) >= 90 degrees + theta.
bool cone_outside(const Vec3& p, const Vec3& a, double theta, const Vec3& n, double d) {
  if (glm::dot(n, p) >= d) return false;
  const double angle = std::acos(std::clamp(glm::dot(a, n), -1.0, 1.0));
  return angle >= 0.5 * kPi + theta + 1e-9;
}

// Does the cone miss the camera's view: outside the half-space in front of the camera, or outside
// one of the four that hold the film's edges (planes through the eye for a pinhole camera,
// parallel to the view for an orthographic one)?
bool cone_misses_view(const Vec3& p, const Vec3& a, double theta, const Camera& camera) {
  if (camera.type != Camera::Type::pinhole && camera.type != Camera::Type::orthographic) return false;  // a host's: not culled
  const Vec3 forward = glm::normalize(camera.look_at - camera.position);
  const Vec3 right = glm::normalize(glm::cross(forward, camera.up));
  const Vec3 up = glm::cross(right, forward);
  const double aspect = static_cast<double>(camera.width_px) / camera.height_px;
  const Vec3& c = camera.position;
  if (cone_outside(p, a, theta, forward, glm::dot(forward, c))) return true;
  if (camera.type == Camera::Type::orthographic) {
    const double half_h = 0.5 * camera.height, half_w = aspect * half_h;
    for (const auto& [n, half] : {std::pair{right, half_w}, {-right, half_w}, {up, half_h}, {-up, half_h}})
      if (cone_outside(p, a, theta, n, glm::dot(n, c) - half)) return true;
    return false;
  }
  const double t = std::tan(0.5 * camera.fov_y_deg * kPi / 180.0);
  // Inward normals of the side planes through the eye: f t_edge -+ e for edge directions f + e t_edge.
  for (const auto& [edge, t_edge] : {std::pair{right, aspect * t}, {-right, aspect * t}, {up, t}, {-up, t}}) {
    const Vec3 n = glm::normalize(forward * t_edge - edge);
    if (cone_outside(p, a, theta, n, glm::dot(n, c))) return true;
  }
  return false;
}

}  // namespace

std::vector<CulledLight> culled_lights(const Scene& scene, bool single_scattering) {
  std::vector<CulledLight> culled;
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
      const double length = glm::length(spot->direction);
      if (!(length > 0.0) || !std::isfinite(length)) continue;  // the methods report it
      const Vec3 axis = spot->direction / length;
      const double theta = std::clamp(spot->cone_deg, 0.0, 180.0) * kPi / 180.0;
      if (single_scattering && cone_misses_view(spot->position, axis, theta, scene.camera)) {
        culled.push_back({i, "spot light whose cone misses the view (the method sees single scattering only)"});
        continue;
      }
      if (scene.medium) {
        const Aabb bounds = medium_bounds(*scene.medium);
        if (!bounds.bounded()) continue;
        if (cone_meets_ball(spot->position, axis, theta, 0.5 * (bounds.lo + bounds.hi), 0.5 * glm::length(bounds.extent()))) continue;
      }
      const bool lights_a_surface = std::any_of(scene.surfaces.begin(), scene.surfaces.end(), [&](const Surface& s) {
        if (const auto* ball = std::get_if<Sphere>(&s.shape)) return cone_meets_ball(spot->position, axis, theta, ball->center, ball->radius);
        if (const auto* mesh = std::get_if<Mesh>(&s.shape)) {
          const Aabb& box = mesh->triangles->bounds();
          return cone_meets_ball(spot->position, axis, theta, 0.5 * (box.lo + box.hi), 0.5 * glm::length(box.extent()));
        }
        const auto& plane = std::get<Plane>(s.shape);
        return cone_meets_plane(spot->position, axis, theta, plane.point, plane.normal);
      });
      if (!lights_a_surface) culled.push_back({i, "spot light whose cone misses the medium and every surface"});
    }
  }
  return culled;
}

}  // namespace haze
