// Phase functions: normalization, importance sampling (chi-square), Legendre moments.
#include <haze/core/error.h>
#include <haze/core/phase.h>

#include <gtest/gtest.h>

#include <functional>

namespace haze {
namespace {

struct Case {
  std::string label;
  std::function<PhaseFunction()> make;
};

std::vector<double> hg_table(double g, int n) {
  std::vector<double> v(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) v[static_cast<size_t>(i)] = hg_eval(g, -1.0 + 2.0 * i / (n - 1));
  return v;
}

std::vector<Case> all_cases() {
  return {
      {"isotropic", [] { return PhaseFunction::isotropic(); }},
      {"rayleigh", [] { return PhaseFunction::rayleigh(); }},
      {"hg_0", [] { return PhaseFunction::henyey_greenstein(0.0); }},
      {"hg_0_5", [] { return PhaseFunction::henyey_greenstein(0.5); }},
      {"hg_minus_0_7", [] { return PhaseFunction::henyey_greenstein(-0.7); }},
      {"hg_0_95", [] { return PhaseFunction::henyey_greenstein(0.95); }},
      {"cornette_shanks_0_8", [] { return PhaseFunction::cornette_shanks(0.8); }},
      {"cornette_shanks_minus_0_3", [] { return PhaseFunction::cornette_shanks(-0.3); }},
      {"double_hg", [] { return PhaseFunction::double_hg(0.8, -0.4, 0.7); }},
      {"tabulated_hg_0_6", [] { return PhaseFunction::tabulated(hg_table(0.6, 513)); }},
      {"tabulated_ramp", [] { return PhaseFunction::tabulated({0.0, 1.0, 3.0, 0.5}); }},
  };
}

class PhaseCase : public testing::TestWithParam<Case> {};

// integral over the sphere = 2 pi integral_{-1}^{1} p(mu) dmu = 1.
TEST_P(PhaseCase, IntegratesToOne) {
  PhaseFunction p = GetParam().make();
  std::vector<double> x, w;
  gauss_legendre(4096, x, w);
  double sum = 0.0;
  for (size_t i = 0; i < x.size(); ++i) sum += 2.0 * kPi * w[i] * p.eval(x[i]);
  EXPECT_NEAR(sum, 1.0, 2e-5);
  EXPECT_NEAR(p.legendre_moments(1)[0], 1.0, 2e-5);
}

// Pearson chi-square of sampled cos(theta) in 50 equal-width bins; expected counts from quadrature
// of the density. Threshold 99.6 is the 0.9999 quantile of chi-square with 49 degrees of freedom.
TEST_P(PhaseCase, SamplingMatchesDensity) {
  PhaseFunction p = GetParam().make();
  const int bins = 50, samples = 200000;
  std::vector<double> observed(bins, 0.0), expected(bins, 0.0);
  Rng rng(7, 3);
  Vec3 wi = glm::normalize(Vec3(0.3, -0.2, 0.9));
  for (int s = 0; s < samples; ++s) {
    auto sample = p.sample(wi, rng);
    double mu = glm::dot(wi, sample.wo);
    ASSERT_NEAR(glm::length(sample.wo), 1.0, 1e-12);
    ASSERT_NEAR(sample.pdf, p.eval(mu), 1e-9 * std::max(1.0, sample.pdf));
    observed[static_cast<size_t>(std::clamp(static_cast<int>((mu + 1.0) * 0.5 * bins), 0, bins - 1))] += 1.0;
  }
  std::vector<double> x, w;
  gauss_legendre(64, x, w);
  for (int b = 0; b < bins; ++b) {
    double lo = -1.0 + 2.0 * b / bins, hi = lo + 2.0 / bins;
    for (size_t i = 0; i < x.size(); ++i)
      expected[static_cast<size_t>(b)] += samples * 2.0 * kPi * 0.5 * (hi - lo) * w[i] * p.eval(0.5 * (lo + hi) + 0.5 * (hi - lo) * x[i]);
  }
  double chi2 = 0.0;
  int dof = -1;
  for (int b = 0; b < bins; ++b) {
    if (expected[static_cast<size_t>(b)] < 5.0) {
      EXPECT_LE(observed[static_cast<size_t>(b)], 20.0) << "bin " << b;
      continue;
    }
    double d = observed[static_cast<size_t>(b)] - expected[static_cast<size_t>(b)];
    chi2 += d * d / expected[static_cast<size_t>(b)];
    ++dof;
  }
  EXPECT_LT(chi2, dof + 6.0 * std::sqrt(2.0 * dof)) << "chi2 " << chi2 << " dof " << dof;
}

INSTANTIATE_TEST_SUITE_P(All, PhaseCase, testing::ValuesIn(all_cases()),
                         [](const auto& info) { return info.param.label; });

// p(mu) = sum (2k+1)/(4 pi) b_k P_k(mu): a converged series rebuilds the function (the analytic
// ones whose series converges within 160 terms).
TEST(Phase, LegendreSeriesRebuildsFunction) {
  for (const auto& p : {PhaseFunction::isotropic(), PhaseFunction::rayleigh(), PhaseFunction::henyey_greenstein(-0.7),
                        PhaseFunction::cornette_shanks(0.8), PhaseFunction::double_hg(0.8, -0.4, 0.7)}) {
    auto b = p.legendre_moments(160);
    for (double mu : {-1.0, -0.5, 0.0, 0.3, 0.9})
      EXPECT_NEAR(eval_legendre_series(b, mu), p.eval(mu), 1e-6 * std::max(1.0, p.eval(mu))) << p.name() << " mu " << mu;
  }
}

TEST(Phase, HenyeyGreensteinMomentsArePowersOfG) {
  for (double g : {-0.6, 0.25, 0.5, 0.9}) {
    auto b = PhaseFunction::henyey_greenstein(g).legendre_moments(12);
    // The numerical path (a tabulated HG) must agree with the closed form b_k = g^k.
    auto numeric = PhaseFunction::tabulated(hg_table(g, 20001)).legendre_moments(12);
    for (int k = 0; k < 12; ++k) {
      EXPECT_DOUBLE_EQ(b[static_cast<size_t>(k)], std::pow(g, k));
      EXPECT_NEAR(numeric[static_cast<size_t>(k)], std::pow(g, k), 2e-4) << "g " << g << " k " << k;
    }
  }
}

TEST(Phase, KnownMoments) {
  auto r = PhaseFunction::rayleigh().legendre_moments(5);
  EXPECT_NEAR(r[1], 0.0, 1e-12);
  EXPECT_NEAR(r[2], 0.1, 1e-12);  // 1 + mu^2 = 4/3 P_0 + 2/3 P_2
  EXPECT_NEAR(r[3], 0.0, 1e-12);
  EXPECT_NEAR(r[4], 0.0, 1e-12);
  // Cornette-Shanks mean cosine 3 g (4 + g^2) / (5 (2 + g^2)).
  for (double g : {-0.5, 0.3, 0.85})
    EXPECT_NEAR(PhaseFunction::cornette_shanks(g).mean_cosine(), 3 * g * (4 + g * g) / (5 * (2 + g * g)), 1e-9);
  EXPECT_NEAR(PhaseFunction::double_hg(0.8, -0.4, 0.7).mean_cosine(), 0.7 * 0.8 - 0.3 * 0.4, 1e-15);
}

// The closed form of the relative L2 truncation error against direct quadrature on the sphere.
TEST(Phase, HgLegendreTruncationError) {
  std::vector<double> x, w;
  gauss_legendre(4096, x, w);
  for (double g : {0.3, 0.5, 0.8}) {
    for (int terms : {1, 4, 12}) {
      auto b = PhaseFunction::henyey_greenstein(g).legendre_moments(terms);
      double err2 = 0.0, norm2 = 0.0;
      for (size_t i = 0; i < x.size(); ++i) {
        double p = hg_eval(g, x[i]);
        double d = p - eval_legendre_series(b, x[i]);
        err2 += w[i] * d * d, norm2 += w[i] * p * p;
      }
      EXPECT_NEAR(hg_legendre_truncation_error(g, terms), std::sqrt(err2 / norm2), 1e-6) << g << " " << terms;
    }
  }
  EXPECT_EQ(hg_legendre_truncation_error(0.5, 0), 1.0);
}

TEST(Phase, RejectsBadParameters) {
  EXPECT_THROW(PhaseFunction::henyey_greenstein(1.0), Error);
  EXPECT_THROW(PhaseFunction::henyey_greenstein(std::nan("")), Error);
  EXPECT_THROW(PhaseFunction::cornette_shanks(-1.5), Error);
  EXPECT_THROW(PhaseFunction::double_hg(0.5, 0.2, 1.5), Error);
  EXPECT_THROW(PhaseFunction::tabulated({1.0}), Error);
  EXPECT_THROW(PhaseFunction::tabulated({1.0, -0.1}), Error);
  EXPECT_THROW(PhaseFunction::tabulated({0.0, 0.0}), Error);
  try {
    PhaseFunction::henyey_greenstein(-1.0);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "g");
    EXPECT_EQ(e.value(), "-1");
  }
}

TEST(Phase, GaussLegendreIntegratesPolynomialsExactly) {
  std::vector<double> x, w;
  for (int n : {1, 2, 5, 16}) {
    gauss_legendre(n, x, w);
    for (int degree = 0; degree < 2 * n; ++degree) {
      double sum = 0.0;
      for (size_t i = 0; i < x.size(); ++i) sum += w[i] * std::pow(x[i], degree);
      EXPECT_NEAR(sum, degree % 2 ? 0.0 : 2.0 / (degree + 1), 1e-13) << n << " " << degree;
    }
  }
}

}  // namespace
}  // namespace haze
