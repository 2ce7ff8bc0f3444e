// The discrete-ordinate solver of method "dom" (seed 000): first-collision source, upwind
// transport (step characteristics), source iteration or GMRES on the moments, and the paper's
// one-cell-per-iteration scheme.
#include <haze/grids/dom.h>
#include <haze/core/stopwatch.h>

#include <haze/core/error.h>
#include <haze/simd/phase_batch.h>

#include "dom_diffusion.h"
#include "dom_internal.h"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace haze::grids {

DomScheme dom_scheme_from_name(const std::string& name) { return from_name<DomScheme>(kDomSchemes, name, "scheme"); }
const char* name(DomScheme scheme) { return name_of<DomScheme>(kDomSchemes, scheme); }
DomSpatial dom_spatial_from_name(const std::string& name) { return from_name<DomSpatial>(kDomSpatials, name, "spatial"); }
const char* name(DomSpatial spatial) { return name_of<DomSpatial>(kDomSpatials, spatial); }
DomAccelerator dom_accelerator_from_name(const std::string& name) { return from_name<DomAccelerator>(kDomAccelerators, name, "accelerator"); }
const char* name(DomAccelerator accelerator) { return name_of<DomAccelerator>(kDomAccelerators, accelerator); }
DomStorage dom_storage_from_name(const std::string& name) { return from_name<DomStorage>(kDomStorages, name, "storage"); }
const char* name(DomStorage storage) { return name_of<DomStorage>(kDomStorages, storage); }

namespace {

int kept_terms(const DomSettings& s) { return s.terms == 0 ? s.directions : s.terms; }
constexpr int kGmresRestart = 12;

// Vector operations of the iteration, threaded in fixed chunks (partial sums added in chunk order,
// so results do not depend on the thread count).
constexpr long long kChunk = 1 << 16;

double chunk_dot(const float* a, const float* b, size_t count) {  // 8 float sums, then double
  float sum[8] = {};
  size_t i = 0;
  for (; i + 8 <= count; i += 8)
    for (size_t e = 0; e < 8; ++e) sum[e] += a[i + e] * b[i + e];
  double total = 0.0;
  for (float e : sum) total += static_cast<double>(e);
  for (; i < count; ++i) total += static_cast<double>(a[i] * b[i]);
  return total;
}

// Split over processes (DomExchange), summed over all of them.
double dot(const std::vector<float>& a, const std::vector<float>& b, int threads, DomExchange* exchange) {
  const auto size = static_cast<long long>(a.size());
  std::vector<double> partial(static_cast<size_t>((size + kChunk - 1) / kChunk), 0.0);
  parallel_for(size, threads, kChunk, [&](long long i0, long long i1) {
    partial[static_cast<size_t>(i0 / kChunk)] = chunk_dot(a.data() + i0, b.data() + i0, static_cast<size_t>(i1 - i0));
  });
  double total = 0.0;
  for (double p : partial) total += p;
  if (exchange) exchange->sum(&total, 1);
  return total;
}
double norm(const std::vector<float>& a, int threads, DomExchange* exchange) { return std::sqrt(dot(a, a, threads, exchange)); }
// a += s b
void axpy(std::vector<float>& a, double s, const std::vector<float>& b, int threads) {
  const auto fs = static_cast<float>(s);
  parallel_for(static_cast<long long>(a.size()), threads, kChunk, [&](long long i0, long long i1) {
    for (auto i = static_cast<size_t>(i0); i < static_cast<size_t>(i1); ++i) a[i] = a[i] + fs * b[i];
  });
}

// GMRES's basis vectors (unit length), in float32 or float16; the vector operations read a
// float16 vector a chunk at a time, converted, in the same fixed chunks.
class KrylovBasis {
 public:
  // Vectors are allocated when first stored: a solve that stops after a few steps (a warm start)
  // does not pay for the whole basis.
  KrylovBasis(int count, size_t size, bool half) : size_(size), half_(half) {
    if (half) halves_.resize(static_cast<size_t>(count));
    else floats_.resize(static_cast<size_t>(count));
  }
  void store(int i, const std::vector<float>& w, double scale, int threads) {  // v_i = scale w
    if (half_) halves_[static_cast<size_t>(i)].resize(size_);
    else floats_[static_cast<size_t>(i)].resize(size_);
    const auto s = static_cast<float>(scale);
    parallel_for(static_cast<long long>(size_), threads, kChunk, [&](long long i0, long long i1) {
      const auto b = static_cast<size_t>(i0), count = static_cast<size_t>(i1 - i0);
      std::vector<float> converted(half_ ? count : 0);
      float* to = half_ ? converted.data() : floats_[static_cast<size_t>(i)].data() + b;
      for (size_t e = 0; e < count; ++e) to[e] = s * w[b + e];
      if (half_) simd::to_half(to, halves_[static_cast<size_t>(i)].data() + b, count);
    });
  }
  void load(int i, std::vector<float>& w, int threads) const {  // w = v_i
    each_chunk(i, i + 1, threads, [&](size_t b, size_t n, int, const float* v) { std::copy(v, v + n, w.data() + b); });
  }
  // h_i = v_i . w for i < count: one pass over w and each v_i, chunk by chunk (classical
  // Gram-Schmidt's projections, where modified Gram-Schmidt passes over w twice per vector).
  std::vector<double> dots(const std::vector<float>& w, int count, int threads, DomExchange* exchange) const {
    const auto chunk = static_cast<size_t>(kChunk), chunks_n = (size_ + chunk - 1) / chunk, vectors = static_cast<size_t>(count);
    std::vector<double> partial(chunks_n * vectors, 0.0);
    each_chunk(0, count, threads, [&](size_t b, size_t n, int i, const float* v) {
      partial[b / chunk * vectors + static_cast<size_t>(i)] = chunk_dot(w.data() + b, v, n);
    });
    std::vector<double> h(vectors, 0.0);
    for (size_t c = 0; c < chunks_n; ++c)
      for (size_t i = 0; i < vectors; ++i) h[i] += partial[c * vectors + i];
    if (exchange) exchange->sum(h.data(), count);
    return h;
  }
  // w -= sum_i h_i v_i for i < count, in one pass over w.
  void subtract(std::vector<float>& w, const std::vector<double>& h, int count, int threads) const {
    each_chunk(0, count, threads, [&](size_t b, size_t n, int i, const float* v) {
      const auto s = static_cast<float>(h[static_cast<size_t>(i)]);
      for (size_t e = 0; e < n; ++e) w[b + e] = w[b + e] - s * v[e];
    });
  }

 private:
  // f(begin, n, i, v_i's values there as float32) for first <= i < last, per fixed chunk, the
  // vectors in order within a chunk.
  template <class F>
  void each_chunk(int first, int last, int threads, const F& f) const {
    parallel_for(static_cast<long long>(size_), threads, kChunk, [&](long long i0, long long i1) {
      const auto b = static_cast<size_t>(i0), n = static_cast<size_t>(i1 - i0);
      std::vector<float> converted(half_ ? n : 0);
      for (int i = first; i < last; ++i) {
        if (!half_) {
          f(b, n, i, floats_[static_cast<size_t>(i)].data() + b);
          continue;
        }
        simd::to_float(halves_[static_cast<size_t>(i)].data() + b, converted.data(), n);
        f(b, n, i, converted.data());
      }
    });
  }
  size_t size_;
  bool half_;
  std::vector<std::vector<float>> floats_;
  std::vector<std::vector<simd::Half>> halves_;
};

// Calls the progress callback once per iteration; throws haze::Cancelled when it says stop.
// Each channel has its own budget of settings.max_iterations sweeps, starting at `start`.
struct IterationProgress {
  const DomSettings& settings;
  int channel, channels, start;
  void operator()(int iteration) const {
    const double fraction = std::min(1.0, (iteration - start) / static_cast<double>(settings.max_iterations));
    if (settings.progress && !settings.progress((channel + fraction) / channels)) throw Cancelled();
  }
};

// Source iteration x <- b + K x (each step one sweep; with `dsa`, the grid, corrected by diffusion
// synthetic acceleration: q0 the phase basis's constant entry), or restarted GMRES on (I - K) x = b.
void solve_moments(const dom::Transport& t, const dom::Channel& channel, const std::vector<float>& b, std::vector<float>& x,
                   const DomSettings& settings, const IterationProgress& progress, DomSolution& out, double tolerance,
                   const DenseGrid* dsa, double q0) {
  const int limit = progress.start + settings.max_iterations;
  std::vector<float> kx(x.size());
  const int th = settings.threads;
  DomExchange* const ex = settings.exchange;
  auto residual = [&](std::vector<float>& r) {  // r = b + K x - x, one sweep
    t.sweep(channel, nullptr, x.data(), 0.0f, kx.data(), th);
    ++out.iterations;
    parallel_for(static_cast<long long>(r.size()), th, kChunk, [&](long long i0, long long i1) {
      for (auto i = static_cast<size_t>(i0); i < static_cast<size_t>(i1); ++i) r[i] = kx[i] + b[i] - x[i];
    });
  };
  if (settings.accelerator == DomAccelerator::none) {
    std::vector<float> r(x.size()), corrected;
    while (out.iterations < limit) {
      residual(r);
      if (dsa) {
        corrected = x;
        axpy(corrected, 1.0, r, th);
        dom::diffusion_correction(*dsa, channel, out.terms(), q0, x, corrected, th);
        for (size_t i = 0; i < r.size(); ++i) r[i] = corrected[i] - x[i];
      }
      axpy(x, 1.0, r, th);
      const double change = norm(r, th, ex) / std::max(norm(x, th, ex), 1e-300);
      out.changes.push_back(change);
      progress(out.iterations);
      if (change < tolerance) return;
    }
    return;
  }
  // GMRES(m) with Givens rotations (Saad, Iterative Methods, alg. 6.9), classical Gram-Schmidt:
  // two passes over w per step instead of two per basis vector. It stops on the rotations'
  // estimate of the residual, as GMRES codes do (a verifying sweep cost 3 of 24 sweeps on the
  // dense cloud and changed nothing there); a restart takes the true residual.
  const int m = kGmresRestart;
  KrylovBasis v(m + 1, x.size(), settings.storage == DomStorage::float16);
  std::vector<float> w(x.size());
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(m + 1, m);
  Eigen::VectorXd cs(m), sn(m), g(m + 1);
  // From x = 0 the first residual is b itself, no sweep; the first cycle measures against |b|.
  bool from_zero = std::all_of(x.begin(), x.end(), [](float e) { return e == 0.0f; });
  if (ex) from_zero = ex->all(from_zero);
  while (out.iterations < limit) {
    if (from_zero) w = b;
    else residual(w);
    const double x_norm = std::max(norm(from_zero ? b : x, th, ex), 1e-300);
    from_zero = false;
    double beta = norm(w, th, ex);
    out.changes.push_back(beta / x_norm);
    progress(out.iterations);
    if (beta / x_norm < tolerance || beta == 0.0) return;
    v.store(0, w, 1.0 / beta, th);
    g.setZero();
    g(0) = beta;
    int j = 0;
    bool estimated = false;  // the Givens estimate of the residual fell under the tolerance
    for (; j < m && out.iterations < limit; ++j) {
      v.load(j, w, th);
      t.sweep(channel, nullptr, w.data(), 0.0f, kx.data(), th);  // w = (I - K) v_j
      ++out.iterations;
      axpy(w, -1.0, kx, th);
      const std::vector<double> projections = v.dots(w, j + 1, th, ex);
      v.subtract(w, projections, j + 1, th);
      for (int i = 0; i <= j; ++i) h(i, j) = projections[static_cast<size_t>(i)];
      h(j + 1, j) = norm(w, th, ex);
      const bool breakdown = !(h(j + 1, j) > 1e-300);  // w in the Krylov space: x_j solves the system there
      if (!breakdown) v.store(j + 1, w, 1.0 / h(j + 1, j), th);
      else h(j + 1, j) = 0.0;
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
      if (breakdown || std::abs(g(j + 1)) / x_norm < tolerance) {
        ++j;
        estimated = true;
        break;
      }
    }
    // The budget ran out before a Krylov step: the residual's sweep is still a source iteration.
    if (j == 0) {
      axpy(x, 1.0, w, th);
      return;
    }
    // x += V_j y, with H_j y = g_j (upper triangular).
    Eigen::VectorXd y = h.topLeftCorner(j, j).triangularView<Eigen::Upper>().solve(g.head(j));
    std::vector<double> minus_y(static_cast<size_t>(j));
    for (int i = 0; i < j; ++i) minus_y[static_cast<size_t>(i)] = -y(i);
    v.subtract(x, minus_y, j, th);
    if (estimated) return;
  }
}

}  // namespace

size_t dom_memory_bytes(const std::array<int, 3>& resolution, int channels, const DomSettings& settings) {
  const size_t cells = static_cast<size_t>(resolution[0]) * static_cast<size_t>(resolution[1]) * static_cast<size_t>(resolution[2]);
  const auto d = static_cast<size_t>(settings.directions), n = static_cast<size_t>(kept_terms(settings));
  const size_t padded = d + 8 * 7;  // the first-collision source pads each octant to a multiple of 8
  // The moments, and the fix-up's marks of the channel being solved (a byte per cell and octant).
  const size_t result = sizeof(float) * static_cast<size_t>(channels) * cells * n + (settings.spatial == DomSpatial::diamond ? cells * 8 : 0);
  if (settings.scheme == DomScheme::paper)  // first-collision source and slopes; radiance twice, in-scatter; moments twice
    return result + sizeof(float) * (cells * padded + 3 * cells + 3 * cells * d + 2 * cells * n);
  // The first-collision source (its slopes, 3 per cell; float16 adds a scale per cell) with b and
  // the second half's sweep output; then, the source freed, b, K x, the sweep output, a work
  // vector and GMRES's basis.
  const bool half = settings.storage == DomStorage::float16;
  const size_t first = (half ? sizeof(simd::Half) * cells * padded + sizeof(float) * cells : sizeof(float) * cells * padded) + sizeof(float) * 3 * cells;
  const size_t basis = settings.accelerator == DomAccelerator::gmres ? kGmresRestart + 1 : 0;
  const size_t iterating = sizeof(float) * 4 * cells * n + (half ? sizeof(simd::Half) : sizeof(float)) * basis * cells * n;
  return result + std::max(first + sizeof(float) * 2 * cells * n, iterating);
}

namespace {

// The solution's directions, phase (the medium's, or its delta-M remainder) and the phase matrix
// with its N-term factorization.
void factorize(const PhaseFunction& phase, const DomSettings& settings, DomSolution& out) {
  out.directions = std::make_shared<DirectionSet>(DirectionSet::fibonacci(settings.directions));
  out.phase = phase;
  if (settings.delta_m && kept_terms(settings) < settings.directions) {
    const auto m = static_cast<int>(std::floor(std::sqrt(kept_terms(settings))));
    const std::vector<double> b = phase.legendre_moments(m + 1);
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
}

}  // namespace

DomSolution solve_dom(const ExtinctionVolume& volume, const std::vector<Light>& lights, const std::vector<DenseGrid>& delta_depths,
                      const DomSettings& settings, const DomSolution* warm, const DomBoundary* boundary,
                      std::vector<std::vector<float>>* spare) {
  if (settings.directions < 8 || settings.directions > 4096)
    throw Error("directions", to_text(settings.directions), "a direction count in [8, 4096]");
  if (settings.terms < 0 || settings.terms > settings.directions)
    throw Error("terms", to_text(settings.terms),
                "a term count in [1, " + to_text(settings.directions) + "] (the direction count), or 0 for the full matrix");
  if (settings.max_iterations < 1) throw Error("iterations", to_text(settings.max_iterations), "at least 1");
  if (!(settings.tolerance > 0.0)) throw Error("tolerance", to_text(settings.tolerance), "a relative change > 0");
  if (settings.storage == DomStorage::float16 && settings.scheme == DomScheme::paper)
    throw Error("storage", "float16", "float32 with scheme \"paper\" (float16 storage is for scheme \"sweep\")");
  if (settings.spatial != DomSpatial::step && settings.scheme == DomScheme::paper)
    throw Error("spatial", name(settings.spatial), "\"step\" with scheme \"paper\" (the paper's Jacobi update is the step scheme)");
  if (boundary && settings.scheme == DomScheme::paper)
    throw Error("scheme", "paper", "scheme \"sweep\" with a boundary (the paper's scheme takes only the sky's radiance)");
  DomExchange* const exchange = settings.exchange;
  const int nz = volume.density.resolution()[2];
  if (exchange) {
    if (exchange->first_plane < 0 || exchange->last_plane > nz || exchange->first_plane >= exchange->last_plane)
      throw Error("exchange", "planes [" + to_text(exchange->first_plane) + ", " + to_text(exchange->last_plane) + ")",
                  "a part of the grid's " + to_text(nz) + " z planes, at least one");
    if (settings.scheme != DomScheme::sweep) throw Error("scheme", name(settings.scheme), "\"sweep\" in a solve split over processes");
    if (settings.accelerator != DomAccelerator::gmres)
      throw Error("accelerator", name(settings.accelerator), "\"gmres\" in a solve split over processes");
    if (boundary) throw Error("boundary", "surfaces or a boundary", "the sky alone in a solve split over processes (surfaces not yet)");
  }
  std::vector<Light> delta_lights;
  std::copy_if(lights.begin(), lights.end(), std::back_inserter(delta_lights), [](const Light& l) { return !std::holds_alternative<SkyLight>(l); });
  if (delta_depths.size() != delta_lights.size())
    throw Error("depths", to_text(delta_depths.size()) + " volumes",
                "one per light other than the sky (" + to_text(delta_lights.size()) + ")");
  for (size_t i = 0; i < delta_depths.size(); ++i)
    if (delta_depths[i].resolution() != volume.density.resolution())
      throw Error("depths[" + std::to_string(i) + "]", "a grid of another resolution", "the density's resolution");

  bool grey = is_grey(volume.sigma_t_scale) && is_grey(volume.albedo);
  for (const Light& l : lights) grey = grey && is_grey(l);
  grey = grey && (!boundary || boundary->grey);
  const Emission& emission = volume.emission;
  grey = grey && (!emission.emits() || (is_grey(emission.color) && emission.blackbody_intensity <= 0.0));
  Stopwatch start;
  DomSolution out;
  out.channels = grey ? 1 : 3;
  out.resolution = volume.density.resolution();
  if (exchange) out.resolution[2] = exchange->last_plane - exchange->first_plane, out.first_plane = exchange->first_plane;
  const size_t cells = static_cast<size_t>(out.resolution[0]) * static_cast<size_t>(out.resolution[1]) * static_cast<size_t>(out.resolution[2]);
  out.bytes = dom_memory_bytes(out.resolution, out.channels, settings);
  check_memory(out.bytes, settings.max_memory, "dom grid",
               to_text(cells) + " cells x " + to_text(settings.directions) + " directions",
               "fewer cells, directions or terms");
  if (exchange) exchange->begin();

  // The directions and the phase matrix's factorization depend only on the medium's phase and the
  // settings: a warm solve of the same ones (an update) takes them as they are.
  out.factorization = volume.phase.key() + (settings.delta_m ? " delta-M" : "") + " D=" + to_text(settings.directions) + " N=" +
                      to_text(kept_terms(settings));
  if (warm && warm->factorization == out.factorization && warm->separable) {
    out.directions = warm->directions, out.phase = warm->phase, out.delta_m_fraction = warm->delta_m_fraction;
    out.matrix = warm->matrix, out.separable = warm->separable;
  } else {
    factorize(volume.phase, settings, out);
  }
  const dom::Transport transport(volume.density, *out.directions, *out.matrix, *out.separable, settings.spatial, settings.scalar_kernel,
                                   exchange);
  const size_t size = cells * static_cast<size_t>(out.terms());
  const std::vector<dom::Faces> faces = boundary ? transport.faces(*boundary, volume.density, out.channels, settings.threads)
                                                 : std::vector<dom::Faces>();
  // DSA needs the basis's first vector constant (the l = 0 eigenvector, eigenvalue 1): its entry q0.
  double q0 = out.separable->basis()(0, 0);
  for (long d = 0; d < out.separable->basis().rows(); ++d)
    if (std::abs(out.separable->basis()(d, 0) - q0) > 1e-6 * std::abs(q0)) q0 = 0.0;
  const bool dsa = settings.diffusion_acceleration && q0 != 0.0;
  bool warm_fits = warm && warm->channels == out.channels && warm->resolution == out.resolution && warm->first_plane == out.first_plane &&
                   warm->terms() == out.terms() && warm->directions && warm->directions->size() == settings.directions;
  if (exchange) warm_fits = exchange->all(warm_fits);  // every process starts warm or none does: their iterations must match

  out.moments.resize(static_cast<size_t>(out.channels));
  double previous_source = 0.0;  // b . x of the channel solved last
  for (int c = 0; c < out.channels; ++c) {
    dom::Channel channel = dom::make_channel(volume, lights, c, out.delta_m_fraction, out.first_plane);
    std::vector<std::uint8_t> bounded;  // the diamond's fix-up marks (dom::Channel)
    if (settings.spatial == DomSpatial::diamond) {
      bounded.assign(cells * 8, 0);
      channel.bounded = bounded.data();
    }
    const dom::Faces* entering = boundary ? &faces[static_cast<size_t>(c)] : nullptr;
    const Stopwatch source_watch;
    dom::FirstCollision first = transport.first_collision(volume, delta_lights, delta_depths, c, 1.0 / (1.0 - out.delta_m_fraction),
                                                          settings.storage == DomStorage::float16, settings.threads, settings.scheme != DomScheme::paper);
    out.first_collision_seconds += source_watch.seconds();
    std::vector<float>& x = out.moments[static_cast<size_t>(c)];
    if (settings.scheme == DomScheme::paper) {
      x = transport.paper(channel, first, warm_fits ? &warm->moments[static_cast<size_t>(c)] : nullptr, settings, out.iterations,
                          out.changes);
      continue;
    }
    const IterationProgress progress{settings, c, out.channels, out.iterations};
    if (warm_fits && settings.accelerator == DomAccelerator::none) {
      // Source iteration from the warm moments, x <- b + K x, each sweep with the first-collision
      // source in it (forming b apart would take one more). With the diamond's fix-up, b apart
      // (its sweep sets the marks, as in a cold solve), unless fold_first_collision sets them in
      // the sweeps of b + K x (DomSettings).
      // A spare buffer of `size` floats, its contents undefined (the sweeps write all of it).
      const auto take = [&] {
        std::vector<float> v;
        if (spare && !spare->empty()) v = std::move(spare->back()), spare->pop_back();
        v.resize(size);
        return v;
      };
      x = take();
      std::copy(warm->moments[static_cast<size_t>(c)].begin(), warm->moments[static_cast<size_t>(c)].end(), x.begin());
      std::vector<float> next = take(), b;
      channel.mark_with_moments = channel.bounded && settings.fold_first_collision;
      if (channel.bounded && !settings.fold_first_collision) {
        b.resize(size);
        transport.sweep(channel, &first, nullptr, channel.sky, b.data(), settings.threads, entering);
        ++out.iterations;
      }
      while (out.iterations - progress.start < settings.max_iterations + (b.empty() ? 0 : 1)) {
        if (b.empty()) {
          transport.sweep(channel, &first, x.data(), channel.sky, next.data(), settings.threads, entering);
        } else {
          transport.sweep(channel, nullptr, x.data(), 0.0f, next.data(), settings.threads);
          axpy(next, 1.0, b, settings.threads);
        }
        ++out.iterations;
        if (dsa) dom::diffusion_correction(volume.density, channel, out.terms(), q0, x, next, settings.threads);
        axpy(x, -1.0, next, settings.threads);
        const double change = norm(x, settings.threads, nullptr) / std::max(norm(next, settings.threads, nullptr), 1e-300);
        x.swap(next);
        out.changes.push_back(change);
        progress(out.iterations);
        if (change < settings.tolerance) break;
      }
      if (spare) spare->push_back(std::move(next));
      continue;
    }
    std::vector<float> b(size);
    transport.sweep(channel, &first, nullptr, channel.sky, b.data(), settings.threads, entering);
    ++out.iterations;
    first = {};
    bool from_channel = false;
    if (warm_fits) {
      x = warm->moments[static_cast<size_t>(c)];
    } else if ((from_channel = c > 0 && previous_source > 0.0)) {
      // The channels differ by a few percent in sigma_t and in the lights' colour: the previous
      // channel's moments, scaled as its source projects onto them, start close.
      x = out.moments[static_cast<size_t>(c - 1)];
      const double scale = dot(b, x, settings.threads, settings.exchange) / previous_source;
      for (float& m : x) m *= static_cast<float>(scale);
    } else if (settings.accelerator == DomAccelerator::gmres) {
      // GMRES from 0: the first residual is b, no sweep, and the Krylov space it builds holds what
      // a start from b reaches in as many sweeps.
      x.assign(size, 0.0f);
    } else {
      x = b;
    }
    // A channel started from the previous one's moments keeps some of that start's slow (diffusive)
    // error, which the residual shows only times (1 - albedo): half the tolerance for it (the
    // particle cloud at 48^3: 0.592% at the full tolerance, 0.580% at half, 0.576% converged).
    solve_moments(transport, channel, b, x, settings, progress, out, from_channel ? 0.5 * settings.tolerance : settings.tolerance,
                  dsa ? &volume.density : nullptr, q0);
    previous_source = dot(b, x, settings.threads, settings.exchange);
  }
  out.converged = !out.changes.empty() && out.changes.back() < settings.tolerance;
  out.sweep_seconds = transport.seconds();
  out.skipped_fraction = transport.skipped_fraction();
  out.seconds = start.seconds();
  return out;
}

Eigen::VectorXd inscatter_weights(const DomSolution& solution, const Vec3& w) {
  return solution.separable->basis().transpose() * solution.matrix->row(w);
}

void inscatter_weights(const DomSolution& solution, const Vec3& w, Eigen::VectorXd& row, Eigen::VectorXd& out) {
  solution.matrix->row(w, row);
  out.resize(solution.separable->basis().cols());
  out.noalias() = solution.separable->basis().transpose() * row;
}

}  // namespace haze::grids
