#include <haze/core/camera.h>
#include <haze/core/error.h>

#include <glm/matrix.hpp>

#include <algorithm>
#include <array>
#include <cmath>

namespace haze {

namespace {

void check_size(int width_px, int height_px) {
  if (width_px < 1 || height_px < 1)
    throw Error("camera.width_px", to_text(width_px) + " x " + to_text(height_px), "an image size of at least 1 x 1");
}

}  // namespace

Camera Camera::from_matrices(const glm::dmat4& view, const glm::dmat4& projection, int width_px, int height_px) {
  check_size(width_px, height_px);
  auto finite = [](const glm::dmat4& m) {
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!std::isfinite(m[c][r])) return false;
    return true;
  };
  if (!finite(view) || std::abs(glm::determinant(view)) < 1e-300)
    throw Error("camera.view", "a matrix that cannot be inverted", "an invertible world-to-eye matrix");
  if (!finite(projection) || std::abs(glm::determinant(projection)) < 1e-300)
    throw Error("camera.projection", "a matrix that cannot be inverted", "an invertible eye-to-clip matrix (glm::perspective, glm::ortho)");
  Camera c;
  c.type = Type::matrices;
  c.width_px = width_px, c.height_px = height_px;
  c.view = view, c.projection = projection;
  c.view_inverse = glm::inverse(view), c.projection_inverse = glm::inverse(projection);
  c.position = Vec3(c.view_inverse[3]);
  return c;
}

Camera Camera::from_rays(std::shared_ptr<const std::vector<Ray>> rays, int width_px, int height_px) {
  check_size(width_px, height_px);
  const size_t count = static_cast<size_t>(width_px) * static_cast<size_t>(height_px);
  if (!rays || rays->size() != count)
    throw Error("camera.rays", to_text(rays ? rays->size() : 0) + " rays", to_text(count) + " (width_px x height_px), one per pixel");
  for (size_t i = 0; i < count; ++i) {
    const Ray& r = (*rays)[i];
    const double length = glm::length(r.direction);
    if (!std::isfinite(r.origin.x + r.origin.y + r.origin.z) || !(std::abs(length - 1.0) <= 1e-6))
      throw Error("camera.rays[" + to_text(i) + "]", "direction of length " + to_text(length) + ", origin (" + to_text(r.origin.x) + ", " +
                      to_text(r.origin.y) + ", " + to_text(r.origin.z) + ")",
                  "a finite origin and a unit direction");
  }
  Camera c;
  c.type = Type::rays;
  c.width_px = width_px, c.height_px = height_px;
  c.rays = std::move(rays);
  return c;
}

Ray Camera::generate_ray(double px, double py) const {
  if (type == Type::rays) {
    const int x = std::clamp(static_cast<int>(px), 0, width_px - 1), y = std::clamp(static_cast<int>(py), 0, height_px - 1);
    return (*rays)[static_cast<size_t>(y) * static_cast<size_t>(width_px) + static_cast<size_t>(x)];
  }
  if (type == Type::matrices) {
    // The pixel's point on the near plane in eye space; a perspective projection (w depends on z)
    // sends rays from the eye through it, an orthographic one along -z from the eye plane.
    const double nx = 2.0 * px / width_px - 1.0, ny = 1.0 - 2.0 * py / height_px;
    const glm::dvec4 near = projection_inverse * glm::dvec4(nx, ny, -1.0, 1.0);
    const Vec3 p = Vec3(near) / near.w;
    const bool perspective = projection[2][3] != 0.0;
    const Vec3 origin = perspective ? Vec3(0.0) : Vec3(p.x, p.y, 0.0), direction = perspective ? p : Vec3(0.0, 0.0, -1.0);
    return {Vec3(view_inverse * glm::dvec4(origin, 1.0)), glm::normalize(Vec3(view_inverse * glm::dvec4(direction, 0.0)))};
  }
  Ray ray;
  row_rays_at(py, &px, 1, &ray);
  return ray;
}

bool Camera::film_position(const Vec3& point, double& px, double& py) const {
  if (type == Type::matrices) {
    if (projection[2][3] == 0.0) return false;  // orthographic
    const glm::dvec4 clip = projection * (view * glm::dvec4(point, 1.0));
    if (!(clip.w > 0.0)) return false;
    px = 0.5 * (clip.x / clip.w + 1.0) * width_px, py = 0.5 * (1.0 - clip.y / clip.w) * height_px;
    return true;
  }
  if (type != Type::pinhole) return false;
  // row_rays_at's frame, inverted.
  Vec3 forward, right, true_up;
  frame(forward, right, true_up);
  const Vec3 d = point - position;
  const double z = glm::dot(d, forward);
  if (!(z > 0.0)) return false;
  const double tan_half = std::tan(0.5 * fov_y_deg * kPi / 180.0), aspect = static_cast<double>(width_px) / height_px;
  px = 0.5 * (glm::dot(d, right) / (z * aspect * tan_half) + 1.0) * width_px;
  py = 0.5 * (1.0 - glm::dot(d, true_up) / (z * tan_half)) * height_px;
  return true;
}

void Camera::row_rays_at(double py, const double* px, int count, Ray* out) const {
  if (type == Type::rays || type == Type::matrices) {
    for (int i = 0; i < count; ++i) out[i] = generate_ray(px[i], py);
    return;
  }
  Vec3 forward, right, true_up;
  frame(forward, right, true_up);
  // Film coordinates in [-1, 1] vertically, aspect-scaled horizontally; row 0 at the top.
  const double aspect = static_cast<double>(width_px) / height_px;
  const double sy = 1.0 - 2.0 * py / height_px;
  if (type == Type::orthographic) {
    const double half = 0.5 * height;
    for (int i = 0; i < count; ++i) out[i] = {position + right * ((2.0 * px[i] / width_px - 1.0) * aspect * half) + true_up * (sy * half), forward};
    return;
  }
  const double tan_half = std::tan(0.5 * fov_y_deg * kPi / 180.0);
  const Vec3 centre = forward + true_up * (sy * tan_half);
  for (int i = 0; i < count; ++i) out[i] = {position, glm::normalize(centre + right * ((2.0 * px[i] / width_px - 1.0) * aspect * tan_half))};
}

void Camera::frame(Vec3& forward, Vec3& right, Vec3& true_up) const {
  forward = look_at - position;
  make_unit(forward);  // check_scene refuses a camera whose view or up gives no frame
  right = glm::cross(forward, up);
  make_unit(right);
  true_up = glm::cross(right, forward);
}

bool Camera::row_frame(double py, Vec3& a, Vec3& b) const {
  if (type == Type::matrices) {
    // generate_ray's near point P^-1 (nx, ny, -1, 1), linear in nx = 2 px / W - 1; its w must not
    // depend on nx (a perspective projection's does not), so that dividing by it keeps it linear.
    if (projection[2][3] == 0.0 || projection_inverse[0][3] != 0.0) return false;
    const double ny = 1.0 - 2.0 * py / height_px;
    const glm::dvec4 near = projection_inverse * glm::dvec4(-1.0, ny, -1.0, 1.0), per_px = projection_inverse[0] * (2.0 / width_px);
    a = Vec3(view_inverse * glm::dvec4(Vec3(near) / near.w, 0.0)), b = Vec3(view_inverse * glm::dvec4(Vec3(per_px) / near.w, 0.0));
    return true;
  }
  if (type != Type::pinhole) return false;
  // row_rays_at's: centre + right ((2 px / W - 1) aspect tan_half).
  Vec3 forward, right, true_up;
  frame(forward, right, true_up);
  const double tan_half = std::tan(0.5 * fov_y_deg * kPi / 180.0), aspect = static_cast<double>(width_px) / height_px;
  const Vec3 right_px = right * (aspect * tan_half);
  a = forward + true_up * ((1.0 - 2.0 * py / height_px) * tan_half) - right_px, b = right_px * (2.0 / width_px);
  return true;
}

bool Camera::eye(Vec3& at) const {
  if (type == Type::pinhole) return at = position, true;
  // A perspective projection (row_frame's condition): its rays leave the eye, the view's origin.
  if (type == Type::matrices && projection[2][3] != 0.0 && projection_inverse[0][3] == 0.0) return at = Vec3(view_inverse[3]), true;
  return false;
}

double Camera::pixel_angle() const {
  const double x = 0.5 * width_px, y = 0.5 * height_px;
  return std::acos(std::clamp(glm::dot(generate_ray(x, y).direction, generate_ray(x + 1.0, y).direction), -1.0, 1.0));
}

void Camera::row_rays(int y, int x0, int x1, Ray* out) const {
  std::array<double, 256> px;  // pixel centres a run at a time: a frame's rows allocate nothing
  for (int from = x0; from < x1; from += static_cast<int>(px.size())) {
    const int count = std::min(static_cast<int>(px.size()), x1 - from);
    for (int i = 0; i < count; ++i) px[static_cast<size_t>(i)] = from + i + 0.5;
    row_rays_at(y + 0.5, px.data(), count, out + (from - x0));
  }
}

}  // namespace haze
