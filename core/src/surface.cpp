#include <haze/core/surface.h>

namespace haze {

bool Surface::intersect(const Ray& ray, double t_min, double t_max, double& t, Vec3& normal) const {
  if (auto* plane = std::get_if<Plane>(&shape)) {
    double denom = glm::dot(plane->normal, ray.direction);
    if (std::abs(denom) < 1e-12) return false;
    double th = glm::dot(plane->point - ray.origin, plane->normal) / denom;
    if (!(th > t_min && th < t_max)) return false;
    t = th;
    normal = denom < 0.0 ? plane->normal : -plane->normal;
    return true;
  }
  const auto& sphere = std::get<Sphere>(shape);
  Vec3 oc = ray.origin - sphere.center;
  double b = glm::dot(oc, ray.direction);
  double c = glm::dot(oc, oc) - sphere.radius * sphere.radius;
  double disc = b * b - c;
  if (disc < 0.0) return false;
  double root = std::sqrt(disc);
  double th = -b - root;
  if (!(th > t_min)) th = -b + root;
  if (!(th > t_min && th < t_max)) return false;
  t = th;
  normal = (ray.at(t) - sphere.center) / sphere.radius;
  if (glm::dot(normal, ray.direction) > 0.0) normal = -normal;
  return true;
}

Rgb Surface::brdf(const Vec3& wi, const Vec3& wo, const Vec3& n) const {
  Rgb f = kd / kPi;
  if (ks != Rgb(0.0)) {
    Vec3 mirrored = 2.0 * glm::dot(wi, n) * n - wi;
    double cos_alpha = std::max(0.0, glm::dot(mirrored, wo));
    f += ks * ((shininess + 2.0) / (2.0 * kPi) * std::pow(cos_alpha, shininess));
  }
  return f;
}

const Surface* nearest_surface(const std::vector<Surface>& surfaces, const Ray& ray, double t_max, double& t, Vec3& normal) {
  const Surface* hit = nullptr;
  t = t_max;
  for (const auto& s : surfaces) {
    double ts;
    Vec3 n;
    if (s.intersect(ray, 1e-7, t, ts, n)) t = ts, normal = n, hit = &s;
  }
  return hit;
}

bool occluded(const std::vector<Surface>& surfaces, const Vec3& x, const Vec3& dir, double distance) {
  double t;
  Vec3 n;
  return !surfaces.empty() && nearest_surface(surfaces, {x, dir}, distance * (1.0 - 1e-9), t, n) != nullptr;
}

}  // namespace haze
