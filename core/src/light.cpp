#include <haze/core/light.h>

namespace haze {

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

}  // namespace haze
