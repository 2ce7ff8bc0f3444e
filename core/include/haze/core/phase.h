// Phase functions, normalized to 1 over the sphere (isotropic = 1/(4 pi)), with evaluation,
// importance sampling and Legendre moments. cos_theta = dot(wi, wo) between propagation
// directions, so g > 0 scatters forward.
#pragma once

#include <haze/core/math.h>
#include <haze/core/rng.h>

#include <string>
#include <variant>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

enum class PhaseType { isotropic, rayleigh, henyey_greenstein, cornette_shanks, double_hg, tabulated };

class PhaseFunction {
 public:
  // Isotropic by default.
  PhaseFunction();
  static PhaseFunction isotropic();
  // p = 3/(16 pi) (1 + mu^2).
  static PhaseFunction rayleigh();
  // p = (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^(3/2)) (seed 000 eq. 3), |g| <= 0.9999 (kMaxAsymmetry).
  static PhaseFunction henyey_greenstein(double g);
  // p = 3/(8 pi) (1 - g^2)(1 + mu^2) / ((2 + g^2)(1 + g^2 - 2 g mu)^(3/2)), |g| <= 0.9999 (seed 001's
  // Mie approximation).
  static PhaseFunction cornette_shanks(double g);
  // w HG(g1) + (1 - w) HG(g2), w in [0, 1].
  static PhaseFunction double_hg(double g1, double g2, double w);
  // Piecewise linear in mu over values at mu_i = -1 + 2 i / (n - 1), n >= 2, values >= 0 and not all
  // zero. The table is rescaled to integrate to 1; normalization() returns the factor applied.
  static PhaseFunction tabulated(std::vector<double> values);

  PhaseType type() const;
  std::string name() const;  // the scene-file type name: "hg", "rayleigh", ...
  // The name with every parameter at full precision (a tabulated one by a hash of its values):
  // equal keys mean equal functions. Used to name cached tables.
  std::string key() const;
  // Mean cosine <mu> = b_1.
  double mean_cosine() const;
  // Factor applied to make a tabulated function integrate to 1 (1 for the analytic ones).
  double normalization() const;

  // Per steradian.
  double eval(double cos_theta) const;
  double eval(const Vec3& wi, const Vec3& wo) const { return eval(glm::dot(wi, wo)); }

  // Samples cos_theta with density 2 pi p(cos_theta) on [-1, 1]; exact for every type.
  double sample_cos_theta(Rng& rng) const;
  struct Sample {
    Vec3 wo;
    double pdf;  // per steradian, equal to eval(wi, wo)
  };
  // Samples an outgoing propagation direction for incoming direction wi.
  Sample sample(const Vec3& wi, Rng& rng) const;

  // b_k = 2 pi integral p(mu) P_k(mu) dmu for k < count, so that
  // p(mu) = sum_k (2k + 1) / (4 pi) b_k P_k(mu), b_0 = 1, b_k = g^k for HG.
  std::vector<double> legendre_moments(int count) const;

  // The model's parameters when it is of type T (one of the structs below), else nullptr.
  template <class T>
  const T* parameters() const {
    return std::get_if<T>(&model_);
  }

  struct Isotropic {};
  struct Rayleigh {};
  struct HenyeyGreenstein { double g; };
  struct CornetteShanks { double g; };
  struct DoubleHg { double g1, g2, w; };
  struct Tabulated {
    std::vector<double> values;  // normalized
    std::vector<double> cdf;     // at the table's nodes, cdf.back() == 1
    double normalization;
  };

 private:
  using Model = std::variant<Isotropic, Rayleigh, HenyeyGreenstein, CornetteShanks, DoubleHg, Tabulated>;
  explicit PhaseFunction(Model model) : model_(std::move(model)) {}
  Model model_;
};

// Henyey-Greenstein helpers shared by the phase functions and the SIMD reference.
double hg_eval(double g, double cos_theta);
double hg_sample_cos_theta(double g, double u);

// Legendre polynomial P_k(x) by the three-term recurrence.
double legendre_p(int k, double x);
// p(mu) rebuilt from its first moments.size() Legendre moments b_k.
double eval_legendre_series(const std::vector<double>& moments, double cos_theta);
// Relative L2 error over the sphere, ||p - p_K|| / ||p||, of HG truncated to its first `terms`
// Legendre terms: sqrt(sum_{k>=K} (2k+1) g^(2k) / sum_k (2k+1) g^(2k)).
double hg_legendre_truncation_error(double g, int terms);

// Gauss-Legendre nodes and weights on [-1, 1] (float64 quadrature for tables and tests).
void gauss_legendre(int n, std::vector<double>& nodes, std::vector<double>& weights);

}  // namespace haze

#pragma GCC visibility pop
