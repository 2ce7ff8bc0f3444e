// Visibility network, direct light and the illumination-network iteration (seed 001 sections
// 3.1-3.3; network.h says what Haze does past the paper).
#include <haze/core/error.h>
#include <haze/core/stopwatch.h>
#include <haze/particles/network.h>
#include <haze/simd/phase_batch.h>

#include "network_internal.h"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace haze::particles {

namespace network_internal {

Projector::Projector(const NetworkWindow& window, const Vec3& direction) : c(window.centre), w(direction), r(window.radius), m(window.size) {
  const Frame frame = Frame::from_z(w);
  t1 = frame.s, t2 = frame.t;
}

int Projector::pixel(const Vec3& x) const {
  const Vec3 d = x - c;
  const int px = std::clamp(static_cast<int>((glm::dot(d, t1) + r) / (2.0 * r) * m), 0, m - 1);
  const int py = std::clamp(static_cast<int>((glm::dot(d, t2) + r) / (2.0 * r) * m), 0, m - 1);
  return py * m + px;
}

void link_column(std::vector<std::pair<double, int>>& members, int* out, int* upstream, float* depth, const std::vector<float>& rho) {
  std::sort(members.begin(), members.end());
  for (size_t k = 0; k < members.size(); ++k) {
    const auto p = static_cast<size_t>(members[k].second);
    out[k] = members[k].second;
    if (k == 0) {
      upstream[p] = -1, depth[p] = 0.0f;
      continue;
    }
    const auto [up_depth, up] = members[k - 1];
    upstream[p] = up;
    depth[p] = gap_depth(rho[p], rho[static_cast<size_t>(up)], members[k].first, up_depth);
  }
}

std::array<Vec3, 8> gaussian_nodes(const Vec3& x, double h) {
  std::array<Vec3, 8> nodes;
  for (int corner = 0; corner < 8; ++corner)
    nodes[static_cast<size_t>(corner)] = x + h * std::sqrt(0.5) * Vec3((corner & 1) ? 1.0 : -1.0, (corner & 2) ? 1.0 : -1.0, (corner & 4) ? 1.0 : -1.0);
  return nodes;
}

std::vector<const Light*> delta_lights(const std::vector<Light>& lights, Rgb& sky) {
  std::vector<const Light*> delta;
  sky = Rgb(0.0);
  for (const Light& l : lights) {
    if (const auto* s = std::get_if<SkyLight>(&l)) sky += s->radiance;
    else delta.push_back(&l);
  }
  return delta;
}

bool grey_scene(const MaterialDesc& material, const Emission& emission, const Rgb& sky, const std::vector<const Light*>& delta) {
  return is_grey(material.sigma_t) && is_grey(material.albedo) && is_grey(sky) &&
         (!emission.emits() || (is_grey(emission.color) && emission.blackbody_intensity <= 0.0)) &&
         std::all_of(delta.begin(), delta.end(), [](const Light* l) { return is_grey(*l); });
}

void emission_source(NetworkSolution& s, const ParticleField& field) {
  for (auto& e : s.emitted) e.clear();
  if (!s.emission.emits()) return;
  const Rgb& sigma_t = field.particles().material.sigma_t;
  const size_t n = field.size();
  for (auto& e : s.emitted) e.assign(n, 0.0f);
  for (size_t p = 0; p < n; ++p) {
    const double rho = s.rho[p];
    if (!(rho > 0.0)) continue;
    const Rgb le = emitted_radiance(s.emission, field.position(p), rho);
    for (int c = 0; c < 3; ++c)
      if (sigma_t[c] > 0.0) s.emitted[static_cast<size_t>(c)][p] = static_cast<float>(le[c] / (sigma_t[c] * rho));
  }
}

// Direct light at each particle, attenuated by the continuous density (a depth map per light);
// a light inside a particle gives it the irradiance at a quarter of its diameter, no more.
void direct_light(NetworkSolution& s, const ParticleField& field, const std::vector<const Light*>& delta, const std::vector<int>& particles,
                  int threads) {
  const MaterialDesc& material = field.particles().material;
  const DirectionSet& dirs = *s.directions;
  const auto n = field.size(), d = static_cast<size_t>(dirs.size()), channels = static_cast<size_t>(s.channels);
  // Blocks of kBlock particles: their sources into `block` ([c][i][k], direction-major), then
  // written to s.source ([c][i * n + p]) a run of kBlock at a time where the block's particles
  // are consecutive (one cache line per direction, not kBlock scattered stores each).
  constexpr size_t kBlock = 16;
  const auto body = [&](long long q0, long long q1) {
    thread_local std::vector<float> kept_cosines, kept_phase, kept_block;
    std::vector<float>&cosines = kept_cosines, &phase = kept_phase, &block = kept_block;
    cosines.resize(d), phase.resize(d);
    for (auto b0 = static_cast<size_t>(q0); b0 < static_cast<size_t>(q1); b0 += kBlock) {
      const size_t count = std::min(kBlock, static_cast<size_t>(q1) - b0);
      block.assign(channels * d * kBlock, 0.0f);
      for (size_t k = 0; k < count; ++k) {
        const auto p = static_cast<size_t>(particles[b0 + k]);
        const Vec3 x = field.position(p);
        const double nearest = 0.25 * field.h(p);
        for (size_t l = 0; l < delta.size(); ++l) {
          const LightDepthMap& map = s.light_maps[l];
          LightArrival a;
          if (!arrival(*delta[l], x, a)) continue;
          Rgb e(0.0);
          if (a.distance > 0.0) {
            // The particle's share of the light: E averaged over its Gaussian (2-point Gauss-Hermite
            // per axis), not E at its centre, which misses the light its fringe gets near lit edges.
            for (const Vec3& node : gaussian_nodes(x, field.h(p))) {
              LightArrival at;
              if (map.arrival(node, material.sigma_t, nearest, at) && !occluded(s.surfaces, node, at.to_light, at.distance))
                e += 0.125 * at.irradiance;
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
            float* const to = block.data() + c * d * kBlock + k;
            for (size_t i = 0; i < d; ++i) to[i * kBlock] += scale * phase[i];
          }
        }
      }
      const auto first = static_cast<size_t>(particles[b0]);
      const bool run = static_cast<size_t>(particles[b0 + count - 1]) - first == count - 1 &&
                       std::is_sorted(particles.begin() + static_cast<long>(b0), particles.begin() + static_cast<long>(b0 + count));
      for (size_t c = 0; c < channels; ++c)
        for (size_t i = 0; i < d; ++i) {
          const float* from = block.data() + (c * d + i) * kBlock;
          float* const to = s.source[c].data() + i * n;
          if (run) std::copy_n(from, count, to + first);
          else
            for (size_t k = 0; k < count; ++k) to[static_cast<size_t>(particles[b0 + k])] = from[k];
        }
    }
  };
  parallel_for(static_cast<long long>(particles.size()), threads, 16, [&body](long long q0, long long q1) { body(q0, q1); });
}

void all_transmittance(NetworkSolution& s, const MaterialDesc& material, int threads) {
  const VisibilityNetwork& v = s.visibility;
  const auto n = static_cast<size_t>(v.particles), d = static_cast<size_t>(v.directions);
  for (size_t c = 0; c < static_cast<size_t>(s.channels); ++c) {
    auto& t = s.transmittance[c];
    t.resize(n * d);
    const double sigma = material.sigma_t[static_cast<int>(c)];
    parallel_for(static_cast<long long>(d), threads, 1, [&](long long i0, long long i1) {
      for (auto i = static_cast<size_t>(i0); i < static_cast<size_t>(i1); ++i)
        for (size_t k = 0; k < n; ++k) {
          const size_t at = i * n + static_cast<size_t>(v.order[i * n + k]);
          t[i * n + k] = gap_transmittance(sigma, v.upstream[at], v.depth[at]);
        }
    });
  }
}

void iterate(NetworkSolution& s, const NetworkSettings& settings) {
  s.iterations = 0, s.changes.clear();
  while (s.visibility.particles > 0 && s.iterations < settings.max_iterations) {
    s.changes.push_back(iterate_network(s, settings.threads));
    ++s.iterations;
    if (settings.progress && !settings.progress(std::min(1.0, s.iterations / static_cast<double>(settings.max_iterations)))) throw Cancelled();
    if (s.changes.back() < settings.tolerance) break;
  }
  for (auto c = static_cast<size_t>(s.channels); c < 3; ++c) s.incoming[c] = s.incoming[0];
  s.converged = s.visibility.particles == 0 || (!s.changes.empty() && s.changes.back() < settings.tolerance);
}

void remember(NetworkSolution& s, const ParticleField& field, const std::vector<const Light*>& delta) {
  s.gaussians.resize(field.size());
  for (size_t p = 0; p < field.size(); ++p) s.gaussians[p] = {field.position(p), field.h(p), field.weight(p)};
  s.lights.clear();
  for (const Light* l : delta) s.lights.push_back(*l);
  s.sigma_t = field.particles().material.sigma_t;
}

}  // namespace network_internal

using namespace network_internal;

int default_window(const ParticleField& field) {
  if (field.size() == 0 || !(field.radius() > 0.0)) return 1;
  return std::clamp(static_cast<int>(std::lround(std::sqrt(static_cast<double>(field.size()) * field.mean_h() / (2.0 * field.radius())))), 1, 4096);
}

NetworkWindow network_window(const ParticleField& field, int size) {
  if (size < 1 || size > 65536) throw Error("window", to_text(size), "a window resolution M in [1, 65536]");
  // Slightly larger than the bounding sphere, so that every particle lands inside.
  return {size, field.centre(), std::max(field.radius(), 1e-6 * std::max(1.0, glm::length(field.centre()))) * (1.0 + 1e-6)};
}

VisibilityNetwork build_visibility(const ParticleField& field, const std::vector<float>& rho, const DirectionSet& directions,
                                   const NetworkWindow& window, int threads) {
  if (window.size < 1 || window.size > 65536) throw Error("window", to_text(window.size), "a window resolution M in [1, 65536]");
  VisibilityNetwork v;
  const auto n = static_cast<int>(field.size());
  const size_t pixels = static_cast<size_t>(window.size) * static_cast<size_t>(window.size);
  v.particles = n, v.directions = directions.size(), v.window = window;
  const size_t total = static_cast<size_t>(n) * static_cast<size_t>(directions.size());
  v.upstream.assign(total, -1), v.depth.assign(total, 0.0f), v.order.resize(total);
  v.column_start.assign((pixels + 1) * static_cast<size_t>(directions.size()), 0);
  if (n == 0) return v;
  parallel_for(directions.size(), threads, 1, [&](long long i0, long long i1) {
    std::vector<int> key(static_cast<size_t>(n));
    std::vector<std::pair<double, int>> members;
    for (auto i = static_cast<int>(i0); i < i1; ++i) {
      const Projector project(window, directions[i]);
      int* start = v.column_start.data() + static_cast<size_t>(i) * (pixels + 1);
      int* order = v.order.data() + static_cast<size_t>(i) * static_cast<size_t>(n);
      const size_t base = static_cast<size_t>(i) * static_cast<size_t>(n);
      for (int p = 0; p < n; ++p) ++start[(key[static_cast<size_t>(p)] = project.pixel(field.position(static_cast<size_t>(p)))) + 1];
      // Counting sort by pixel, then each column by depth.
      std::partial_sum(start, start + pixels + 1, start);
      std::vector<int> fill(start, start + pixels);
      for (int p = 0; p < n; ++p) order[fill[static_cast<size_t>(key[static_cast<size_t>(p)])]++] = p;
      for (size_t b = 0; b < pixels; ++b) {
        members.clear();
        for (int k = start[b]; k < start[b + 1]; ++k) members.emplace_back(project.depth(field.position(static_cast<size_t>(order[k]))), order[k]);
        link_column(members, order + start[b], v.upstream.data() + base, v.depth.data() + base, rho);
      }
    }
  });
  return v;
}

NetworkSolution solve_network(const ParticleField& field, const std::vector<Light>& lights, const NetworkSettings& settings,
                              const NetworkSolution* warm, const std::vector<Surface>& surfaces, const Emission& emission) {
  if (settings.directions < 8 || settings.directions > 4096)
    throw Error("directions", to_text(settings.directions), "a direction count in [8, 4096]");
  if (settings.max_iterations < 0) throw Error("iterations", to_text(settings.max_iterations), "at least 0 (0: single scattering only)");
  if (!(settings.tolerance > 0.0)) throw Error("tolerance", to_text(settings.tolerance), "a relative change > 0");
  const MaterialDesc& material = field.particles().material;
  NetworkSolution out;
  Stopwatch start;
  out.directions = std::make_shared<DirectionSet>(DirectionSet::fibonacci(settings.directions));
  out.matrix = std::make_shared<PhaseMatrix>(material.phase, *out.directions);
  const auto n = field.size(), d = static_cast<size_t>(out.directions->size());
  // The networks (upstream, depth, order) and per channel the source, incoming radiance and
  // transmittance, plus the in-scattered light: 4 bytes each per particle and direction.
  const std::size_t network_bytes = 4 * n * d * (3 + 1 + 3 * (settings.max_iterations > 0 ? 3 : 1));
  check_memory(network_bytes, settings.max_memory, "particles", to_text(n) + " particles x " + to_text(d) + " directions",
               "fewer particles or directions");
  out.rho = field.density_at_particles(settings.threads);
  out.visibility = build_visibility(field, out.rho, *out.directions, network_window(field, settings.window ? settings.window : default_window(field)),
                                    settings.threads);
  out.build_seconds = start.seconds();

  start.restart();
  const std::vector<const Light*> delta = delta_lights(lights, out.sky);
  // A map is at most 64 MB: checked as they are made, against the budget before the first (the
  // memory available falls as the maps take it).
  const std::size_t budget = memory_budget(settings.max_memory);
  std::size_t map_bytes = 0;
  for (const Light* l : delta) {
    out.light_maps.emplace_back(field, *l, settings.threads);
    map_bytes += out.light_maps.back().bytes();
    if (network_bytes + map_bytes > budget)
      check_memory(network_bytes + map_bytes, budget, "lights", to_text(out.light_maps.size()) + " of " + to_text(delta.size()) +
                   " light depth maps and the networks", "fewer lights, particles or directions");
    if (settings.progress && !settings.progress(0.0)) throw Cancelled();
  }
  out.channels = grey_scene(material, emission, out.sky, delta) ? 1 : 3;
  out.emission = emission;
  emission_source(out, field);
  out.surfaces = surfaces;
  for (size_t c = 0; c < static_cast<size_t>(out.channels); ++c) out.source[c].assign(n * d, 0.0f);
  std::vector<int> all(n);
  std::iota(all.begin(), all.end(), 0);
  direct_light(out, field, delta, all, settings.threads);
  out.direct_seconds = start.seconds();

  // The iteration's state: the in-scattering product, each gap's transmittance, a warm start.
  start.restart();
  out.albedo = material.albedo;
  const int keep = settings.terms > 0 ? std::min(settings.terms, static_cast<int>(d)) : [&] {
    const Eigen::VectorXd eigenvalues = SeparablePhase(*out.matrix, 1).all_eigenvalues();
    int k = 0;
    while (k < eigenvalues.size() && std::abs(eigenvalues[k]) >= 0.01 * std::abs(eigenvalues[0])) ++k;
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
  all_transmittance(out, material, settings.threads);
  const bool warm_fits = warm && warm->visibility.particles == static_cast<int>(n) && warm->directions && warm->directions->size() == out.directions->size();
  for (size_t c = 0; c < static_cast<size_t>(out.channels); ++c)
    out.incoming[c] = warm_fits && !warm->incoming[c].empty() ? warm->incoming[c] : std::vector<float>(n * d, 0.0f);
  iterate(out, settings);
  out.iterate_seconds = start.seconds();
  remember(out, field, delta);
  return out;
}

// Iteration (section 3.3, with DESIGN.md's normalization): for p and direction i with upstream
// v, over the gap's transmittance T = exp(-sigma_t depth),
//   I[p, i] = T I[v, i] + (1 - T) (albedo (J[v, i] + J[p, i]) + e[v] + e[p]) / 2,   J[q, i] = sum_d P[i][d] I[q, d] + S[q, i],
// the formal solution over the gap with its source (in-scattered radiance, and emission's
// e = L_e / sigma_t rho) averaged from both ends; I = sky where no particle is upstream. Columns run in upstream order (Gauss-Seidel along each column).
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
    const float* emitted = s.emitted[c].empty() ? nullptr : s.emitted[c].data();
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
        float up_in = 0.0f, up_j = 0.0f, up_e = 0.0f;
        for (size_t k = 0; k < n; ++k) {
          const auto p = static_cast<size_t>(order[k]);
          const float jp = j_i[p], tp = tk[k], ep = emitted ? emitted[p] : 0.0f;
          const float value = tp < 0.0f ? sky : tp * up_in + (1.0f - tp) * 0.5f * (albedo * (up_j + jp) + up_e + ep);
          const float delta = value - in_i[p];
          change += static_cast<double>(delta * delta), total += static_cast<double>(value * value);
          in_i[p] = value;
          up_in = value, up_j = jp, up_e = ep;
        }
        diff[i] = change, ref[i] = total;
      }
    });
    for (size_t i = 0; i < d; ++i) diff_sum += diff[i], ref_sum += ref[i];
  }
  return ref_sum > 0.0 ? std::sqrt(diff_sum / ref_sum) : 0.0;
}

}  // namespace haze::particles
