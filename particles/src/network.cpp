// Visibility network, direct light and the illumination-network iteration (seed 001 sections
// 3.1-3.3; network.h says what Haze does past the paper).
#include <haze/core/error.h>
#include <haze/particles/network.h>
#include <haze/simd/phase_batch.h>

#include <Eigen/Core>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

namespace haze::particles {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

int default_window(const ParticleField& field) {
  if (field.size() == 0 || !(field.radius() > 0.0)) return 1;
  return std::clamp(static_cast<int>(std::lround(std::sqrt(static_cast<double>(field.size()) * field.mean_h() / (2.0 * field.radius())))), 1, 4096);
}

VisibilityNetwork build_visibility(const ParticleField& field, const std::vector<float>& rho, const DirectionSet& directions, int window,
                                   int threads) {
  if (window < 1 || window > 65536) throw Error("window", to_text(window), "a window resolution M in [1, 65536]");
  VisibilityNetwork v;
  const auto n = static_cast<int>(field.size());
  v.particles = n, v.directions = directions.size(), v.window = window;
  const size_t total = static_cast<size_t>(n) * static_cast<size_t>(directions.size());
  v.upstream.assign(total, -1), v.depth.assign(total, 0.0f), v.order.resize(total);
  if (n == 0) return v;
  // A window slightly larger than the bounding sphere, so that every particle lands inside.
  const double r = std::max(field.radius(), 1e-6 * std::max(1.0, glm::length(field.centre()))) * (1.0 + 1e-6);
  const Vec3 c = field.centre();
  parallel_for(directions.size(), threads, 1, [&](long long i0, long long i1) {
    std::vector<int> key(static_cast<size_t>(n)), sorted(static_cast<size_t>(n));
    std::vector<double> depth(static_cast<size_t>(n));
    std::vector<int> start(static_cast<size_t>(window) * static_cast<size_t>(window) + 1);
    for (auto i = static_cast<int>(i0); i < i1; ++i) {
      const Vec3 w = directions[i];
      const Frame frame = Frame::from_z(w);
      const Vec3 t1 = frame.s, t2 = frame.t;
      std::fill(start.begin(), start.end(), 0);
      for (int p = 0; p < n; ++p) {
        const Vec3 d = field.position(static_cast<size_t>(p)) - c;
        const int px = std::clamp(static_cast<int>((glm::dot(d, t1) + r) / (2.0 * r) * window), 0, window - 1);
        const int py = std::clamp(static_cast<int>((glm::dot(d, t2) + r) / (2.0 * r) * window), 0, window - 1);
        key[static_cast<size_t>(p)] = py * window + px;
        depth[static_cast<size_t>(p)] = glm::dot(d, w);
        ++start[static_cast<size_t>(key[static_cast<size_t>(p)]) + 1];
      }
      // Counting sort by pixel, then by depth (ties by index) within each pixel.
      std::partial_sum(start.begin(), start.end(), start.begin());
      std::vector<int> fill(start.begin(), start.end() - 1);
      for (int p = 0; p < n; ++p) sorted[static_cast<size_t>(fill[static_cast<size_t>(key[static_cast<size_t>(p)])]++)] = p;
      for (size_t b = 0; b + 1 < start.size(); ++b) {
        auto* first = sorted.data() + start[b];
        auto* last = sorted.data() + start[b + 1];
        std::sort(first, last, [&](int a, int q) {
          return depth[static_cast<size_t>(a)] < depth[static_cast<size_t>(q)] || (depth[static_cast<size_t>(a)] == depth[static_cast<size_t>(q)] && a < q);
        });
        for (auto* e = first + 1; e < last; ++e) {
          const auto p = static_cast<size_t>(*e), up = static_cast<size_t>(*(e - 1));
          const size_t at = static_cast<size_t>(i) * static_cast<size_t>(n) + p;
          v.upstream[at] = *(e - 1);
          // The gap's density integral by the trapezoid rule on the continuous density.
          v.depth[at] = static_cast<float>(0.5 * (static_cast<double>(rho[p]) + static_cast<double>(rho[up])) * (depth[p] - depth[up]));
        }
      }
      std::copy(sorted.begin(), sorted.end(), v.order.begin() + static_cast<long>(i) * n);
    }
  });
  return v;
}

NetworkSolution solve_network(const ParticleField& field, const std::vector<Light>& lights, const NetworkSettings& settings,
                              const NetworkSolution* warm) {
  if (settings.directions < 8 || settings.directions > 4096)
    throw Error("directions", to_text(settings.directions), "a direction count in [8, 4096]");
  if (settings.max_iterations < 0) throw Error("iterations", to_text(settings.max_iterations), "at least 0 (0: single scattering only)");
  if (!(settings.tolerance > 0.0)) throw Error("tolerance", to_text(settings.tolerance), "a relative change > 0");
  const MaterialDesc& material = field.particles().material;
  NetworkSolution out;
  auto start = std::chrono::steady_clock::now();
  out.directions = std::make_shared<DirectionSet>(DirectionSet::fibonacci(settings.directions));
  out.matrix = std::make_shared<PhaseMatrix>(material.phase, *out.directions);
  const DirectionSet& dirs = *out.directions;
  const auto n = static_cast<size_t>(field.size()), d = static_cast<size_t>(dirs.size());
  out.rho = field.density_at_particles(settings.threads);
  out.visibility = build_visibility(field, out.rho, dirs, settings.window ? settings.window : default_window(field), settings.threads);
  out.build_seconds = seconds_since(start);

  // Direct light at every particle, attenuated by the continuous density (a depth map per light);
  // a light inside a particle gives it the irradiance at a quarter of its diameter, no more.
  start = std::chrono::steady_clock::now();
  std::vector<const Light*> delta;
  Rgb sky(0.0);
  for (const Light& l : lights) {
    if (const auto* s = std::get_if<SkyLight>(&l)) sky += s->radiance;
    else delta.push_back(&l);
  }
  for (const Light* l : delta) out.light_maps.emplace_back(field, *l, settings.threads);
  const bool grey = is_grey(material.sigma_t) && is_grey(material.albedo) && is_grey(sky) &&
                    std::all_of(delta.begin(), delta.end(), [](const Light* l) { return is_grey(*l); });
  out.channels = grey ? 1 : 3;
  const auto channels = static_cast<size_t>(out.channels);
  auto& source = out.source;  // S[c][i * n + p]: direct light scattered into w_i, per unit albedo
  for (size_t c = 0; c < channels; ++c) source[c].assign(n * d, 0.0f);
  parallel_for(static_cast<long long>(n), settings.threads, 16, [&](long long p0, long long p1) {
    std::vector<float> cosines(d), phase(d);
    for (auto p = static_cast<size_t>(p0); p < static_cast<size_t>(p1); ++p) {
      const Vec3 x = field.position(p);
      const double nearest = 0.25 * field.h(p);
      for (size_t l = 0; l < delta.size(); ++l) {
        const LightDepthMap& map = out.light_maps[l];
        LightArrival a;
        if (!arrival(*delta[l], x, a)) continue;
        Rgb e(0.0);
        if (a.distance > 0.0) {
          // The particle's share of the light: E averaged over its Gaussian (2-point Gauss-Hermite
          // per axis, nodes x +- h / sqrt(2)), not E at its centre, which misses the light its
          // fringe gets near lit edges.
          for (int corner = 0; corner < 8; ++corner) {
            const Vec3 offset((corner & 1) ? 1.0 : -1.0, (corner & 2) ? 1.0 : -1.0, (corner & 4) ? 1.0 : -1.0);
            LightArrival at;
            if (map.arrival(x + field.h(p) * std::sqrt(0.5) * offset, material.sigma_t, nearest, at)) e += 0.125 * at.irradiance;
          }
        } else {  // the light at the centre: no direction; a point light's irradiance at `nearest`
          const auto* point = std::get_if<PointLight>(delta[l]);
          e = point ? point->intensity / (nearest * nearest) * glm::exp(-material.sigma_t * map.depth(x)) : Rgb(0.0);
          a.to_light = Vec3(0.0);
        }
        if (e == Rgb(0.0)) continue;
        for (size_t i = 0; i < d; ++i) cosines[i] = static_cast<float>(-glm::dot(a.to_light, dirs[static_cast<int>(i)]));
        simd::eval_phase(material.phase, cosines.data(), phase.data(), d);
        double sum = 0.0;
        for (size_t i = 0; i < d; ++i) sum += static_cast<double>(phase[i]) * dirs.weight(static_cast<int>(i));
        for (size_t c = 0; c < channels; ++c) {
          const auto scale = static_cast<float>(e[static_cast<int>(c)] / sum);  // quadrature over directions gives back E exactly
          for (size_t i = 0; i < d; ++i) source[c][i * n + p] += scale * phase[i];
        }
      }
    }
  });
  out.direct_seconds = seconds_since(start);

  // The iteration's state: each gap's transmittance, the in-scattering product, a warm start.
  start = std::chrono::steady_clock::now();
  out.albedo = material.albedo, out.sky = sky;
  const int keep = settings.terms > 0 ? std::min(settings.terms, static_cast<int>(d)) : [&] {
    const Eigen::VectorXd all = SeparablePhase(*out.matrix, 1).all_eigenvalues();
    int k = 0;
    while (k < all.size() && std::abs(all[k]) >= 0.01 * std::abs(all[0])) ++k;
    return 4 * k > static_cast<int>(d) ? static_cast<int>(d) : std::max(k, 1);
  }();
  out.terms = keep;
  if (keep >= static_cast<int>(d)) {
    out.scatter_a = out.matrix->matrix().transpose().cast<float>();
  } else {
    const SeparablePhase separable(*out.matrix, keep);
    out.scatter_a = separable.basis().cast<float>();
    out.scatter_b = (separable.eigenvalues().asDiagonal() * separable.basis().transpose()).cast<float>();
  }
  const bool warm_fits = warm && warm->visibility.particles == static_cast<int>(n) && warm->directions && warm->directions->size() == dirs.size();
  for (size_t c = 0; c < channels; ++c) {
    auto& t = out.transmittance[c];
    t.resize(n * d);
    const double sigma = material.sigma_t[static_cast<int>(c)];
    parallel_for(static_cast<long long>(d), settings.threads, 1, [&](long long i0, long long i1) {
      for (auto i = static_cast<size_t>(i0); i < static_cast<size_t>(i1); ++i)
        for (size_t k = 0; k < n; ++k) {
          const size_t at = i * n + static_cast<size_t>(out.visibility.order[i * n + k]);
          t[i * n + k] = out.visibility.upstream[at] < 0 ? -1.0f : static_cast<float>(std::exp(-sigma * static_cast<double>(out.visibility.depth[at])));
        }
    });
    out.incoming[c] = warm_fits ? warm->incoming[c] : std::vector<float>(n * d, 0.0f);
  }
  while (n > 0 && out.iterations < settings.max_iterations) {
    out.changes.push_back(iterate_network(out, settings.threads));
    ++out.iterations;
    if (settings.progress && !settings.progress(std::min(1.0, out.iterations / static_cast<double>(settings.max_iterations))))
      throw Cancelled();
    if (out.changes.back() < settings.tolerance) break;
  }
  for (size_t c = channels; c < 3; ++c) out.incoming[c] = out.incoming[0];
  out.converged = n == 0 || (!out.changes.empty() && out.changes.back() < settings.tolerance);
  out.iterate_seconds = seconds_since(start);
  return out;
}

// Iteration (section 3.3, with DESIGN.md's normalization): for p and direction i with upstream
// v, over the gap's transmittance T = exp(-sigma_t depth),
//   I[p, i] = T I[v, i] + (1 - T) albedo (J[v, i] + J[p, i]) / 2,   J[q, i] = sum_d P[i][d] I[q, d] + S[q, i],
// the formal solution over the gap with its in-scattered radiance averaged from both ends; I = sky
// where no particle is upstream. Columns run in upstream order (Gauss-Seidel along each column).
double iterate_network(NetworkSolution& s, int threads) {
  using Matrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic>;
  using Block = Eigen::Map<Matrix, 0, Eigen::OuterStride<>>;
  const VisibilityNetwork& v = s.visibility;
  const auto n = static_cast<size_t>(v.particles), d = static_cast<size_t>(v.directions);
  std::vector<float>& j = s.inscattered;
  j.resize(n * d);
  std::vector<double> diff(d), ref(d);
  double diff_sum = 0.0, ref_sum = 0.0;
  for (size_t c = 0; c < static_cast<size_t>(s.channels); ++c) {
    std::vector<float>& in = s.incoming[c];
    const std::vector<float>& source = s.source[c];
    const std::vector<float>& t = s.transmittance[c];
    // J = S + I A (B), threaded over blocks of particles (the rows of I and J).
    parallel_for(static_cast<long long>(n), threads, 256, [&](long long p0, long long p1) {
      const auto rows = static_cast<long>(p1 - p0);
      const Eigen::OuterStride<> stride(static_cast<long>(n));
      Block out(j.data() + p0, rows, static_cast<long>(d), stride);
      out = Block(const_cast<float*>(source.data()) + p0, rows, static_cast<long>(d), stride);
      const Block i_block(in.data() + p0, rows, static_cast<long>(d), stride);
      if (s.scatter_b.size() == 0) out.noalias() += i_block * s.scatter_a;
      else out.noalias() += (i_block * s.scatter_a) * s.scatter_b;
    });
    const auto albedo = static_cast<float>(s.albedo[static_cast<int>(c)]), sky = static_cast<float>(s.sky[static_cast<int>(c)]);
    // In sweep order a particle's upstream one is the previous particle of its column (the
    // transmittance is stored in that order, -1 where a column starts), so I and J of the upstream
    // particle are the values just handled.
    parallel_for(static_cast<long long>(d), threads, 1, [&](long long i0, long long i1) {
      for (auto i = static_cast<size_t>(i0); i < static_cast<size_t>(i1); ++i) {
        const size_t base = i * n;
        const int* order = v.order.data() + base;
        const float* tk = t.data() + base;
        float* in_i = in.data() + base;
        const float* j_i = j.data() + base;
        double change = 0.0, total = 0.0;
        float up_in = 0.0f, up_j = 0.0f;
        for (size_t k = 0; k < n; ++k) {
          const auto p = static_cast<size_t>(order[k]);
          const float jp = j_i[p], tp = tk[k];
          const float value = tp < 0.0f ? sky : tp * up_in + (1.0f - tp) * albedo * 0.5f * (up_j + jp);
          const float delta = value - in_i[p];
          change += static_cast<double>(delta * delta), total += static_cast<double>(value * value);
          in_i[p] = value;
          up_in = value, up_j = jp;
        }
        diff[i] = change, ref[i] = total;
      }
    });
    for (size_t i = 0; i < d; ++i) diff_sum += diff[i], ref_sum += ref[i];
  }
  return ref_sum > 0.0 ? std::sqrt(diff_sum / ref_sum) : 0.0;
}

}  // namespace haze::particles
