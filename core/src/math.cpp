#include <haze/core/math.h>

namespace haze {

bool Aabb::clip(const Ray& ray, double& t0, double& t1) const {
  for (int a = 0; a < 3; ++a) {
    double inv = 1.0 / ray.direction[a];
    double near = (lo[a] - ray.origin[a]) * inv;
    double far = (hi[a] - ray.origin[a]) * inv;
    if (near > far) std::swap(near, far);
    // NaN (0 * inf on a face) compares false and leaves the interval alone.
    if (near > t0) t0 = near;
    if (far < t1) t1 = far;
    if (t0 > t1) return false;
  }
  return true;
}

Frame Frame::from_z(const Vec3& n) {
  double sign = std::copysign(1.0, n.z);
  double a = -1.0 / (sign + n.z);
  double b = n.x * n.y * a;
  return {Vec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3(b, sign + n.y * n.y * a, -n.y), n};
}

Vec3 direction_around(const Vec3& axis, double cos_theta, double phi) {
  double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
  return Frame::from_z(axis).to_world(Vec3(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta));
}

}  // namespace haze
