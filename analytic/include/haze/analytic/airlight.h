// Single-scattered airlight from a point light along a view segment in a homogeneous medium
// (seed 002 sec. 4.2.1, the angle-formulated airlight integral, eq. 4.3-4.8).
//
// In Haze's conventions (docs/SCENES.md) the thesis' C0 = kappa_t I0 e^(-kappa_t t) / h becomes
// sigma_s I e^(-sigma_t t) / h: the thesis writes kappa_t where sigma_s = albedo sigma_t belongs,
// and its p integrates to 1 over the sphere as Haze's does. With theta the angle of the light's
// emission direction from the perpendicular to the ray, x = t + h tan(theta) and r = h / cos(theta):
//   L_a = sigma_s I / h  integral_{theta0}^{thetad} e^(-sigma_t (x + r)) p(-sin theta) dtheta,
// theta0 = gamma - pi/2, thetad = atan((d_vp - t) / h), t = d_sv cos(gamma), h = d_sv sin(gamma).
#pragma once

#include <haze/core/phase.h>
#include <haze/core/progress.h>
#include <haze/core/rng.h>

#include <filesystem>
#include <string>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::analytic {

// One view segment and one point light (thesis table 4.1).
struct AirlightSegment {
  double d_sv = 1.0;        // viewer to light
  double gamma = 0.5;       // between the view direction and the direction to the light, [0, pi]
  double d_vp = kInfinity;  // viewer to the end of the segment (a surface), or infinite

  // From positions: the viewer, the unit view direction, the light, the segment length.
  static AirlightSegment from_points(const Vec3& viewer, const Vec3& direction, const Vec3& light, double length);
};

// The medium and the light's strength: L_a is proportional to sigma_s I.
struct AirlightMedium {
  double sigma_t = 1.0;
  double sigma_s = 1.0;
  double intensity = 1.0;
};

// The yardstick: adaptive Gauss-Kronrod quadrature of the angle-formulated integral to rel_tol.
// The segment must not touch the light (h > 0 and d_sv > 0).
double airlight_quadrature(const PhaseFunction& phase, const AirlightMedium& medium, const AirlightSegment& segment,
                           double rel_tol = 1e-10);

// The randomized sweep the tables are measured with (tests, bench/analytic_accuracy): case k has
// optical depth sigma_t d_sv log-uniform in [1e-6, 50]; gamma uniform, or within 1e-6 to 1e-4 of
// the light ahead (k % 5 == 0), or of the light behind the viewer (k % 5 == 1); a segment of 1e-3 to
// 1e3 d_sv or infinite (k % 7 == 0); the viewer next to the light (d_sv 1e-6 of the segment, every
// 11th). sigma_s = 0.7 sigma_t, I = 1.
struct AirlightCase {
  AirlightMedium medium;
  AirlightSegment segment;
};
AirlightCase random_airlight_case(Rng& rng, int k);

// Seed 004 / BEYOND.md: isotropic phase and no extinction,
// L = sigma_s I / (4 pi h) [atan((d_vp - t) / h) - atan(-t / h)]. A segment through the light is
// evaluated at h = 1e-9 d_sv (and d_sv >= 1e-12): large, finite, never NaN.
double airlight_no_extinction(const AirlightMedium& medium, const AirlightSegment& segment);

// Airlight from a spot light, I(psi) = I0 cos^n(psi) inside the cone half-angle (the thesis' future
// work, sec. 6.2.1): the view segment is cut to the stretches inside the cone (a quadratic in the
// distance along the ray), and each stretch is integrated in the angle form by adaptive
// Gauss-Kronrod to rel_tol. No table: the cone adds two angles and an exponent per light, and the
// stretches are short where the cone is narrow. `medium.intensity` is I0.
double spot_airlight(const PhaseFunction& phase, const AirlightMedium& medium, const Vec3& viewer, const Vec3& direction,
                     double length, const Vec3& light, const Vec3& axis, double exponent, double cone_deg,
                     double rel_tol = 1e-5);

// The tabulated airlight for one phase function (the thesis' H(u, v) in a better-conditioned form).
// With eta = asinh(tan theta) (so w = (1 + sin theta) / cos theta = e^eta, x + r = t + h e^eta and
// dtheta = deta / cosh eta), the airlight is a difference of two tails,
//   L_a = sigma_s I / h [e^(-sigma_t d_sv) K(u, eta0) - e^(-sigma_t (d_vp + d_sp)) K(u, eta_d)],
//   K(u, eta0) = integral_{eta0}^inf e^(-u (e^eta - e^eta0)) p(-tanh eta) / cosh eta deta,  u = sigma_t h,
// each term in range for every optical depth and for lights behind the viewer (where the thesis'
// H(u, v) differences cancel). The table holds T = K (1 + w0) (1 + a) / 2 with a = u (1 + w0),
// which stays bounded and smooth: eta0 uniform in [-30, 30] (beyond, T no longer depends on eta0
// to 1e-13), and m = sqrt(a / (1 + a)) uniform in [0, 1] (the square root absorbs K's u log u
// behaviour at small u; m = 1 is the exact limit). Lookups are bicubic (Catmull-Rom). At the
// default 256 x 512 the worst relative error against quadrature over 10^4 random segments with
// the extremes (tests/analytic/airlight_test.cpp) is 5.8e-4 for HG g in [-0.95, 0.95]; a table takes
// about 0.4 s on 2 threads.
class AirlightTable {
 public:
  AirlightTable(const PhaseFunction& phase, int a_samples = 256, int eta_samples = 512, int threads = 0,
                ProgressCallback progress = {});

  // Airlight for one segment by two table lookups; when the far tail is at least half the near one
  // (a short segment) the difference would cancel, so that stretch is integrated directly. A
  // segment through the light is evaluated at h = 1e-9 d_sv: large, finite, never NaN.
  double eval(const AirlightMedium& medium, const AirlightSegment& segment) const;
  // K(u, eta0) by bicubic lookup.
  double tail(double u, double eta0) const;

  // The table for `phase` read from `dir` when a file for it is there, else built and written there
  // (a single-channel EXR named by a hash of key()). A cache that cannot be read or written only
  // costs the rebuild; `from_cache` says which happened.
  static AirlightTable cached(const PhaseFunction& phase, const std::filesystem::path& dir, int a_samples = 256,
                              int eta_samples = 512, int threads = 0, bool* from_cache = nullptr);
  // What the values depend on: format version, phase key, sizes.
  std::string key() const;
  const PhaseFunction& phase() const { return phase_; }

  int a_samples() const { return na_; }
  int eta_samples() const { return neta_; }
  const std::vector<float>& values() const { return t_; }  // a fastest
  // The float32 lanes' form (haze::simd::add_airlight): log T on a grid kFineEta times finer in
  // eta, resampled from the table by Catmull-Rom in log T along eta. T is steep in eta for
  // forward-scattering media: bilinear lookups in T itself were 1.2e-2 off eval's bicubic ones at
  // g = 0.9, in this form 8e-4. Stored as pairs of neighbouring a rows, eta fastest: at float
  // 2 (i fine_eta_samples() + j), log T at (i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1), so that
  // a bilinear lookup is one 16-byte load (and a ray's neighbouring slices read neighbouring
  // records); rows i < a_samples() - 1.
  const std::vector<float>& log_fine_pairs() const { return log_fine_; }
  int fine_eta_samples() const { return kFineEta * (neta_ - 1) + 1; }

  static constexpr double kEtaMax = 30.0;
  static constexpr int kFineEta = 4;

 private:
  friend class LegendreAirlightTables;
  AirlightTable(const PhaseFunction& phase, int a_samples, int eta_samples, std::vector<float> values, std::string origin = "")
      : phase_(phase), na_(a_samples), neta_(eta_samples), t_(std::move(values)), origin_(std::move(origin)) {
    refine();
  }
  void refine();  // log_fine_ (log_fine_pairs) from t_
  PhaseFunction phase_;
  int na_, neta_;
  std::vector<float> t_, log_fine_;
  std::string origin_;  // how the values were made when not by direct integration (part of key())
};

// Dynamic g (seed 002 sec. 4.3, eq. 4.16-4.18) in the tail form: one table per Legendre order k
// with P_k(-tanh eta) in place of p, so that for p = sum_k (2k+1)/(4 pi) b_k P_k the airlight tail
// is K = sum_k (2k+1)/(4 pi) b_k K_k. combine_hg(g) sums them into an AirlightTable for HG(g)
// truncated to terms() orders: a weighted sum of terms() tables of 256 x 512, a few milliseconds,
// so g can change every frame without recomputing integrals.
class LegendreAirlightTables {
 public:
  LegendreAirlightTables(int terms, int a_samples = 256, int eta_samples = 512, int threads = 0);
  // The fewest orders K whose dropped HG terms stay below `tolerance` times the smallest value of
  // the phase function (so the relative airlight error is bounded even for back-scattered light,
  // where p is smallest): sum_{k>=K} (2k+1)|g|^k <= tol (1 - g^2) / (1 + |g|)^3. At most max_terms.
  // The thesis' fixed 3 terms bound nothing: at g = 0.5 the sweep measures 34% error with 7 terms.
  static int terms_for(double g, double tolerance, int max_terms = 64);
  // That bound for a given number of orders (the truncation error `haze` reports).
  static double truncation_bound(double g, int terms);
  // From moments b_0 .. b_{K-1}, K <= terms(); short segments are integrated directly with HG(b_1).
  AirlightTable combine(const std::vector<double>& moments) const;
  // HG(g) truncated to `terms` orders (0: all of terms()).
  AirlightTable combine_hg(double g, int terms = 0) const;
  int terms() const { return terms_; }

  std::string key() const;

  // As AirlightTable::cached: all orders in one EXR, keyed by version, orders and sizes.
  static LegendreAirlightTables cached(int terms, const std::filesystem::path& dir, int a_samples = 256, int eta_samples = 512,
                                       int threads = 0, bool* from_cache = nullptr);

 private:
  LegendreAirlightTables(int terms, int a_samples, int eta_samples, std::vector<std::vector<float>> tables)
      : terms_(terms), na_(a_samples), neta_(eta_samples), tables_(std::move(tables)) {}
  int terms_, na_, neta_;
  std::vector<std::vector<float>> tables_;  // per order: K_k (1 + w0) (1 + a) / 2, a fastest
  friend class LegendreSurfaceTables;
};

// Batches of view segments for fast airlight evaluation (structure of arrays, float32): start
// (viewer or medium entry), unit direction, length (+inf when unbounded).
struct SegmentBatch {
  const float* ox;
  const float* oy;
  const float* oz;
  const float* dx;
  const float* dy;
  const float* dz;
  const float* length;
  size_t count;
};

// One colour channel of one point light in a homogeneous medium.
struct AirlightChannel {
  float x, y, z;  // light position
  float sigma_t, sigma_s, intensity;
};

// out[i] += airlight of segment i, one segment at a time through AirlightTable::eval in float64
// (method analytic's `kernel` "float64"; add_airlight in airlight_batch.h is the SIMD one).
void add_airlight_float64(const AirlightTable& table, const AirlightChannel& light, const SegmentBatch& batch, float* out);

// Airlight scattered onto a surface (seed 002 eq. 4.11-4.15) in Haze's energy-normalized BRDFs:
//   L_pa = sigma_s I e^(-T) / d_sp [kd J1(T, theta_s) + ks J_n(T, theta'_s) max(0, n . R)],
// T = sigma_t d_sp, theta_s the angle between the normal and the light, theta'_s the angle between
// the light and R, the view direction mirrored about the normal. With gamma the angle between an
// incident direction and the light and K the airlight tail (the sin gamma of the solid angle
// cancels the 1 / h of the airlight):
//   J1 = 1/pi            integral_0^pi K(T sin gamma, ln tan(gamma/2)) Phi_1(gamma) dgamma,
//   J_n = (n + 2)/(2 pi) integral_0^pi K(T sin gamma, ln tan(gamma/2)) Phi_n(gamma) dgamma,
// Phi_1 = integral over azimuth of max(0, cos theta_i) (closed form), Phi_n the same of
// max(0, omega . R)^n. The Phong form drops cos theta_i inside the lobe for max(0, n . R) outside
// it, as the thesis' reparameterization does; no surface blocks the incident airlight.
class SurfaceAirlightTable {
 public:
  // exponent 0 builds J1 (Lambert); n > 0 builds J_n (Phong).
  SurfaceAirlightTable(const AirlightTable& airlight, double exponent, int t_samples = 64, int angle_samples = 64,
                       int threads = 0);
  // J(T, angle): bilinear in m = T / (1 + T) and the angle in [0, pi].
  double eval(double optical_depth, double angle) const;
  double exponent() const { return exponent_; }

  // As AirlightTable::cached; the key adds the exponent and sizes to the airlight table's.
  static SurfaceAirlightTable cached(const AirlightTable& airlight, double exponent, const std::filesystem::path& dir,
                                     int t_samples = 64, int angle_samples = 64, int threads = 0, bool* from_cache = nullptr);
  const std::vector<float>& values() const { return j_; }  // (1 + T) J, T fastest
  int t_samples() const { return nt_; }
  int angle_samples() const { return na_; }

 private:
  friend class LegendreSurfaceTables;
  SurfaceAirlightTable(double exponent, int t_samples, int angle_samples, std::vector<float> values)
      : exponent_(exponent), nt_(t_samples), na_(angle_samples), j_(std::move(values)) {}
  double exponent_;
  int nt_, na_;
  std::vector<float> j_;  // (1 + T) J, T fastest
};

// Dynamic g for the surface airlight: J tables built from each Legendre order's tail (J is linear
// in the tail), summed for a given g like the airlight tables.
class LegendreSurfaceTables {
 public:
  LegendreSurfaceTables(const LegendreAirlightTables& legendre, double exponent, int t_samples = 64, int angle_samples = 64,
                        int threads = 0);
  static LegendreSurfaceTables cached(const LegendreAirlightTables& legendre, double exponent, const std::filesystem::path& dir,
                                      int t_samples = 64, int angle_samples = 64, int threads = 0, bool* from_cache = nullptr);
  // J for HG(g) truncated to `terms` orders (at most the orders built).
  SurfaceAirlightTable combine_hg(double g, int terms) const;

 private:
  LegendreSurfaceTables(double exponent, int t_samples, int angle_samples, std::vector<std::vector<float>> tables)
      : exponent_(exponent), nt_(t_samples), na_(angle_samples), j_(std::move(tables)) {}
  double exponent_;
  int nt_, na_;
  std::vector<std::vector<float>> j_;  // per order
};

}  // namespace haze::analytic

#pragma GCC visibility pop
