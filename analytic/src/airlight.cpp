#include <haze/analytic/airlight.h>
#include <haze/core/error.h>
#include <haze/analytic/integrate.h>
#include <haze/core/image.h>
#include <haze/core/light.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <optional>
#include <thread>
#include <unordered_map>

namespace haze::analytic {

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

// The tail integrand over eta for the table.
double tail_integral(const PhaseFunction& phase, double u, double eta0) {
  const double w0 = std::exp(eta0);
  auto f = [&](double eta) {
    return std::exp(-u * (std::exp(eta) - w0)) * phase.eval(-std::tanh(eta)) / std::cosh(eta);
  };
  // Past eta0 + 45 (and 45 past 0) the integrand is below e^-45 of its start.
  double end = std::max(eta0, 0.0) + 45.0;
  return integrate_adaptive(f, eta0, end, 1e-5, 0.0, 1 << 14).value;
}

void catmull_rom_weights(double x, double w[4]) {
  w[0] = 0.5 * x * ((2.0 - x) * x - 1.0);
  w[1] = 0.5 * (x * x * (3.0 * x - 5.0) + 2.0);
  w[2] = 0.5 * x * ((4.0 - 3.0 * x) * x + 1.0);
  w[3] = 0.5 * x * x * (x - 1.0);
}

// w = (xi + r) / h without cancellation, xi the signed distance from the foot of the perpendicular.
double w_of(double xi, double r, double h) { return xi >= 0.0 ? (xi + r) / h : h / (r - xi); }

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

AirlightCase random_airlight_case(Rng& rng, int k) {
  double d_sv = std::exp(std::log(1e-3) + rng.uniform() * std::log(1e6));
  double depth = std::exp(std::log(1e-6) + rng.uniform() * std::log(50.0 / 1e-6));
  double gamma = kPi * rng.uniform();
  if (k % 5 == 0) gamma = 1e-6 + rng.uniform() * 1e-4;
  if (k % 5 == 1) gamma = kPi - 1e-6 - rng.uniform() * 1e-3;
  double d_vp = (k % 7 == 0) ? kInfinity : d_sv * std::exp(std::log(1e-3) + rng.uniform() * std::log(1e6));
  if (k % 11 == 0) d_sv = 1e-6 * (std::isfinite(d_vp) ? d_vp : 1.0);
  return {{depth / d_sv, 0.7 * depth / d_sv, 1.0}, {d_sv, gamma, d_vp}};
}

double airlight_no_extinction(const AirlightMedium& medium, const AirlightSegment& segment) {
  check(medium, segment);
  Reduced r = reduce(segment);
  // atan((d_vp - t)/h) - atan(-t/h) = theta_d - theta0.
  return medium.sigma_s * medium.intensity * kInv4Pi / r.h * (r.theta_d - r.theta0);
}

double spot_airlight(const PhaseFunction& phase, const AirlightMedium& medium, const Vec3& viewer, const Vec3& direction,
                     double length, const Vec3& light, const Vec3& axis, double exponent, double cone_deg, double rel_tol) {
  AirlightSegment segment = AirlightSegment::from_points(viewer, direction, light, length);
  check(medium, segment);
  const double cos_c = std::cos(cone_deg * kPi / 180.0);
  const double end = std::isfinite(length) ? length : kInfinity;
  std::vector<double> cuts = cone_crossings(SpotLight{light, axis, Rgb(1.0), exponent, cone_deg}, {viewer, direction}, end);
  cuts.insert(cuts.begin(), 0.0);
  cuts.push_back(end);

  Reduced r = reduce(segment);
  Integrand base{phase, medium.sigma_t, r};
  double total = 0.0;
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    double x0 = cuts[k], x1 = cuts[k + 1];
    double probe = std::isfinite(x1) ? 0.5 * (x0 + x1) : x0 + 1.0 + x0;
    Vec3 e = viewer + probe * direction - light;
    double len_e = glm::length(e);
    if (!(len_e > 0.0) || glm::dot(e, axis) < cos_c * len_e) continue;  // this stretch is outside the cone
    double th0 = std::atan2(x0 - r.t, r.h), th1 = std::isfinite(x1) ? std::atan2(x1 - r.t, r.h) : 0.5 * kPi;
    auto f = [&](double theta) {
      // The point at angle theta and its emission direction from the light.
      double x = r.t + r.h * std::tan(theta);
      Vec3 em = glm::normalize(viewer + x * direction - light);
      double cos_psi = std::max(0.0, glm::dot(em, axis));
      return base(theta) * std::pow(cos_psi, exponent);
    };
    total += integrate_adaptive(f, th0, th1, rel_tol, 0.0, 4096).value;
  }
  return medium.sigma_s * medium.intensity * std::exp(-medium.sigma_t * r.d_sv) / r.h * total;
}

AirlightTable::AirlightTable(const PhaseFunction& phase, int a_samples, int eta_samples, int threads,
                             ProgressCallback progress)
    : phase_(phase), na_(a_samples), neta_(eta_samples) {
  if (a_samples < 2 || a_samples > 8192) throw Error("a_samples", to_text(a_samples), "an integer in [2, 8192]");
  if (eta_samples < 2 || eta_samples > 8192) throw Error("eta_samples", to_text(eta_samples), "an integer in [2, 8192]");
  t_.assign(static_cast<size_t>(na_) * static_cast<size_t>(neta_), 0.0f);
  ProgressTracker tracker(std::move(progress), neta_);
  parallel_for(neta_, threads, 1, [&](long long j0, long long j1) {
    for (auto j = static_cast<int>(j0); j < j1 && !tracker.cancelled(); ++j) {
      double eta0 = -kEtaMax + 2.0 * kEtaMax * j / (neta_ - 1);
      double w0 = std::exp(eta0);
      for (int i = 0; i < na_; ++i) {
        double m = static_cast<double>(i) / (na_ - 1);
        double value;
        if (i == na_ - 1) {
          // a -> infinity: K -> p(-tanh eta0) / (cosh eta0 u w0), so T -> p (1 + w0)^2 / (1 + w0^2).
          value = phase_.eval(-std::tanh(eta0)) * (1.0 + w0) * (1.0 + w0) / (1.0 + w0 * w0);
        } else {
          double a = m * m / (1.0 - m * m);
          value = tail_integral(phase_, a / (1.0 + w0), eta0) * 0.5 * (1.0 + w0) * (1.0 + a);
        }
        t_[static_cast<size_t>(j) * static_cast<size_t>(na_) + static_cast<size_t>(i)] = static_cast<float>(value);
      }
      tracker.advance();
    }
  });
  tracker.throw_if_cancelled();
  refine();
}

void AirlightTable::refine() {
  if (t_.empty()) return;
  const size_t na = static_cast<size_t>(na_);
  std::vector<float> log_t(t_.size());
  // T > 0 but for underflow: log 1e-30 is e^-69 below every value the lanes can resolve.
  for (size_t k = 0; k < t_.size(); ++k) log_t[k] = std::log(std::max(t_[k], 1e-30f));
  const auto nf = static_cast<size_t>(fine_eta_samples());
  std::vector<float> fine_values(nf * na);  // eta fastest
  for (int fine = 0; fine < fine_eta_samples(); ++fine) {
    const int j = std::min(fine / kFineEta, neta_ - 2);
    double w[4];
    catmull_rom_weights(static_cast<double>(fine - j * kFineEta) / kFineEta, w);
    for (size_t i = 0; i < na; ++i) {
      double v = 0.0;
      for (int k = 0; k < 4; ++k) v += w[k] * static_cast<double>(log_t[static_cast<size_t>(std::clamp(j - 1 + k, 0, neta_ - 1)) * na + i]);
      fine_values[i * nf + static_cast<size_t>(fine)] = static_cast<float>(v);
    }
  }
  // Rows i and i + 1 interleaved (log_fine_pairs).
  log_fine_.assign(2 * (na - 1) * nf, 0.0f);
  for (size_t i = 0; i + 1 < na; ++i)
    for (size_t j = 0; j < nf; ++j) log_fine_[2 * (i * nf + j)] = fine_values[i * nf + j], log_fine_[2 * (i * nf + j) + 1] = fine_values[(i + 1) * nf + j];
}

void add_airlight_float64(const AirlightTable& table, const AirlightChannel& light, const SegmentBatch& batch, float* out) {
  const AirlightMedium medium{light.sigma_t, light.sigma_s, light.intensity};
  for (size_t i = 0; i < batch.count; ++i) {
    Vec3 origin(batch.ox[i], batch.oy[i], batch.oz[i]), dir(batch.dx[i], batch.dy[i], batch.dz[i]);
    double length = std::isfinite(batch.length[i]) ? static_cast<double>(batch.length[i]) : kInfinity;
    out[i] += static_cast<float>(
        table.eval(medium, AirlightSegment::from_points(origin, glm::normalize(dir), Vec3(light.x, light.y, light.z), length)));
  }
}

LegendreAirlightTables::LegendreAirlightTables(int terms, int a_samples, int eta_samples, int threads)
    : terms_(terms), na_(a_samples), neta_(eta_samples) {
  if (terms < 1 || terms > 256) throw Error("terms", to_text(terms), "a number of Legendre orders in [1, 256]");
  if (a_samples < 2 || eta_samples < 2) throw Error("samples", to_text(a_samples) + " x " + to_text(eta_samples), "at least 2 x 2");
  const size_t cells = static_cast<size_t>(na_) * static_cast<size_t>(neta_);
  tables_.assign(static_cast<size_t>(terms_), std::vector<float>(cells, 0.0f));
  parallel_for(neta_, threads, 1, [&](long long j0, long long j1) {
    for (auto j = static_cast<int>(j0); j < j1; ++j) {
      double eta0 = -AirlightTable::kEtaMax + 2.0 * AirlightTable::kEtaMax * j / (neta_ - 1);
      double w0 = std::exp(eta0);
      for (int i = 0; i < na_; ++i) {
        double m = static_cast<double>(i) / (na_ - 1);
        size_t cell = static_cast<size_t>(j) * static_cast<size_t>(na_) + static_cast<size_t>(i);
        if (i == na_ - 1) {
          double scale = (1.0 + w0) * (1.0 + w0) / (1.0 + w0 * w0);
          for (int k = 0; k < terms_; ++k)
            tables_[static_cast<size_t>(k)][cell] = static_cast<float>(std::legendre(static_cast<unsigned>(k), -std::tanh(eta0)) * scale);
          continue;
        }
        double a = m * m / (1.0 - m * m), u = a / (1.0 + w0);
        // In psi = pi - 2 atan(e^eta) the tail is a finite, smooth integral (e^eta = cot(psi/2),
        // deta / cosh eta = -dpsi, -tanh eta = -cos psi):
        //   K_k = integral_0^psi0 e^(-u (cot(psi/2) - cot(psi0/2))) P_k(-cos psi) dpsi,
        // the exponent's difference written without cancellation. A few panels resolve it where the
        // eta form needed dozens over its long tail.
        const double psi0 = 2.0 * std::atan(1.0 / w0), sin_half0 = std::sin(0.5 * psi0);
        auto f = [&](const double* psi, int count, double* out) {
          constexpr int kMax = 15;  // nodes per Gauss-Kronrod panel
          double x[kMax], prev[kMax], cur[kMax];
          const auto terms = static_cast<size_t>(terms_);
          for (int q = 0; q < count; ++q) {
            double s = std::sin(0.5 * psi[q]);
            cur[q] = u == 0.0 ? 1.0 : s > 0.0 ? std::exp(-u * std::sin(0.5 * (psi0 - psi[q])) / (s * sin_half0)) : 0.0;
            x[q] = -std::cos(psi[q]);
            prev[q] = 0.0;
          }
          // weight P_k by (k + 1) P_{k+1} = (2k + 1) x P_k - k P_{k-1}, across the panel's nodes at once
          // (one serial chain per node made this recurrence the build's bottleneck).
          for (size_t k = 0; k < terms; ++k) {
            for (int q = 0; q < count; ++q) out[static_cast<size_t>(q) * terms + k] = cur[q];
            const double c_a = (2.0 * static_cast<double>(k) + 1.0) / (static_cast<double>(k) + 1.0);
            const double c_b = static_cast<double>(k) / (static_cast<double>(k) + 1.0);
            for (int q = 0; q < count; ++q) {
              double next = c_a * x[q] * cur[q] - c_b * prev[q];
              prev[q] = cur[q], cur[q] = next;
            }
          }
        };
        auto k_values = integrate_adaptive_nodes(f, terms_, 0.0, psi0, 1e-5, 1 << 14);
        for (int k = 0; k < terms_; ++k)
          tables_[static_cast<size_t>(k)][cell] = static_cast<float>(k_values[static_cast<size_t>(k)] * 0.5 * (1.0 + w0) * (1.0 + a));
      }
    }
  });
}

int LegendreAirlightTables::terms_for(double g, double tolerance, int max_terms) {
  if (!(tolerance > 0.0 && tolerance < 1.0)) throw Error("tolerance", to_text(tolerance), "a number in (0, 1)");
  if (!(std::abs(g) < 1.0)) throw Error("g", to_text(g), "|g| < 1");
  // The dropped terms are at most sum_{k>=K} (2k+1) |g|^k / (4 pi) anywhere; relative to the
  // smallest value of p, (1 - g^2) / (4 pi (1 + |g|)^3), that bounds the relative airlight error.
  const double x = std::abs(g), floor = (1.0 - g * g) / std::pow(1.0 + x, 3.0);
  for (int k = 1; k <= max_terms; ++k) {
    double tail = std::pow(x, k) * ((2.0 * k + 1.0) / (1.0 - x) + 2.0 * x / ((1.0 - x) * (1.0 - x)));
    if (tail <= tolerance * floor) return k;
  }
  return max_terms;
}

double LegendreAirlightTables::truncation_bound(double g, int terms) {
  const double x = std::abs(g), floor = (1.0 - g * g) / std::pow(1.0 + x, 3.0);
  return std::pow(x, terms) * ((2.0 * terms + 1.0) / (1.0 - x) + 2.0 * x / ((1.0 - x) * (1.0 - x))) / floor;
}

AirlightTable LegendreAirlightTables::combine(const std::vector<double>& moments) const {
  if (moments.empty() || moments.size() > static_cast<size_t>(terms_))
    throw Error("moments", to_text(moments.size()) + " values", "1 to " + to_text(terms_) + " Legendre moments");
  std::vector<double> sum(tables_[0].size(), 0.0);
  for (int k = 0; k < static_cast<int>(moments.size()); ++k) {
    double c = (2.0 * k + 1.0) * kInv4Pi * moments[static_cast<size_t>(k)];
    const auto& t = tables_[static_cast<size_t>(k)];
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += c * static_cast<double>(t[i]);
  }
  std::vector<float> values(sum.begin(), sum.end());
  // The phase kept for direct integration of short segments: the truncated series' source.
  std::string origin = "legendre";
  for (double b : moments) {
    char buf[32];
    std::snprintf(buf, sizeof buf, " %.17g", b);
    origin.append(buf);
  }
  return AirlightTable(PhaseFunction::henyey_greenstein(moments.size() > 1 ? moments[1] : 0.0), na_, neta_, std::move(values),
                       origin);
}

AirlightTable LegendreAirlightTables::combine_hg(double g, int terms) const {
  return combine(PhaseFunction::henyey_greenstein(g).legendre_moments(terms > 0 ? terms : terms_));
}

namespace {

std::filesystem::path table_file(const std::filesystem::path& dir, const std::string& prefix, const std::string& key) {
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a
  for (unsigned char c : key) h = (h ^ c) * 1099511628211ULL;
  char name[64];
  std::snprintf(name, sizeof name, "%s-%016llx.exr", prefix.c_str(), static_cast<unsigned long long>(h));
  return dir / name;
}

// The cached values when the file is there and was written for exactly this key.
std::optional<std::vector<float>> load_table(const std::filesystem::path& file, const std::string& key, int width, int height) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) return std::nullopt;
  try {
    int w = 0, h = 0;
    std::map<std::string, std::string> attributes;
    auto values = read_exr_table(file, w, h, attributes);
    if (w == width && h == height && attributes["key"] == key) return values;
  } catch (const Error&) {
  }
  return std::nullopt;
}

void store_table(const std::filesystem::path& file, const std::string& key, int width, int height, const std::vector<float>& values) {
  try {
    std::filesystem::create_directories(file.parent_path());
    // Write aside, then rename: a concurrent reader never sees half a file.
    auto partial = file;
    partial += ".partial" + std::to_string(std::hash<std::thread::id>{}(std::this_thread::get_id()));
    write_exr_table(partial, width, height, values, {{"key", key}});
    std::filesystem::rename(partial, file);
  } catch (const std::exception&) {
    // A cache that cannot be written costs a rebuild next time, nothing more.
  }
}

// What a surface table adds to the key of the airlight table(s) it is built from.
std::string surface_key_suffix(double exponent, int t_samples, int angle_samples) {
  char suffix[96];
  std::snprintf(suffix, sizeof suffix, "; surface v1 n=%.17g %dx%d", exponent, t_samples, angle_samples);
  return suffix;
}

// Several equal-sized tables (one per Legendre order) kept as one EXR, stacked along y.
std::optional<std::vector<std::vector<float>>> load_stacked(const std::filesystem::path& file, const std::string& key, int width,
                                                            int height, int count) {
  auto values = load_table(file, key, width, height * count);
  if (!values) return std::nullopt;
  const auto cells = static_cast<std::ptrdiff_t>(width) * height;
  std::vector<std::vector<float>> tables(static_cast<size_t>(count));
  for (std::ptrdiff_t k = 0; k < count; ++k) tables[static_cast<size_t>(k)].assign(values->begin() + k * cells, values->begin() + (k + 1) * cells);
  return tables;
}

void store_stacked(const std::filesystem::path& file, const std::string& key, int width, int height,
                   const std::vector<std::vector<float>>& tables) {
  std::vector<float> stacked;
  for (const auto& t : tables) stacked.insert(stacked.end(), t.begin(), t.end());
  store_table(file, key, width, height * static_cast<int>(tables.size()), stacked);
}

}  // namespace

std::string AirlightTable::key() const {
  std::string key = "airlight-tail v1; " + phase_.key() + "; " + std::to_string(na_) + "x" + std::to_string(neta_);
  if (!origin_.empty()) key.append("; ").append(origin_);
  return key;
}

AirlightTable AirlightTable::cached(const PhaseFunction& phase, const std::filesystem::path& dir, int a_samples, int eta_samples,
                                    int threads, bool* from_cache) {
  AirlightTable probe(phase, a_samples, eta_samples, std::vector<float>());
  auto file = table_file(dir, "airlight", probe.key());
  if (auto values = load_table(file, probe.key(), a_samples, eta_samples)) {
    if (from_cache) *from_cache = true;
    return AirlightTable(phase, a_samples, eta_samples, std::move(*values));
  }
  AirlightTable built(phase, a_samples, eta_samples, threads);
  store_table(file, built.key(), a_samples, eta_samples, built.t_);
  if (from_cache) *from_cache = false;
  return built;
}

namespace {

// The bicubic (Catmull-Rom) stencil of K(u, eta0) on an a x eta table, shared by every table on
// that grid (one per Legendre order): K = scale * sum_q weight[q] T[offset[q]].
struct TailStencil {
  size_t offset[16];
  double weight[16];
  double scale;

  TailStencil(int na, int neta, double u, double eta0) {
    double w0 = std::exp(std::min(eta0, 700.0));
    double a = u * (1.0 + w0);
    double m = std::sqrt(a / (1.0 + a));
    double fa = (std::isfinite(a) ? m : 1.0) * (na - 1);
    double fe = (std::clamp(eta0, -AirlightTable::kEtaMax, AirlightTable::kEtaMax) + AirlightTable::kEtaMax) /
                (2.0 * AirlightTable::kEtaMax) * (neta - 1);
    int i = std::min(static_cast<int>(fa), na - 2), j = std::min(static_cast<int>(fe), neta - 2);
    // Bicubic: T's curvature limits bilinear lookups to ~3e-3 at the default sizes.
    double wx[4], wy[4];
    catmull_rom_weights(fa - i, wx);
    catmull_rom_weights(fe - j, wy);
    for (int k = 0; k < 4; ++k) {
      size_t row = static_cast<size_t>(std::clamp(j - 1 + k, 0, neta - 1)) * static_cast<size_t>(na);
      for (int l = 0; l < 4; ++l) {
        offset[4 * k + l] = row + static_cast<size_t>(std::clamp(i - 1 + l, 0, na - 1));
        weight[4 * k + l] = wy[k] * wx[l];
      }
    }
    scale = 2.0 / ((1.0 + w0) * (1.0 + a));
  }

  double operator()(const std::vector<float>& table) const {
    double t = 0.0;
    for (int q = 0; q < 16; ++q) t += weight[q] * static_cast<double>(table[offset[q]]);
    return scale * t;
  }
};

}  // namespace

double AirlightTable::tail(double u, double eta0) const { return TailStencil(na_, neta_, u, eta0)(t_); }

double AirlightTable::eval(const AirlightMedium& medium, const AirlightSegment& segment) const {
  check(medium, segment);
  Reduced r = reduce(segment);
  const double u = medium.sigma_t * r.h;
  // Near end: xi = -t, r = d_sv; far end: xi = d_vp - t, r = d_sp.
  double near = std::exp(-medium.sigma_t * r.d_sv) * tail(u, std::log(w_of(-r.t, r.d_sv, r.h)));
  double far = r.infinite ? 0.0
                          : std::exp(-medium.sigma_t * (segment.d_vp + r.d_sp)) *
                                tail(u, std::log(w_of(segment.d_vp - r.t, r.d_sp, r.h)));
  double integral = near - far;
  if (far > 0.5 * near) {
    integral = std::exp(-medium.sigma_t * r.d_sv) *
               integrate_adaptive(Integrand{phase_, medium.sigma_t, r}, r.theta0, r.theta_d, 1e-7, 0.0, 1024).value;
  }
  return medium.sigma_s * medium.intensity / r.h * std::max(0.0, integral);
}

namespace {

// integral_0^2pi max(0, A cos phi + B)^n dphi, A >= 0: closed form for n = 1, Gauss-Legendre over the
// positive arc otherwise (the integrand is smooth there).
double azimuth_integral(double A, double B, double n) {
  if (B >= A) {
    if (n == 1.0) return 2.0 * kPi * B;
  } else if (B <= -A) {
    return 0.0;
  }
  double phi_c = B >= A ? kPi : std::acos(std::clamp(-B / A, -1.0, 1.0));
  if (n == 1.0) return 2.0 * (A * std::sin(phi_c) + B * phi_c);
  static const auto rule = [] {
    std::pair<std::vector<double>, std::vector<double>> r;
    gauss_legendre(48, r.first, r.second);
    return r;
  }();
  // Integer exponents (the usual Phong n) by repeated squaring: std::pow dominated the table build.
  const bool integer = n == std::floor(n) && n <= 65536.0;
  const auto ni = static_cast<unsigned>(n);
  auto power = [&](double x) {
    if (!integer) return std::pow(x, n);
    double result = 1.0;
    for (unsigned e = ni; e; e >>= 1, x *= x)
      if (e & 1u) result *= x;
    return result;
  };
  double sum = 0.0;
  for (size_t q = 0; q < rule.first.size(); ++q) {
    double phi = 0.5 * phi_c * (rule.first[q] + 1.0);
    sum += rule.second[q] * power(std::max(0.0, A * std::cos(phi) + B));
  }
  return 2.0 * 0.5 * phi_c * sum;  // symmetric in phi
}

// J for several tail tables on one a x eta grid (one per Legendre order, or a single one): the
// azimuthal integral and the lookup stencil at each node are shared by all of them, and one
// adaptive quadrature serves every table (its error is relative to the largest, order 0).
// Returns per table (1 + T) J, T fastest.
std::vector<std::vector<float>> surface_tables(const std::vector<const std::vector<float>*>& tails, int a_samples,
                                               int eta_samples, double exponent, int t_samples, int angle_samples,
                                               int threads) {
  if (!(exponent >= 0.0 && exponent <= 1e5)) throw Error("shininess", to_text(exponent), "a Phong exponent in [0, 1e5]");
  if (t_samples < 2 || angle_samples < 2) throw Error("samples", to_text(t_samples) + " x " + to_text(angle_samples), "at least 2 x 2");
  const bool lambert = exponent == 0.0;
  const double n = lambert ? 1.0 : exponent;
  const double scale = lambert ? 1.0 / kPi : (n + 2.0) / (2.0 * kPi);
  const int count = static_cast<int>(tails.size());
  const size_t cells = static_cast<size_t>(t_samples) * static_cast<size_t>(angle_samples);
  std::vector<std::vector<float>> j(tails.size(), std::vector<float>(cells, 0.0f));
  // The tails interleaved (all tables' values for one grid cell together): a stencil then reads 16
  // short runs instead of 16 scattered values from each table.
  const size_t grid = tails[0]->size();
  std::vector<double> interleaved(grid * tails.size());
  for (size_t c = 0; c < grid; ++c)
    for (size_t q = 0; q < tails.size(); ++q) interleaved[c * tails.size() + q] = static_cast<double>((*tails[q])[c]);
  parallel_for(angle_samples, threads, 1, [&](long long k0, long long k1) {
    for (auto k = static_cast<int>(k0); k < k1; ++k) {
      double angle = kPi * k / (angle_samples - 1);
      // Phi depends on gamma and the angle only, and the bisections for different T share most
      // nodes: computed once per node.
      std::unordered_map<double, double> phi_at;
      for (int i = 0; i < t_samples; ++i) {
        double m = static_cast<double>(i) / (t_samples - 1);
        double T = i == t_samples - 1 ? 1e12 : m / (1.0 - m);
        // Incident directions around the light: the lobe axis (normal or R) sits at `angle`.
        auto f = [&](double gamma, double* out) {
          auto [it, added] = phi_at.try_emplace(gamma, 0.0);
          if (added) it->second = azimuth_integral(std::sin(gamma) * std::sin(angle), std::cos(gamma) * std::cos(angle), n);
          const double phi = it->second;
          if (phi == 0.0) {
            std::fill(out, out + count, 0.0);
            return;
          }
          TailStencil stencil(a_samples, eta_samples, T * std::sin(gamma), std::log(std::tan(0.5 * gamma)));
          std::fill(out, out + count, 0.0);
          for (int l = 0; l < 16; ++l) {
            const double* run = interleaved.data() + stencil.offset[l] * tails.size();
            const double w = phi * stencil.scale * stencil.weight[l];
            for (int q = 0; q < count; ++q) out[q] += w * run[q];
          }
        };
        // Phi has kinks where the lobe's horizon enters the circle of directions at gamma (cos(gamma
        // +- angle) = 0): integrating between them spares the quadrature from bisecting into them.
        const double kinks[2] = {std::abs(0.5 * kPi - angle), std::min(0.5 * kPi + angle, 1.5 * kPi - angle)};
        std::vector<double> values(tails.size(), 0.0);
        double lo = 0.0;
        for (double hi : {std::min(kinks[0], kinks[1]), std::max(kinks[0], kinks[1]), kPi}) {
          if (hi <= lo) continue;
          auto piece = integrate_adaptive_vector(f, count, lo, hi, 1e-5, 2048);
          for (size_t q = 0; q < values.size(); ++q) values[q] += piece[q];
          lo = hi;
        }
        size_t cell = static_cast<size_t>(k) * static_cast<size_t>(t_samples) + static_cast<size_t>(i);
        for (int q = 0; q < count; ++q) j[static_cast<size_t>(q)][cell] = static_cast<float>((1.0 + T) * scale * values[static_cast<size_t>(q)]);
      }
    }
  });
  return j;
}

}  // namespace

SurfaceAirlightTable::SurfaceAirlightTable(const AirlightTable& airlight, double exponent, int t_samples, int angle_samples,
                                           int threads)
    : exponent_(exponent),
      nt_(t_samples),
      na_(angle_samples),
      j_(std::move(surface_tables({&airlight.values()}, airlight.a_samples(), airlight.eta_samples(), exponent, t_samples,
                                  angle_samples, threads)[0])) {}

std::string LegendreAirlightTables::key() const {
  return "legendre-tail v1; orders " + std::to_string(terms_) + "; " + std::to_string(na_) + "x" + std::to_string(neta_);
}

LegendreSurfaceTables::LegendreSurfaceTables(const LegendreAirlightTables& legendre, double exponent, int t_samples,
                                             int angle_samples, int threads)
    : exponent_(exponent), nt_(t_samples), na_(angle_samples) {
  std::vector<const std::vector<float>*> tails;
  for (const auto& table : legendre.tables_) tails.push_back(&table);
  j_ = surface_tables(tails, legendre.na_, legendre.neta_, exponent, t_samples, angle_samples, threads);
}

LegendreSurfaceTables LegendreSurfaceTables::cached(const LegendreAirlightTables& legendre, double exponent,
                                                    const std::filesystem::path& dir, int t_samples, int angle_samples,
                                                    int threads, bool* from_cache) {
  const std::string key = legendre.key() + surface_key_suffix(exponent, t_samples, angle_samples);
  auto file = table_file(dir, "legendre-surface", key);
  if (auto tables = load_stacked(file, key, t_samples, angle_samples, legendre.terms())) {
    if (from_cache) *from_cache = true;
    return LegendreSurfaceTables(exponent, t_samples, angle_samples, std::move(*tables));
  }
  LegendreSurfaceTables built(legendre, exponent, t_samples, angle_samples, threads);
  store_stacked(file, key, t_samples, angle_samples, built.j_);
  if (from_cache) *from_cache = false;
  return built;
}

SurfaceAirlightTable LegendreSurfaceTables::combine_hg(double g, int terms) const {
  if (terms < 1 || terms > static_cast<int>(j_.size())) throw Error("terms", to_text(terms), "1 to " + to_text(j_.size()) + " orders");
  std::vector<double> sum(j_[0].size(), 0.0);
  for (int k = 0; k < terms; ++k) {
    double c = (2.0 * k + 1.0) * kInv4Pi * std::pow(g, k);
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += c * static_cast<double>(j_[static_cast<size_t>(k)][i]);
  }
  return SurfaceAirlightTable(exponent_, nt_, na_, std::vector<float>(sum.begin(), sum.end()));
}

LegendreAirlightTables LegendreAirlightTables::cached(int terms, const std::filesystem::path& dir, int a_samples, int eta_samples,
                                                     int threads, bool* from_cache) {
  LegendreAirlightTables probe(terms, a_samples, eta_samples, std::vector<std::vector<float>>());
  const std::string key = probe.key();
  auto file = table_file(dir, "legendre", key);
  if (auto tables = load_stacked(file, key, a_samples, eta_samples, terms)) {
    if (from_cache) *from_cache = true;
    return LegendreAirlightTables(terms, a_samples, eta_samples, std::move(*tables));
  }
  LegendreAirlightTables built(terms, a_samples, eta_samples, threads);
  store_stacked(file, key, a_samples, eta_samples, built.tables_);
  if (from_cache) *from_cache = false;
  return built;
}

SurfaceAirlightTable SurfaceAirlightTable::cached(const AirlightTable& airlight, double exponent, const std::filesystem::path& dir,
                                                 int t_samples, int angle_samples, int threads, bool* from_cache) {
  const std::string key = airlight.key() + surface_key_suffix(exponent, t_samples, angle_samples);
  auto file = table_file(dir, exponent == 0.0 ? "surface-lambert" : "surface-phong", key);
  if (auto values = load_table(file, key, t_samples, angle_samples)) {
    if (from_cache) *from_cache = true;
    return SurfaceAirlightTable(exponent, t_samples, angle_samples, std::move(*values));
  }
  SurfaceAirlightTable built(airlight, exponent, t_samples, angle_samples, threads);
  store_table(file, key, t_samples, angle_samples, built.j_);
  if (from_cache) *from_cache = false;
  return built;
}

double SurfaceAirlightTable::eval(double optical_depth, double angle) const {
  if (!(optical_depth >= 0.0 && optical_depth < kInfinity && angle == angle)) return 0.0;  // no index from NaN
  double m = optical_depth / (1.0 + optical_depth);
  double fi = std::clamp(m, 0.0, 1.0) * (nt_ - 1), fk = std::clamp(angle / kPi, 0.0, 1.0) * (na_ - 1);
  int i = std::min(static_cast<int>(fi), nt_ - 2), k = std::min(static_cast<int>(fk), na_ - 2);
  double x = fi - i, y = fk - k;
  auto at = [&](int ii, int kk) { return static_cast<double>(j_[static_cast<size_t>(kk) * static_cast<size_t>(nt_) + static_cast<size_t>(ii)]); };
  double v = (1 - y) * ((1 - x) * at(i, k) + x * at(i + 1, k)) + y * ((1 - x) * at(i, k + 1) + x * at(i + 1, k + 1));
  return v / (1.0 + optical_depth);
}

}  // namespace haze::analytic
