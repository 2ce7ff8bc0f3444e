// The angle-formulated airlight (seed 002 sec. 4.2.1): the quadrature yardstick against closed
// forms and the adaptive integrator against known integrals.
#include <haze/analytic/airlight.h>
#include <haze/core/stopwatch.h>
#include <haze/core/error.h>
#include <haze/analytic/integrate.h>
#include <haze/core/rng.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <unistd.h>


namespace haze::analytic {
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

struct SweepStats {
  double worst = 0.0;
  AirlightSegment worst_segment;
  AirlightMedium worst_medium;
  int count = 0;
};

// The randomized sweep with the extremes (haze::random_airlight_case).
SweepStats sweep(const PhaseFunction& phase, const AirlightTable& table, int n, std::uint64_t seed) {
  Rng rng(seed, 17);
  SweepStats stats;
  for (int k = 0; k < n; ++k) {
    auto [m, s] = random_airlight_case(rng, k);
    double exact = airlight_quadrature(phase, m, s, 1e-9);
    double fast = table.eval(m, s);
    EXPECT_TRUE(std::isfinite(fast));
    double err = std::abs(fast - exact) / exact;
    if (!(err <= stats.worst)) stats.worst = err, stats.worst_segment = s, stats.worst_medium = m;
    ++stats.count;
  }
  return stats;
}

// Issue 4: the table within 1e-3 of quadrature over 10^4 configurations with the extremes.
TEST(Airlight, TableMatchesQuadratureOverRandomSweep) {
  int total = 0;
  for (double g : {-0.95, -0.5, 0.0, 0.5, 0.8, 0.95}) {
    PhaseFunction phase = PhaseFunction::henyey_greenstein(g);
    Stopwatch start;
    AirlightTable table(phase);
    double seconds = start.seconds();
    SweepStats stats = sweep(phase, table, 1700, static_cast<std::uint64_t>(1000 * (g + 1)));
    total += stats.count;
    std::printf("HG g %+.2f: table %.2f s; %d configurations, worst relative error %.2e (d_sv %.3g gamma %.9g d_vp %.3g sigma_t %.3g)\n",
                g, seconds, stats.count, stats.worst, stats.worst_segment.d_sv, stats.worst_segment.gamma,
                stats.worst_segment.d_vp, stats.worst_medium.sigma_t);
    EXPECT_LT(stats.worst, 1e-3) << "g " << g;
  }
  EXPECT_GE(total, 10000);
}

// At the singular limits the radiance diverges; the table returns a large finite value, the same
// whatever thread count built it.
TEST(Airlight, SingularLimitsAreFiniteAndThreadIndependent) {
  PhaseFunction phase = PhaseFunction::henyey_greenstein(0.6);
  AirlightTable one(phase, 64, 128, 1), two(phase, 64, 128, 2);
  EXPECT_EQ(one.values(), two.values());
  AirlightMedium m{0.4, 0.3, 1.0};
  for (const AirlightSegment& s : {AirlightSegment{2.0, 0.0, 5.0}, AirlightSegment{2.0, 0.0, kInfinity},
                                   AirlightSegment{2.0, kPi, 5.0}, AirlightSegment{0.0, 0.3, 5.0},
                                   AirlightSegment{0.0, 0.0, kInfinity}}) {
    double value = one.eval(m, s);
    EXPECT_TRUE(std::isfinite(value)) << s.d_sv << " " << s.gamma;
    EXPECT_GE(value, 0.0);
    EXPECT_EQ(value, two.eval(m, s));
  }
  // Through the light ahead it is far above a near miss; behind the viewer it stays moderate.
  EXPECT_GT(one.eval(m, {2.0, 0.0, 5.0}), 1e3 * one.eval(m, {2.0, 0.1, 5.0}));
  EXPECT_LT(one.eval(m, {2.0, kPi, 5.0}), 1.0);
}

// Airlight onto a surface point against brute force: the airlight of every incident direction by
// adaptive quadrature, integrated over directions around the light (Gauss-Legendre in gamma and
// azimuth, the hemisphere cut by max(0, .)).
double brute_force_surface_airlight(const PhaseFunction& phase, const AirlightMedium& m, double d_sp, double theta_s,
                                    double exponent, double theta_r, bool exact_cosine) {
  std::vector<double> xg, wg, xp, wp;
  gauss_legendre(96, xg, wg);
  gauss_legendre(256, xp, wp);
  const Vec3 normal(std::sin(theta_s), 0.0, std::cos(theta_s));  // light along +z
  const Vec3 lobe(std::sin(theta_r), 0.0, std::cos(theta_r));
  double sum = 0.0;
  for (size_t i = 0; i < xg.size(); ++i) {
    double gamma = 0.5 * kPi * (xg[i] + 1.0);
    double airlight = airlight_quadrature(phase, m, {d_sp, gamma, kInfinity}, 1e-8);
    for (size_t k = 0; k < xp.size(); ++k) {
      double phi = kPi * (xp[k] + 1.0);
      Vec3 w(std::sin(gamma) * std::cos(phi), std::sin(gamma) * std::sin(phi), std::cos(gamma));
      double cos_i = glm::dot(w, normal);
      double f = exponent == 0.0 ? 1.0 / kPi * std::max(0.0, cos_i)
                                 : (exponent + 2.0) / (2.0 * kPi) * std::pow(std::max(0.0, glm::dot(w, lobe)), exponent) *
                                       (exact_cosine ? std::max(0.0, cos_i) : std::max(0.0, glm::dot(normal, lobe)));
      sum += 0.5 * kPi * wg[i] * kPi * wp[k] * std::sin(gamma) * airlight * f;
    }
  }
  return sum;
}

TEST(Airlight, SurfaceTablesMatchBruteForce) {
  PhaseFunction phase = PhaseFunction::henyey_greenstein(0.4);
  AirlightTable airlight(phase);
  SurfaceAirlightTable lambert(airlight, 0.0), phong(airlight, 20.0);
  for (double depth : {0.02, 0.6, 3.0})
    for (double theta_s : {0.3, 1.2, 2.0}) {
      const double d_sp = 1.5;
      AirlightMedium m{depth / d_sp, 0.8 * depth / d_sp, 2.0};
      double prefactor = m.sigma_s * m.intensity * std::exp(-depth) / d_sp;
      double exact = brute_force_surface_airlight(phase, m, d_sp, theta_s, 0.0, 0.0, true);
      double table = prefactor * lambert.eval(depth, theta_s);
      EXPECT_NEAR(table / exact, 1.0, 0.01) << "Lambert, depth " << depth << " theta_s " << theta_s;
      // Phong with the lobe axis R at 0.4 rad from the normal.
      double theta_r = theta_s - 0.4;
      double approx = brute_force_surface_airlight(phase, m, d_sp, theta_s, 20.0, theta_r, false);
      double full = brute_force_surface_airlight(phase, m, d_sp, theta_s, 20.0, theta_r, true);
      double phong_table = prefactor * phong.eval(depth, std::abs(theta_r)) * std::cos(0.4);
      EXPECT_NEAR(phong_table / approx, 1.0, 0.01) << "Phong, depth " << depth << " theta_s " << theta_s;
      std::printf("surface airlight depth %.2f theta_s %.1f: Lambert table/exact %.5f; Phong table/exact %.5f "
                  "(the lobe-cosine approximation alone: %.5f)\n",
                  depth, theta_s, table / exact, phong_table / full, approx / full);
    }
}

// Dynamic g: Legendre tables built once, recombined for each g, against the exact HG airlight.
// With terms_for's bound the measured error stays below the tolerance plus the table's own error.
TEST(Airlight, LegendreTablesFollowGWithinTheTruncationBound) {
  Stopwatch start;
  LegendreAirlightTables legendre(32, 128, 512);
  double seconds = start.seconds();
  for (double g : {-0.3, 0.2, 0.5}) {
    const double tolerance = 1e-2;
    int terms = LegendreAirlightTables::terms_for(g, tolerance, 32);
    ASSERT_LT(terms, 32) << g;
    start.restart();
    AirlightTable table = legendre.combine_hg(g, terms);
    double combine_ms = 1e3 * start.seconds();
    SweepStats stats = sweep(PhaseFunction::henyey_greenstein(g), table, 400, 7);
    std::printf("Legendre (32 orders of 128 x 512, built in %.2f s): g %+.1f, tolerance %.0e -> %d terms (bound %.1e), "
                "combined in %.1f ms, worst relative error %.2e\n",
                seconds, g, tolerance, terms, LegendreAirlightTables::truncation_bound(g, terms), combine_ms, stats.worst);
    EXPECT_LE(LegendreAirlightTables::truncation_bound(g, terms), tolerance);
    EXPECT_LT(stats.worst, tolerance + 5e-3) << g;
  }
}

// Dynamic g for the surface airlight: the per-order J tables summed for g reproduce the J tables
// built from HG(g)'s own airlight table (both Lambert and Phong), to the truncation bound plus
// the tables' interpolation error.
TEST(Airlight, LegendreSurfaceTablesMatchDirectTables) {
  const double g = 0.3;
  LegendreAirlightTables legendre(24, 128, 256);
  ASSERT_LT(LegendreAirlightTables::truncation_bound(g, 24), 1e-9);
  AirlightTable direct(PhaseFunction::henyey_greenstein(g), 128, 256);
  for (double exponent : {0.0, 20.0}) {
    auto summed = LegendreSurfaceTables(legendre, exponent, 24, 24).combine_hg(g, 24).values();
    auto exact = SurfaceAirlightTable(direct, exponent, 24, 24).values();
    ASSERT_EQ(summed.size(), exact.size());
    double worst = 0.0, largest = 0.0;
    for (size_t i = 0; i < exact.size(); ++i) {
      worst = std::max(worst, std::abs(static_cast<double>(summed[i] - exact[i])));
      largest = std::max(largest, std::abs(static_cast<double>(exact[i])));
    }
    EXPECT_LT(worst, 2e-3 * largest) << "exponent " << exponent;
    std::printf("J (exponent %g) from 24 Legendre orders vs from HG(%.1f): worst difference %.1e of the largest value\n",
                exponent, g, worst / largest);
  }
}

// Tables cached as EXR: the second request reads what the first wrote, bit for bit; a file
// written for other parameters is not taken for this one.
TEST(Airlight, TablesRoundTripThroughTheCache) {
  auto dir = std::filesystem::temp_directory_path() / ("haze_airlight_cache_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  PhaseFunction phase = PhaseFunction::henyey_greenstein(0.3);
  bool hit = true;
  AirlightTable built = AirlightTable::cached(phase, dir, 32, 64, 0, &hit);
  EXPECT_FALSE(hit);
  AirlightTable read = AirlightTable::cached(phase, dir, 32, 64, 0, &hit);
  EXPECT_TRUE(hit);
  EXPECT_EQ(read.values(), built.values());
  EXPECT_EQ(read.key(), built.key());
  SurfaceAirlightTable j = SurfaceAirlightTable::cached(read, 10.0, dir, 16, 16, 0, &hit);
  EXPECT_FALSE(hit);
  EXPECT_EQ(SurfaceAirlightTable::cached(read, 10.0, dir, 16, 16, 0, &hit).values(), j.values());
  EXPECT_TRUE(hit);
  // Another g or size is another table.
  AirlightTable::cached(PhaseFunction::henyey_greenstein(0.30001), dir, 32, 64, 0, &hit);
  EXPECT_FALSE(hit);
  AirlightTable::cached(phase, dir, 32, 65, 0, &hit);
  EXPECT_FALSE(hit);
  // Legendre tables (all orders in one file) and their surface tables round-trip too.
  LegendreAirlightTables orders = LegendreAirlightTables::cached(4, dir, 16, 32, 0, &hit);
  EXPECT_FALSE(hit);
  LegendreAirlightTables orders_read = LegendreAirlightTables::cached(4, dir, 16, 32, 0, &hit);
  EXPECT_TRUE(hit);
  EXPECT_EQ(orders_read.combine_hg(0.4).values(), orders.combine_hg(0.4).values());
  auto surface = LegendreSurfaceTables::cached(orders, 0.0, dir, 8, 8, 0, &hit);
  EXPECT_FALSE(hit);
  EXPECT_EQ(LegendreSurfaceTables::cached(orders_read, 0.0, dir, 8, 8, 0, &hit).combine_hg(0.4, 4).values(),
            surface.combine_hg(0.4, 4).values());
  EXPECT_TRUE(hit);
  // A damaged file is rebuilt, not an error.
  for (const auto& entry : std::filesystem::directory_iterator(dir)) std::filesystem::resize_file(entry.path(), 100);
  AirlightTable rebuilt = AirlightTable::cached(phase, dir, 32, 64, 0, &hit);
  EXPECT_FALSE(hit);
  EXPECT_EQ(rebuilt.values(), built.values());
  std::filesystem::remove_all(dir);
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
}  // namespace haze::analytic
