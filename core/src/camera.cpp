#include <haze/core/camera.h>

namespace haze {

Ray Camera::generate_ray(double px, double py) const {
  Vec3 forward = glm::normalize(look_at - position);
  Vec3 right = glm::normalize(glm::cross(forward, up));
  Vec3 true_up = glm::cross(right, forward);
  // Film coordinates in [-1, 1] vertically, aspect-scaled horizontally; row 0 at the top.
  double aspect = static_cast<double>(width_px) / height_px;
  double sx = (2.0 * px / width_px - 1.0) * aspect;
  double sy = 1.0 - 2.0 * py / height_px;
  if (type == Type::orthographic) {
    double half = 0.5 * height;
    return {position + right * (sx * half) + true_up * (sy * half), forward};
  }
  double tan_half = std::tan(0.5 * fov_y_deg * kPi / 180.0);
  return {position, glm::normalize(forward + right * (sx * tan_half) + true_up * (sy * tan_half))};
}

}  // namespace haze
