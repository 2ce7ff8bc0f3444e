// The discrete-ordinate solver of method "dom" (seed 000): first-collision source, upwind
// transport (step characteristics), source iteration or GMRES on the moments, and the paper's
// one-cell-per-iteration scheme.
#include <haze/grids/dom.h>

#include <haze/core/error.h>
#include <haze/simd/phase_batch.h>

#include "dom_internal.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iterator>
#include <unistd.h>

namespace haze::grids {

DomScheme dom_scheme_from_name(const std::string& name) {
  if (name == "paper") return DomScheme::paper;
  if (name == "sweep") return DomScheme::sweep;
  throw Error("scheme", name, "\"paper\" or \"sweep\"");
}
const char* name(DomScheme scheme) { return scheme == DomScheme::paper ? "paper" : "sweep"; }

DomAccelerator dom_accelerator_from_name(const std::string& name) {
  if (name == "none") return DomAccelerator::none;
  if (name == "gmres") return DomAccelerator::gmres;
  throw Error("accelerator", name, "\"none\" or \"gmres\"");
}
const char* name(DomAccelerator accelerator) { return accelerator == DomAccelerator::none ? "none" : "gmres"; }

namespace {

size_t available_memory() {
  std::ifstream in("/proc/meminfo");
  std::string key, unit;
  size_t kb = 0;
  while (in >> key >> kb >> unit)
    if (key == "MemAvailable:") return kb * 1024;
  const long pages = sysconf(_SC_AVPHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<size_t>(pages) * static_cast<size_t>(page) : SIZE_MAX;
}

int kept_terms(const DomSettings& s) { return s.terms == 0 ? s.directions : s.terms; }
constexpr int kGmresRestart = 12;

// Vector operations of the iteration, threaded in fixed chunks (partial sums added in chunk order,
// so results do not depend on the thread count).
constexpr long long kChunk = 1 << 16;

double dot(const std::vector<float>& a, const std::vector<float>& b, int threads) {
  const auto size = static_cast<long long>(a.size());
  std::vector<double> partial(static_cast<size_t>((size + kChunk - 1) / kChunk), 0.0);
  parallel_for(size, threads, kChunk, [&](long long i0, long long i1) {
    float sum[8] = {};
    long long i = i0;
    for (; i + 8 <= i1; i += 8)
      for (long long e = 0; e < 8; ++e) sum[e] += a[static_cast<size_t>(i + e)] * b[static_cast<size_t>(i + e)];
    double total = 0.0;
    for (float e : sum) total += static_cast<double>(e);
    for (; i < i1; ++i) total += static_cast<double>(a[static_cast<size_t>(i)] * b[static_cast<size_t>(i)]);
    partial[static_cast<size_t>(i0 / kChunk)] = total;
  });
  double total = 0.0;
  for (double p : partial) total += p;
  return total;
}
double norm(const std::vector<float>& a, int threads) { return std::sqrt(dot(a, a, threads)); }
// a = alpha a + beta b
void combine(std::vector<float>& a, double alpha, double beta, const std::vector<float>& b, int threads) {
  const auto fa = static_cast<float>(alpha), fb = static_cast<float>(beta);
  parallel_for(static_cast<long long>(a.size()), threads, kChunk, [&](long long i0, long long i1) {
    for (auto i = static_cast<size_t>(i0); i < static_cast<size_t>(i1); ++i) a[i] = fa * a[i] + fb * b[i];
  });
}
void axpy(std::vector<float>& a, double s, const std::vector<float>& b, int threads) { combine(a, 1.0, s, b, threads); }

// Calls the progress callback once per iteration; throws haze::Cancelled when it says stop.
struct IterationProgress {
  const DomSettings& settings;
  void operator()(int iteration) const {
    if (settings.progress && !settings.progress(std::min(1.0, iteration / static_cast<double>(settings.max_iterations))))
      throw Cancelled();
  }
};

// Source iteration x <- b + K x (each step one sweep), or restarted GMRES on (I - K) x = b.
void solve_moments(const dom::Transport& t, const dom::Channel& channel, const std::vector<float>& b, std::vector<float>& x,
                   const DomSettings& settings, DomSolution& out) {
  const IterationProgress progress{settings};
  std::vector<float> kx(x.size());
  const int th = settings.threads;
  auto residual = [&](std::vector<float>& r) {  // r = b + K x - x, one sweep
    t.sweep(channel, nullptr, x.data(), 0.0f, kx.data(), th);
    ++out.iterations;
    r = kx;
    axpy(r, 1.0, b, th);
    axpy(r, -1.0, x, th);
  };
  if (settings.accelerator == DomAccelerator::none) {
    std::vector<float> r(x.size());
    while (out.iterations < settings.max_iterations) {
      residual(r);
      axpy(x, 1.0, r, th);
      const double change = norm(r, th) / std::max(norm(x, th), 1e-300);
      out.changes.push_back(change);
      progress(out.iterations);
      if (change < settings.tolerance) return;
    }
    return;
  }
  // GMRES(m) with modified Gram-Schmidt and Givens rotations (Saad, Iterative Methods, alg. 6.9).
  const int m = kGmresRestart;
  std::vector<std::vector<float>> v(static_cast<size_t>(m + 1), std::vector<float>(x.size()));
  std::vector<float> w(x.size());
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(m + 1, m);
  Eigen::VectorXd cs(m), sn(m), g(m + 1);
  while (out.iterations < settings.max_iterations) {
    residual(v[0]);
    const double x_norm = std::max(norm(x, th), 1e-300);
    double beta = norm(v[0], th);
    out.changes.push_back(beta / x_norm);
    progress(out.iterations);
    if (beta / x_norm < settings.tolerance || beta == 0.0) return;
    combine(v[0], 1.0 / beta, 0.0, v[0], th);
    g.setZero();
    g(0) = beta;
    int j = 0;
    for (; j < m && out.iterations < settings.max_iterations; ++j) {
      t.sweep(channel, nullptr, v[static_cast<size_t>(j)].data(), 0.0f, kx.data(), th);  // w = (I - K) v_j
      ++out.iterations;
      w = v[static_cast<size_t>(j)];
      axpy(w, -1.0, kx, th);
      for (int i = 0; i <= j; ++i) {
        h(i, j) = dot(w, v[static_cast<size_t>(i)], th);
        axpy(w, -h(i, j), v[static_cast<size_t>(i)], th);
      }
      h(j + 1, j) = norm(w, th);
      if (h(j + 1, j) > 0.0) combine(v[static_cast<size_t>(j + 1)], 0.0, 1.0 / h(j + 1, j), w, th);
      for (int i = 0; i < j; ++i) {
        const double a = cs(i) * h(i, j) + sn(i) * h(i + 1, j);
        h(i + 1, j) = -sn(i) * h(i, j) + cs(i) * h(i + 1, j);
        h(i, j) = a;
      }
      const double r = std::hypot(h(j, j), h(j + 1, j));
      cs(j) = h(j, j) / r, sn(j) = h(j + 1, j) / r;
      h(j, j) = r, h(j + 1, j) = 0.0;
      g(j + 1) = -sn(j) * g(j);
      g(j) = cs(j) * g(j);
      out.changes.push_back(std::abs(g(j + 1)) / x_norm);
      progress(out.iterations);
      if (std::abs(g(j + 1)) / x_norm < settings.tolerance) {
        ++j;
        break;
      }
    }
    // x += V_j y, with H_j y = g_j (upper triangular).
    Eigen::VectorXd y = h.topLeftCorner(j, j).triangularView<Eigen::Upper>().solve(g.head(j));
    for (int i = 0; i < j; ++i) axpy(x, y(i), v[static_cast<size_t>(i)], th);
  }
}

}  // namespace

size_t dom_memory_bytes(const std::array<int, 3>& resolution, int channels, const DomSettings& settings) {
  const size_t cells = static_cast<size_t>(resolution[0]) * static_cast<size_t>(resolution[1]) * static_cast<size_t>(resolution[2]);
  const auto d = static_cast<size_t>(settings.directions), n = static_cast<size_t>(kept_terms(settings));
  const size_t padded = d + 8 * 7;  // the first-collision source pads each octant to a multiple of 8
  const size_t result = static_cast<size_t>(channels) * cells * n;
  size_t work;
  if (settings.scheme == DomScheme::paper) {
    work = cells * padded + 3 * cells * d + 2 * cells * n;  // first-collision source; radiance twice, in-scatter; moments twice
  } else {
    // first-collision source (freed before iterating), b, K x and the second half's sweep output;
    // GMRES adds its Krylov basis.
    const size_t vectors = 3 + (settings.accelerator == DomAccelerator::gmres ? kGmresRestart + 2 : 1);
    work = std::max(cells * padded + 2 * cells * n, vectors * cells * n);
  }
  return sizeof(float) * (result + work);
}

DomSolution solve_dom(const ExtinctionVolume& volume, const std::vector<Light>& lights, const std::vector<DenseGrid>& delta_depths,
                      const DomSettings& settings, const DomSolution* warm) {
  if (settings.directions < 8 || settings.directions > 4096)
    throw Error("directions", to_text(settings.directions), "a direction count in [8, 4096]");
  if (settings.terms < 0 || settings.terms > settings.directions)
    throw Error("terms", to_text(settings.terms),
                "a term count in [1, " + to_text(settings.directions) + "] (the direction count), or 0 for the full matrix");
  if (settings.max_iterations < 1) throw Error("iterations", to_text(settings.max_iterations), "at least 1");
  if (!(settings.tolerance > 0.0)) throw Error("tolerance", to_text(settings.tolerance), "a relative change > 0");
  std::vector<Light> delta_lights;
  std::copy_if(lights.begin(), lights.end(), std::back_inserter(delta_lights), [](const Light& l) { return !std::holds_alternative<SkyLight>(l); });
  if (delta_depths.size() != delta_lights.size())
    throw Error("depths", to_text(delta_depths.size()) + " volumes",
                "one per light other than the sky (" + to_text(delta_lights.size()) + ")");
  for (size_t i = 0; i < delta_depths.size(); ++i)
    if (delta_depths[i].resolution() != volume.density.resolution())
      throw Error("depths[" + std::to_string(i) + "]", "a grid of another resolution", "the density's resolution");

  bool grey = is_grey(volume.sigma_t_scale) && is_grey(volume.albedo);
  for (const Light& l : lights) {
    std::visit([&](const auto& light) {
      using T = std::decay_t<decltype(light)>;
      if constexpr (std::is_same_v<T, DirectionalLight>) grey = grey && is_grey(light.irradiance);
      else if constexpr (std::is_same_v<T, SkyLight>) grey = grey && is_grey(light.radiance);
      else grey = grey && is_grey(light.intensity);
    }, l);
  }
  const auto start = std::chrono::steady_clock::now();
  DomSolution out;
  out.channels = grey ? 1 : 3;
  out.resolution = volume.density.resolution();
  out.bytes = dom_memory_bytes(out.resolution, out.channels, settings);
  if (const size_t free = available_memory(); out.bytes > free)
    throw Error("dom grid", to_text(out.bytes >> 20) + " MiB for " + to_text(volume.density.cell_count()) + " cells x " +
                                to_text(settings.directions) + " directions",
                "a solve that fits in the " + to_text(free >> 20) + " MiB available (fewer cells, directions or terms)");

  out.directions = std::make_shared<DirectionSet>(DirectionSet::fibonacci(settings.directions));
  out.phase = volume.phase;
  if (settings.delta_m && kept_terms(settings) < settings.directions) {
    const auto m = static_cast<int>(std::floor(std::sqrt(kept_terms(settings))));
    const std::vector<double> b = volume.phase.legendre_moments(m + 1);
    if (const double f = b[static_cast<size_t>(m)]; f > 1e-6 && f < 1.0) {
      std::vector<double> remainder(static_cast<size_t>(m));
      for (size_t k = 0; k < remainder.size(); ++k) remainder[k] = (b[k] - f) / (1.0 - f);
      std::vector<double> table(2049);
      for (size_t i = 0; i < table.size(); ++i)
        table[i] = std::max(0.0, eval_legendre_series(remainder, -1.0 + 2.0 * static_cast<double>(i) / 2048.0));
      out.phase = PhaseFunction::tabulated(std::move(table));
      out.delta_m_fraction = f;
    }
  }
  out.matrix = std::make_shared<PhaseMatrix>(out.phase, *out.directions);
  out.separable = std::make_shared<SeparablePhase>(*out.matrix, kept_terms(settings));
  const dom::Transport transport(volume.density, *out.directions, *out.matrix, *out.separable, settings.scalar_kernel);
  const size_t size = volume.density.cell_count() * static_cast<size_t>(out.terms());
  const bool warm_fits = warm && warm->channels == out.channels && warm->resolution == out.resolution &&
                         warm->terms() == out.terms() && warm->directions && warm->directions->size() == settings.directions;

  out.moments.resize(static_cast<size_t>(out.channels));
  for (int c = 0; c < out.channels; ++c) {
    const dom::Channel channel = dom::make_channel(volume, lights, c, out.delta_m_fraction);
    std::vector<float> first = transport.first_collision(volume, delta_lights, delta_depths, c, 1.0 / (1.0 - out.delta_m_fraction), settings.threads);
    std::vector<float>& x = out.moments[static_cast<size_t>(c)];
    if (settings.scheme == DomScheme::paper) {
      x = transport.paper(channel, first, warm_fits ? &warm->moments[static_cast<size_t>(c)] : nullptr, settings, out.iterations,
                          out.changes);
      continue;
    }
    std::vector<float> b(size);
    transport.sweep(channel, first.data(), nullptr, channel.sky, b.data(), settings.threads);
    ++out.iterations;
    std::vector<float>().swap(first);
    x = warm_fits ? warm->moments[static_cast<size_t>(c)] : b;
    solve_moments(transport, channel, b, x, settings, out);
  }
  out.converged = !out.changes.empty() && out.changes.back() < settings.tolerance;
  out.sweep_seconds = transport.seconds();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

Eigen::VectorXd inscatter_weights(const DomSolution& solution, const Vec3& w) {
  const PhaseFunction& phase = solution.phase;
  const DirectionSet& dirs = *solution.directions;
  const Eigen::VectorXd& s = solution.matrix->scaling();
  Eigen::VectorXd row(dirs.size());
  for (int j = 0; j < dirs.size(); ++j) row(j) = phase.eval(glm::dot(w, dirs[j])) * dirs.weight(j) * s(j);
  row /= row.sum();
  return solution.separable->basis().transpose() * row;
}

}  // namespace haze::grids
