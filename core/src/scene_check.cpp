// check_scene and check_medium: every range a scene's values must lie in, checked here alone and
// worded once, for scenes from files (Scene::from_json reads the types, then calls check_scene)
// and from the API alike.
#include <haze/core/error.h>
#include <haze/core/limits.h>
#include <haze/core/medium.h>
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

void number(double x, const std::string& field, double lo, double hi, const std::string& expected) {
  if (!(x >= lo && x <= hi)) throw Error(field, to_text(x), expected);
}

// Each channel in [lo, hi]; the error names the channel (field[1]) unless all three are the same
// (a file's single number).
void channels(const Rgb& c, const std::string& field, double lo, double hi, const std::string& expected) {
  for (int i = 0; i < 3; ++i)
    if (!(c[i] >= lo && c[i] <= hi)) number(c[i], c.r == c.g && c.g == c.b ? field : field + "[" + std::to_string(i) + "]", lo, hi, expected);
}

double largest(const Rgb& c) { return std::max({c.r, c.g, c.b}); }

void radiometric(const Rgb& c, const std::string& field) { channels(c, field, 0.0, kMaxRadiometric, "values in [0, 1e15] (haze::kMaxRadiometric)"); }

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
  // kd and ks are reflectances (albedos): above 1 a surface would create energy.
  channels(s.kd, at + ".kd", 0.0, 1.0, "values in [0, 1]");
  channels(s.ks, at + ".ks", 0.0, 1.0, "values in [0, 1]");
  number(s.shininess, at + ".shininess", 0.0, kMaxShininess, "a Phong exponent in [0, 1e5]");
}

}  // namespace


void check_medium(const MediumDesc& desc, const std::string& path) {
  const Aabb& b = desc.bounds;
  const bool unbounded = b.lo == Vec3(-kInfinity) && b.hi == Vec3(kInfinity);
  if (!unbounded && !(within_reach(b.lo) && within_reach(b.hi) && b.lo.x < b.hi.x && b.lo.y < b.hi.y && b.lo.z < b.hi.z))
    throw Error(path + ".bounds", to_text(b.lo) + " to " + to_text(b.hi),
                "a box with lo < hi on every axis within 1e9 of the origin (haze::kMaxCoordinate), or unbounded");
  channels(desc.sigma_t, path + ".sigma_t", 0.0, kMaxExtinction, "values in [0, 1e9] (haze::kMaxExtinction)");
  channels(desc.albedo, path + ".albedo", 0.0, 1.0, "values in [0, 1]");
  const Emission& e = desc.emission;
  number(e.strength, path + ".emission.strength", 0.0, kMaxRadiometric, "a strength in [0, 1e15] (haze::kMaxRadiometric)");
  radiometric(e.color, path + ".emission.color");
  if (largest(e.color) * e.strength > kMaxRadiometric)
    throw Error(path + ".emission.color", to_text(e.color), "values whose product with the strength is at most 1e15 (haze::kMaxRadiometric)");
  number(e.blackbody_intensity, path + ".blackbody.intensity", 0.0, kMaxRadiometric, "an intensity in [0, 1e15] (haze::kMaxRadiometric)");
  radiometric(e.blackbody_tint, path + ".blackbody.tint");
  if (largest(e.blackbody_tint) * e.blackbody_intensity > kMaxRadiometric)
    throw Error(path + ".blackbody.tint", to_text(e.blackbody_tint), "values whose product with the intensity is at most 1e15 (haze::kMaxRadiometric)");
  number(e.temperature, path + ".blackbody.temperature", 0.0, 1e6, "kelvin in [0, 1e6]");
  if (e.emits() && unbounded && !(desc.sigma_t.r > 0.0 && desc.sigma_t.g > 0.0 && desc.sigma_t.b > 0.0) &&
      !std::holds_alternative<RbfDensity>(desc.density) && !std::holds_alternative<FieldDensity>(desc.density))
    throw Error(path + ".sigma_t", to_text(desc.sigma_t), "> 0 in every channel for an unbounded medium that emits (else its radiance is infinite)");
  // Extinction sigma_t rho past kMaxExtinction, blamed on the density value that reaches it.
  const double sigma_max = largest(desc.sigma_t);
  auto extinction = [&](double density, const std::string& field) {
    if (sigma_max * density > kMaxExtinction)
      throw Error(field, to_text(density), "a density whose product with sigma_t (" + to_text(sigma_max) +
                                               ") is at most 1e9 (haze::kMaxExtinction: extinction per unit length)");
  };
  if (const auto* c = std::get_if<ConstantDensity>(&desc.density)) {
    if (!(std::isfinite(c->value) && c->value >= 0.0)) throw Error(path + ".density.value", to_text(c->value), "a finite density >= 0");
    extinction(c->value, path + ".density.value");
  } else if (const auto* rbf = std::get_if<RbfDensity>(&desc.density)) {
    if (rbf->blobs.empty()) throw Error(path + ".density.blobs", "[]", "at least one blob");
    for (size_t i = 0; i < rbf->blobs.size(); ++i) {
      const RbfBlob& blob = rbf->blobs[i];
      const std::string at = path + ".density.blobs[" + std::to_string(i) + "]";
      if (!within_reach(blob.center)) throw Error(at + ".center", to_text(blob.center), "a point within 1e9 of the origin (haze::kMaxCoordinate)");
      if (!(std::isfinite(blob.weight) && blob.weight >= 0.0)) throw Error(at + ".weight", to_text(blob.weight), "a finite weight >= 0");
      extinction(blob.weight, at + ".weight");
      if (!(std::isfinite(blob.sharpness) && blob.sharpness > 0.0)) throw Error(at + ".sharpness", to_text(blob.sharpness), "a finite sharpness > 0");
      // Unbounded, the medium reaches 6 / sharpness past each centre (medium_bounds): a blob of
      // sharpness 1e-300 made quadrature's steps 1e298 long and its image NaN.
      if (unbounded && 6.0 / blob.sharpness > kMaxCoordinate)
        throw Error(at + ".sharpness", to_text(blob.sharpness), "a sharpness >= 6e-9 (the blob reaching 6 / sharpness, at most 1e9), or medium.bounds");
    }
  } else if (const auto* f = std::get_if<FieldDensity>(&desc.density)) {
    if (!f->field) throw Error(path + ".density", "a " + f->type + " field without data", "a density field");
    const Aabb fb = f->field->bounds();
    if (!(within_reach(fb.lo) && within_reach(fb.hi)))
      throw Error(path + ".density", "a " + f->type + " field from " + to_text(fb.lo) + " to " + to_text(fb.hi),
                  "a field within 1e9 of the origin (haze::kMaxCoordinate)");
    extinction(f->field->max_density(fb), path + ".density");
  } else {
    const auto& grid = std::get<GridDensity>(desc.density);
    if (unbounded) throw Error(path + ".bounds", "unbounded", "bounds for a grid density");
    size_t cells = 1;
    for (int a = 0; a < 3; ++a) {
      if (grid.resolution[a] < 1)
        throw Error(path + ".density.resolution[" + std::to_string(a) + "]", to_text(grid.resolution[a]), "at least 1 cell");
      cells *= static_cast<size_t>(grid.resolution[a]);
    }
    const std::span<const float> samples = grid.samples();
    const std::string field = path + ".density." + (grid.view.data() ? "view" : "values");
    if (samples.size() != cells)
      throw Error(field, to_text(samples.size()) + " values",
                  to_text(cells) + " (resolution " + to_text(grid.resolution[0]) + " x " + to_text(grid.resolution[1]) + " x " +
                      to_text(grid.resolution[2]) + ")");
    const auto nx = static_cast<size_t>(grid.resolution[0]), ny = static_cast<size_t>(grid.resolution[1]);
    for (size_t i = 0; i < samples.size(); ++i)
      if (!(std::isfinite(samples[i]) && samples[i] >= 0.0f))
        throw Error(field + "[" + std::to_string(i) + "]",
                    to_text(samples[i]) + " at cell (" + to_text(i % nx) + ", " + to_text(i / nx % ny) + ", " + to_text(i / (nx * ny)) + ")",
                    "a finite density >= 0");
      else if (sigma_max * static_cast<double>(samples[i]) > kMaxExtinction)
        extinction(static_cast<double>(samples[i]), field + "[" + std::to_string(i) + "]");
  }
}

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
