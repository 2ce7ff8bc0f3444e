// check_scene: what every method relies on, for scenes from files and from the API alike.
#include <haze/core/error.h>
#include <haze/core/limits.h>
#include <haze/core/scene.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace haze {

namespace {

void point(const Vec3& p, const std::string& field, const char* hint = "") {
  if (!within_reach(p))
    throw Error(field, to_text(p), std::string("a point within 1e9 of the origin on every axis (haze::kMaxCoordinate)") + hint);
}

void direction(const Vec3& d, const std::string& field) {
  Vec3 unit = d;
  if (!make_unit(unit)) throw Error(field, to_text(d), "a non-zero vector of finite numbers");
}

void radiometric(const Rgb& c, const std::string& field) {
  if (!(std::isfinite(c.r + c.g + c.b) && std::min({c.r, c.g, c.b}) >= 0.0 && std::max({c.r, c.g, c.b}) <= kMaxRadiometric))
    throw Error(field, to_text(c), "values in [0, 1e15] (haze::kMaxRadiometric)");
}

void number(double x, const std::string& field, double lo, double hi, const char* expected) {
  if (!(x >= lo && x <= hi)) throw Error(field, to_text(x), expected);
}

void check_camera(const Camera& c) {
  if (c.type == Camera::Type::rays || c.type == Camera::Type::matrices) {
    // from_rays and from_matrices checked the rays and matrices; the eye must be in reach.
    if (c.type == Camera::Type::matrices) point(Vec3(c.view_inverse[3]), "camera.view", " for the eye");
    return;
  }
  point(c.position, "camera.position");
  point(c.look_at, "camera.look_at");
  Vec3 view = c.look_at - c.position, up = c.up;
  if (!make_unit(view)) throw Error("camera.look_at", to_text(c.look_at), "a point different from camera.position");
  if (!make_unit(up)) throw Error("camera.up", to_text(c.up), "a non-zero vector of finite numbers");
  if (glm::length(glm::cross(view, up)) < 1e-6)
    throw Error("camera.up", to_text(c.up), "a vector not parallel to the view direction (look_at - position)");
  if (c.type == Camera::Type::pinhole && !(c.fov_y_deg > 0.0 && c.fov_y_deg < 180.0))
    throw Error("camera.fov_y_deg", to_text(c.fov_y_deg), "an angle in degrees in (0, 180)");
  else number(c.height, "camera.height", 1e-9, 2.0 * kMaxCoordinate, "a height in [1e-9, 2e9]");
}

// A point or spot light at `position` seen from the eye: its in-scattered radiance grows as 1 / d
// (from 1e5 I sigma_s at d = 1e-5 to NaN at 1e-100), so it keeps a distance from the eye.
void apart_from_eye(const Vec3& position, const Vec3& eye, const std::string& field) {
  const double scale = 1.0 + max_abs(eye);
  if (glm::length(position - eye) < 1e-9 * scale)
    throw Error(field, to_text(position), "a point at least 1e-9 (1 + |camera.position|) from the camera (the radiance at a point light is infinite)");
}

void check_light(const Light& light, const Vec3& eye, const std::string& at) {
  const char* far = " (a farther light is a directional light)";
  if (const auto* p = std::get_if<PointLight>(&light)) {
    point(p->position, at + ".position", far);
    apart_from_eye(p->position, eye, at + ".position");
    radiometric(p->intensity, at + ".intensity");
  } else if (const auto* s = std::get_if<SpotLight>(&light)) {
    point(s->position, at + ".position", far);
    apart_from_eye(s->position, eye, at + ".position");
    direction(s->direction, at + ".direction");
    radiometric(s->intensity, at + ".intensity");
    number(s->exponent, at + ".exponent", 0.0, 1e5, "an exponent in [0, 1e5]");
    if (!(s->cone_deg > 0.0 && s->cone_deg <= 90.0)) throw Error(at + ".cone_deg", to_text(s->cone_deg), "a half-angle in degrees in (0, 90]");
  } else if (const auto* d = std::get_if<DirectionalLight>(&light)) {
    direction(d->direction, at + ".direction");
    radiometric(d->irradiance, at + ".irradiance");
  } else {
    radiometric(std::get<SkyLight>(light).radiance, at + ".radiance");
  }
}

void check_surface(const Surface& s, const std::string& at) {
  if (const auto* plane = std::get_if<Plane>(&s.shape)) {
    point(plane->point, at + ".point");
    direction(plane->normal, at + ".normal");
  } else if (const auto* sphere = std::get_if<Sphere>(&s.shape)) {
    point(sphere->center, at + ".center");
    number(sphere->radius, at + ".radius", 1e-9, kMaxCoordinate, "a radius in [1e-9, 1e9]");
  } else if (!std::get<Mesh>(s.shape).triangles) {
    throw Error(at, "a mesh without triangles", "a TriangleMesh (TriangleMesh::load_obj or from_buffers)");
  }
  radiometric(s.kd, at + ".kd");
  radiometric(s.ks, at + ".ks");
  number(s.shininess, at + ".shininess", 0.0, kMaxShininess, "a Phong exponent in [0, 1e5]");
}

}  // namespace

void check_scene(const Scene& scene) {
  check_camera(scene.camera);
  const Camera& c = scene.camera;
  const Vec3 eye = c.type == Camera::Type::matrices ? Vec3(c.view_inverse[3]) : c.type == Camera::Type::rays ? Vec3(kInfinity) : c.position;
  for (size_t i = 0; i < scene.lights.size(); ++i) check_light(scene.lights[i], eye, "lights[" + std::to_string(i) + "]");
  for (size_t i = 0; i < scene.surfaces.size(); ++i) check_surface(scene.surfaces[i], "surfaces[" + std::to_string(i) + "]");
  radiometric(scene.background, "background");
  if (scene.medium) check_medium(*scene.medium);
}

}  // namespace haze
