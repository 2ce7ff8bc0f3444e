#include <haze/core/light.h>

#include <algorithm>
#include <type_traits>

namespace haze {

bool is_grey(const Light& light) {
  return std::visit([](const auto& l) {
    using T = std::decay_t<decltype(l)>;
    if constexpr (std::is_same_v<T, DirectionalLight>) return is_grey(l.irradiance);
    else if constexpr (std::is_same_v<T, SkyLight>) return is_grey(l.radiance);
    else return is_grey(l.intensity);
  }, light);
}

bool arrival(const Light& light, const Vec3& x, LightArrival& out) {
  if (auto* p = std::get_if<PointLight>(&light)) {
    Vec3 d = p->position - x;
    double d2 = glm::dot(d, d);
    out.distance = std::sqrt(d2);
    out.to_light = d / out.distance;
    out.irradiance = p->intensity / d2;
    return true;
  }
  if (auto* s = std::get_if<SpotLight>(&light)) {
    Vec3 d = s->position - x;
    double d2 = glm::dot(d, d);
    out.distance = std::sqrt(d2);
    out.to_light = d / out.distance;
    double cos_theta = -glm::dot(out.to_light, s->direction);
    bool inside = cos_theta >= std::cos(s->cone_deg * kPi / 180.0) && cos_theta > 0.0;
    out.irradiance = inside ? s->intensity * std::pow(cos_theta, s->exponent) / d2 : Rgb(0.0);
    return true;
  }
  if (auto* l = std::get_if<DirectionalLight>(&light)) {
    out.to_light = -l->direction;
    out.distance = kInfinity;
    out.irradiance = l->irradiance;
    return true;
  }
  return false;
}

int equiangular_nodes(const Ray& ray, const Vec3& centre, double t0, double t1, double max_angle, std::span<double> t,
                      std::span<double> weight) {
  if (!(t1 > t0) || t.empty()) return 0;
  const double t_c = glm::dot(centre - ray.origin, ray.direction);
  // A ray through the light: b from the stretch's scale keeps the weights finite.
  const double b = std::max(glm::length(centre - ray.at(t_c)), 1e-9 * (std::abs(t0) + std::abs(t1) + 1.0));
  const double theta0 = std::atan((t0 - t_c) / b), theta1 = std::atan((t1 - t_c) / b);
  const auto most = static_cast<int>(std::min(t.size(), weight.size()));
  const int count = std::clamp(static_cast<int>(std::ceil((theta1 - theta0) / max_angle)), 1, most);
  const double d_theta = (theta1 - theta0) / count;
  for (int n = 0; n < count; ++n) {
    const double theta = theta0 + (n + 0.5) * d_theta, c = std::cos(theta);
    t[static_cast<size_t>(n)] = t_c + b * std::tan(theta);
    weight[static_cast<size_t>(n)] = b / (c * c) * d_theta;  // d^2 / b dtheta, d = b / cos(theta)
  }
  return count;
}

std::vector<double> cone_crossings(const SpotLight& spot, const Ray& ray, double t_max) {
  // Inside: (m + t d) . a >= cos(c) |m + t d|, m = origin - apex; squared, a quadratic in t.
  const double cos_c = std::cos(spot.cone_deg * kPi / 180.0), c2 = cos_c * cos_c;
  const Vec3 m = ray.origin - spot.position;
  const double da = glm::dot(ray.direction, spot.direction), ma = glm::dot(m, spot.direction);
  const double A = da * da - c2, B = 2.0 * (da * ma - c2 * glm::dot(m, ray.direction)), C = ma * ma - c2 * glm::dot(m, m);
  std::vector<double> roots;
  if (std::abs(A) > 1e-14) {
    double disc = B * B - 4.0 * A * C;
    if (disc > 0.0) {
      double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
      roots.push_back(q / A);
      if (q != 0.0) roots.push_back(C / q);
    }
  } else if (B != 0.0) {
    roots.push_back(-C / B);
  }
  if (da != 0.0) roots.push_back(-ma / da);  // the plane through the apex
  std::vector<double> out;
  for (double t : roots)
    if (t > 0.0 && t < t_max) out.push_back(t);
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace haze
