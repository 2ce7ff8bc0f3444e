#include <haze/core/error.h>
#include <haze/core/limits.h>
#include <haze/core/phase.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace haze {

namespace {

// |g| up to 0.9999 (haze::kMaxAsymmetry): the lobe is then 1e-4 rad wide; past it the analytic
// method's tables took a minute at 0.9999999 and a peak that narrow is a delta, no scattering.
void check_g(double g, const char* field) {
  if (!(std::abs(g) <= kMaxAsymmetry)) throw Error(field, to_text(g), "a number with |g| <= 0.9999");
}

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

double tabulated_eval(const PhaseFunction::Tabulated& t, double mu) {
  const auto n = t.values.size();
  double x = (std::clamp(mu, -1.0, 1.0) + 1.0) * 0.5 * static_cast<double>(n - 1);
  auto i = std::min(static_cast<size_t>(x), n - 2);
  double f = x - static_cast<double>(i);
  return (1.0 - f) * t.values[i] + f * t.values[i + 1];
}

// Inverts the CDF of a piecewise linear density: pick the segment, then solve the quadratic
// a x + (b - a) x^2 / 2 = r (a + b) / 2 in the form that does not cancel.
double tabulated_sample(const PhaseFunction::Tabulated& t, double u) {
  const auto n = t.values.size();
  auto it = std::upper_bound(t.cdf.begin(), t.cdf.end(), u);
  auto k = static_cast<size_t>(std::clamp<std::ptrdiff_t>(it - t.cdf.begin() - 1, 0, static_cast<std::ptrdiff_t>(n - 2)));
  double mass = t.cdf[k + 1] - t.cdf[k];
  double r = mass > 0.0 ? std::clamp((u - t.cdf[k]) / mass, 0.0, 1.0) : 0.5;
  double a = t.values[k], b = t.values[k + 1];
  double denom = a + std::sqrt(std::max(0.0, a * a + (b - a) * r * (a + b)));
  double x = denom > 0.0 ? r * (a + b) / denom : r;
  double h = 2.0 / static_cast<double>(n - 1);
  return std::clamp(-1.0 + (static_cast<double>(k) + x) * h, -1.0, 1.0);
}

}  // namespace

double hg_eval(double g, double cos_theta) {
  double denom = 1.0 + g * g - 2.0 * g * cos_theta;
  return kInv4Pi * (1.0 - g * g) / (denom * std::sqrt(denom));
}

double hg_sample_cos_theta(double g, double u) {
  if (std::abs(g) < 1e-4) return 1.0 - 2.0 * u;
  double s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
  return std::clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
}

PhaseFunction::PhaseFunction() : model_(Isotropic{}) {}
PhaseFunction PhaseFunction::isotropic() { return PhaseFunction(Isotropic{}); }
PhaseFunction PhaseFunction::rayleigh() { return PhaseFunction(Rayleigh{}); }
PhaseFunction PhaseFunction::henyey_greenstein(double g) {
  check_g(g, "g");
  return PhaseFunction(HenyeyGreenstein{g});
}
PhaseFunction PhaseFunction::cornette_shanks(double g) {
  check_g(g, "g");
  return PhaseFunction(CornetteShanks{g});
}
PhaseFunction PhaseFunction::double_hg(double g1, double g2, double w) {
  check_g(g1, "g1");
  check_g(g2, "g2");
  if (!(w >= 0.0 && w <= 1.0)) throw Error("w", to_text(w), "a lobe weight in [0, 1]");
  return PhaseFunction(DoubleHg{g1, g2, w});
}
PhaseFunction PhaseFunction::tabulated(std::vector<double> values) {
  if (values.size() < 2) throw Error("values", to_text(values.size()) + " entries", "at least 2 table entries");
  for (size_t i = 0; i < values.size(); ++i)
    if (!(values[i] >= 0.0 && std::isfinite(values[i])))
      throw Error("values[" + std::to_string(i) + "]", to_text(values[i]), "a finite value >= 0");
  const double h = 2.0 / static_cast<double>(values.size() - 1);
  std::vector<double> cdf(values.size(), 0.0);
  for (size_t i = 1; i < values.size(); ++i) cdf[i] = cdf[i - 1] + 2.0 * kPi * h * 0.5 * (values[i - 1] + values[i]);
  double total = cdf.back();
  if (!(total > 0.0)) throw Error("values", "all zero", "a table with a positive integral");
  for (auto& v : values) v /= total;
  for (auto& c : cdf) c /= total;
  cdf.back() = 1.0;
  return PhaseFunction(Tabulated{std::move(values), std::move(cdf), 1.0 / total});
}

PhaseType PhaseFunction::type() const { return static_cast<PhaseType>(model_.index()); }

std::string PhaseFunction::name() const {
  static const char* names[] = {"isotropic", "rayleigh", "hg", "cornette_shanks", "double_hg", "tabulated"};
  return names[model_.index()];
}

std::string PhaseFunction::key() const {
  char buf[160];
  std::visit(Overloaded{[&](const HenyeyGreenstein& m) { std::snprintf(buf, sizeof buf, "hg g=%.17g", m.g); },
                        [&](const CornetteShanks& m) { std::snprintf(buf, sizeof buf, "cornette_shanks g=%.17g", m.g); },
                        [&](const DoubleHg& m) {
                          std::snprintf(buf, sizeof buf, "double_hg g1=%.17g g2=%.17g w=%.17g", m.g1, m.g2, m.w);
                        },
                        [&](const Tabulated& t) {
                          // FNV-1a over the normalized values' bits.
                          std::uint64_t h = 1469598103934665603ULL;
                          for (double v : t.values) {
                            std::uint64_t bits;
                            std::memcpy(&bits, &v, sizeof bits);
                            for (int k = 0; k < 8; ++k) h = (h ^ ((bits >> (8 * k)) & 0xffu)) * 1099511628211ULL;
                          }
                          std::snprintf(buf, sizeof buf, "tabulated n=%zu fnv=%016llx", t.values.size(),
                                        static_cast<unsigned long long>(h));
                        },
                        [&](const auto&) { std::snprintf(buf, sizeof buf, "%s", name().c_str()); }},
             model_);
  return buf;
}

double PhaseFunction::normalization() const {
  if (auto* t = std::get_if<Tabulated>(&model_)) return t->normalization;
  return 1.0;
}

double PhaseFunction::mean_cosine() const {
  return std::visit(Overloaded{[](const HenyeyGreenstein& m) { return m.g; },
                               [](const DoubleHg& m) { return m.w * m.g1 + (1.0 - m.w) * m.g2; },
                               [this](const auto&) { return legendre_moments(2)[1]; }},
                    model_);
}

double PhaseFunction::eval(double mu) const {
  return std::visit(
      Overloaded{[](const Isotropic&) { return kInv4Pi; },
                 [mu](const Rayleigh&) { return 3.0 / (16.0 * kPi) * (1.0 + mu * mu); },
                 [mu](const HenyeyGreenstein& m) { return hg_eval(m.g, mu); },
                 [mu](const CornetteShanks& m) {
                   // HG times 3/2 (1 + mu^2) / (2 + g^2).
                   return hg_eval(m.g, mu) * 1.5 * (1.0 + mu * mu) / (2.0 + m.g * m.g);
                 },
                 [mu](const DoubleHg& m) { return m.w * hg_eval(m.g1, mu) + (1.0 - m.w) * hg_eval(m.g2, mu); },
                 [mu](const Tabulated& t) { return tabulated_eval(t, mu); }},
      model_);
}

double PhaseFunction::sample_cos_theta(Rng& rng) const {
  return std::visit(
      Overloaded{[&](const Isotropic&) { return 1.0 - 2.0 * rng.uniform(); },
                 [&](const Rayleigh&) {
                   // Invert F(mu) = 3/8 (mu + mu^3 / 3) + 1/2: mu^3 + 3 mu = q (Cardano).
                   double q = 8.0 * rng.uniform() - 4.0;
                   double d = std::sqrt(0.25 * q * q + 1.0);
                   return std::clamp(std::cbrt(0.5 * q + d) + std::cbrt(0.5 * q - d), -1.0, 1.0);
                 },
                 [&](const HenyeyGreenstein& m) { return hg_sample_cos_theta(m.g, rng.uniform()); },
                 [&](const CornetteShanks& m) {
                   // Rejection from HG(g): CS / HG = 3/2 (1 + mu^2) / (2 + g^2) <= 3 / (2 + g^2);
                   // accept with probability (1 + mu^2) / 2 (expected tries < 2).
                   for (;;) {
                     double mu = hg_sample_cos_theta(m.g, rng.uniform());
                     if (2.0 * rng.uniform() <= 1.0 + mu * mu) return mu;
                   }
                 },
                 [&](const DoubleHg& m) {
                   double u = rng.uniform();
                   return u < m.w ? hg_sample_cos_theta(m.g1, rng.uniform()) : hg_sample_cos_theta(m.g2, rng.uniform());
                 },
                 [&](const Tabulated& t) { return tabulated_sample(t, rng.uniform()); }},
      model_);
}

PhaseFunction::Sample PhaseFunction::sample(const Vec3& wi, Rng& rng) const {
  double mu = sample_cos_theta(rng);
  Vec3 wo = direction_around(wi, mu, 2.0 * kPi * rng.uniform());
  return {wo, eval(mu)};
}

std::vector<double> PhaseFunction::legendre_moments(int count) const {
  if (count < 1) throw Error("terms", to_text(count), "at least 1 Legendre term");
  std::vector<double> b(static_cast<size_t>(count), 0.0);
  b[0] = 1.0;
  if (auto* hg = std::get_if<HenyeyGreenstein>(&model_)) {
    for (int k = 1; k < count; ++k) b[static_cast<size_t>(k)] = std::pow(hg->g, k);
    return b;
  }
  if (auto* m = std::get_if<DoubleHg>(&model_)) {
    for (int k = 1; k < count; ++k) b[static_cast<size_t>(k)] = m->w * std::pow(m->g1, k) + (1.0 - m->w) * std::pow(m->g2, k);
    return b;
  }
  if (std::holds_alternative<Isotropic>(model_)) return b;
  // Numerical: b_k = 2 pi integral p(mu) P_k(mu) dmu. A tabulated function is piecewise linear, so
  // integrate segment by segment with enough Gauss points to be exact for degree count + 1.
  std::vector<double> nodes, weights;
  std::vector<std::pair<double, double>> spans{{-1.0, 1.0}};
  if (auto* t = std::get_if<Tabulated>(&model_)) {
    spans.clear();
    const auto n = t->values.size();
    for (size_t i = 0; i + 1 < n; ++i)
      spans.emplace_back(-1.0 + 2.0 * static_cast<double>(i) / static_cast<double>(n - 1),
                         -1.0 + 2.0 * static_cast<double>(i + 1) / static_cast<double>(n - 1));
    gauss_legendre(count / 2 + 2, nodes, weights);
  } else {
    gauss_legendre(std::max(2048, 2 * count), nodes, weights);
  }
  std::fill(b.begin(), b.end(), 0.0);
  for (auto [lo, hi] : spans) {
    double half = 0.5 * (hi - lo), mid = 0.5 * (hi + lo);
    for (size_t q = 0; q < nodes.size(); ++q) {
      double mu = mid + half * nodes[q];
      double w = 2.0 * kPi * half * weights[q] * eval(mu);
      double p_prev = 1.0, p = mu;  // P_0, P_1
      b[0] += w;
      if (count > 1) b[1] += w * mu;
      for (int k = 2; k < count; ++k) {
        double p_next = ((2.0 * k - 1.0) * mu * p - (k - 1.0) * p_prev) / k;
        p_prev = p, p = p_next;
        b[static_cast<size_t>(k)] += w * p;
      }
    }
  }
  return b;
}

double legendre_p(int k, double x) {
  if (k == 0) return 1.0;
  double p_prev = 1.0, p = x;
  for (int n = 2; n <= k; ++n) {
    double p_next = ((2.0 * n - 1.0) * x * p - (n - 1.0) * p_prev) / n;
    p_prev = p, p = p_next;
  }
  return p;
}

double eval_legendre_series(const std::vector<double>& moments, double cos_theta) {
  double sum = 0.0;
  for (size_t k = 0; k < moments.size(); ++k)
    sum += (2.0 * static_cast<double>(k) + 1.0) * moments[k] * legendre_p(static_cast<int>(k), cos_theta);
  return kInv4Pi * sum;
}

double hg_legendre_truncation_error(double g, int terms) {
  check_g(g, "g");
  if (terms < 0) throw Error("terms", to_text(terms), "a count >= 0");
  // ||p||^2 = sum_k (2k+1) b_k^2 / (4 pi); with x = g^2,
  // sum_{k>=K} (2k+1) x^k = x^K [(2K+1)/(1-x) + 2x/(1-x)^2] and the full sum is (1+x)/(1-x)^2.
  double x = g * g, K = terms;
  double ratio = std::pow(x, K) * ((2.0 * K + 1.0) * (1.0 - x) + 2.0 * x) / (1.0 + x);
  return std::sqrt(ratio);
}

void gauss_legendre(int n, std::vector<double>& nodes, std::vector<double>& weights) {
  if (n < 1) throw Error("nodes", to_text(n), "at least 1 quadrature node");
  nodes.assign(static_cast<size_t>(n), 0.0);
  weights.assign(static_cast<size_t>(n), 0.0);
  for (int i = 0; i < (n + 1) / 2; ++i) {
    // Newton from Tricomi's initial guess.
    double x = std::cos(kPi * (i + 0.75) / (n + 0.5));
    double dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1, p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1.0);
      double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-15) break;
    }
    // Recompute the derivative at the converged node for the weight.
    double p0 = 1.0, p1 = x;
    for (int k = 2; k <= n; ++k) {
      double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
      p0 = p1, p1 = p2;
    }
    dp = n == 1 ? 1.0 : n * (x * p1 - p0) / (x * x - 1.0);
    double w = 2.0 / ((1.0 - x * x) * dp * dp);
    nodes[static_cast<size_t>(i)] = -x;
    nodes[static_cast<size_t>(n - 1 - i)] = x;
    weights[static_cast<size_t>(i)] = weights[static_cast<size_t>(n - 1 - i)] = w;
  }
  if (n % 2 == 1) nodes[static_cast<size_t>(n / 2)] = 0.0;
}

}  // namespace haze
