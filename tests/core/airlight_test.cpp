// The angle-formulated airlight (seed 002 sec. 4.2.1): the quadrature yardstick against closed
// forms and the adaptive integrator against known integrals.
#include <haze/core/airlight.h>
#include <haze/core/error.h>
#include <haze/core/integrate.h>

#include <gtest/gtest.h>


namespace haze {
namespace {

// BEYOND.md: Sun et al. 2005, sigma_t 0.5, albedo 1, I 1, d_sv 2, gamma 0.7, d_vp 5 -> 0.0132328536.
TEST(Airlight, QuadratureMatchesSunEtAl) {
  EXPECT_NEAR(airlight_quadrature(PhaseFunction::isotropic(), {0.5, 0.5, 1.0}, {2.0, 0.7, 5.0}), 0.0132328536, 1e-10);
}

// Seed 004: without extinction the isotropic airlight is an arctangent difference.
TEST(Airlight, QuadratureMatchesNoExtinctionClosedForm) {
  for (double gamma : {0.01, 0.7, 1.6, 3.0})
    for (double d_vp : {0.1, 2.0, 50.0, kInfinity}) {
      AirlightSegment s{1.5, gamma, d_vp};
      AirlightMedium m{0.0, 0.3, 2.0};
      double exact = airlight_no_extinction(m, s);
      EXPECT_NEAR(airlight_quadrature(PhaseFunction::isotropic(), m, s) / exact, 1.0, 1e-9) << gamma << " " << d_vp;
    }
}

// The yardstick agrees with the ray-marching quadrature of the physical (distance) integral for an
// anisotropic phase function, the light behind the viewer, and a thick medium.
TEST(Airlight, AngleFormMatchesDistanceForm) {
  const PhaseFunction phase = PhaseFunction::henyey_greenstein(0.8);
  for (double gamma : {0.05, 1.0, 2.5, 3.1})
    for (double sigma_t : {1e-4, 0.3, 5.0}) {
      AirlightMedium m{sigma_t, 0.6 * sigma_t, 3.0};
      AirlightSegment s{1.2, gamma, 4.0};
      double t = s.d_sv * std::cos(gamma), h = s.d_sv * std::sin(gamma);
      auto f = [&](double x) {
        double r = std::hypot(h, x - t);
        return m.sigma_s * m.intensity * std::exp(-sigma_t * (x + r)) / (r * r) * phase.eval((t - x) / r);
      };
      double distance_form = integrate_adaptive(f, 0.0, std::max(0.0, t), 1e-12).value +
                             integrate_adaptive(f, std::max(0.0, t), s.d_vp, 1e-12).value;
      EXPECT_NEAR(airlight_quadrature(phase, m, s) / distance_form, 1.0, 1e-8) << gamma << " " << sigma_t;
    }
}

TEST(Integrate, AdaptiveGaussKronrodResolvesPeaksAndEndpoints) {
  // A narrow Lorentzian: integral = atan(1/eps) - atan(-1/eps) over [-1, 1].
  const double eps = 1e-6;
  auto r = integrate_adaptive([&](double x) { return eps / (x * x + eps * eps); }, -1.0, 1.0, 1e-12);
  EXPECT_NEAR(r.value, 2.0 * std::atan(1.0 / eps), 1e-10);
  // An integrable endpoint singularity: integral_0^1 x^-0.5 = 2.
  EXPECT_NEAR(integrate_adaptive([](double x) { return 1.0 / std::sqrt(x); }, 0.0, 1.0, 1e-10, 0.0, 1 << 16).value, 2.0, 1e-6);
  EXPECT_THROW(integrate_adaptive([](double) { return 1.0; }, 0.0, kInfinity), Error);
}

}  // namespace
}  // namespace haze
