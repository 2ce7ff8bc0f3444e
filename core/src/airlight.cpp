#include <haze/core/airlight.h>
#include <haze/core/error.h>
#include <haze/core/integrate.h>

#include <algorithm>

namespace haze {

namespace {

constexpr double kHalfPi = 0.5 * kPi;

// Reduced geometry of a segment (thesis table 4.1).
struct Reduced {
  double d_sv, t, h, theta0, theta_d, d_sp;
  bool infinite;
};

Reduced reduce(const AirlightSegment& s) {
  Reduced r;
  double d_sv = std::max(s.d_sv, 1e-12);
  r.t = d_sv * std::cos(s.gamma);
  r.h = std::max(d_sv * std::sin(s.gamma), 1e-9 * d_sv);
  r.d_sv = std::hypot(r.t, r.h);
  r.infinite = !std::isfinite(s.d_vp);
  r.theta0 = std::atan2(-r.t, r.h);  // gamma - pi/2
  r.theta_d = r.infinite ? kHalfPi : std::atan2(s.d_vp - r.t, r.h);
  r.d_sp = r.infinite ? kInfinity : std::hypot(r.h, s.d_vp - r.t);
  return r;
}

void check(const AirlightMedium& m, const AirlightSegment& s) {
  if (!(m.sigma_t >= 0.0 && std::isfinite(m.sigma_t))) throw Error("sigma_t", to_text(m.sigma_t), "a finite number >= 0");
  if (!(m.sigma_s >= 0.0 && std::isfinite(m.sigma_s))) throw Error("sigma_s", to_text(m.sigma_s), "a finite number >= 0");
  if (!(s.gamma >= 0.0 && s.gamma <= kPi)) throw Error("gamma", to_text(s.gamma), "an angle in [0, pi]");
  if (!(s.d_vp > 0.0)) throw Error("d_vp", to_text(s.d_vp), "a segment length > 0");
  if (!(s.d_sv >= 0.0 && std::isfinite(s.d_sv))) throw Error("d_sv", to_text(s.d_sv), "a finite distance >= 0");
}

// The angle-formulated integrand, scaled by e^(sigma_t d_sv) so it stays in range:
// e^(-sigma_t (x + r - d_sv)) p(-sin theta).
struct Integrand {
  const PhaseFunction& phase;
  double sigma_t;
  Reduced r;
  double operator()(double theta) const {
    double c = std::cos(theta), s = std::sin(theta);
    double excess = r.t + r.h * (s + 1.0) / c - r.d_sv;  // x + r - d_sv >= 0
    return std::exp(-sigma_t * std::max(0.0, excess)) * phase.eval(-s);
  }
};

}  // namespace

AirlightSegment AirlightSegment::from_points(const Vec3& viewer, const Vec3& direction, const Vec3& light, double length) {
  Vec3 to_light = light - viewer;
  double d = glm::length(to_light);
  double cos_gamma = d > 0.0 ? std::clamp(glm::dot(to_light / d, direction), -1.0, 1.0) : 1.0;
  return {d, std::acos(cos_gamma), length};
}

double airlight_quadrature(const PhaseFunction& phase, const AirlightMedium& medium, const AirlightSegment& segment,
                           double rel_tol) {
  check(medium, segment);
  if (!(segment.d_sv > 0.0 && std::sin(segment.gamma) > 0.0))
    throw Error("segment", "through the light", "a view segment that misses the light (h > 0), for quadrature");
  Reduced r = reduce(segment);
  auto result = integrate_adaptive(Integrand{phase, medium.sigma_t, r}, r.theta0, r.theta_d, rel_tol, 0.0, 1 << 16);
  return medium.sigma_s * medium.intensity * std::exp(-medium.sigma_t * r.d_sv) / r.h * result.value;
}

double airlight_no_extinction(const AirlightMedium& medium, const AirlightSegment& segment) {
  check(medium, segment);
  Reduced r = reduce(segment);
  // atan((d_vp - t)/h) - atan(-t/h) = theta_d - theta0.
  return medium.sigma_s * medium.intensity * kInv4Pi / r.h * (r.theta_d - r.theta0);
}

}  // namespace haze
