// The networks of moved particles, updated where the particles changed (network.h, update_network).
#include <haze/core/error.h>
#include <haze/core/stopwatch.h>
#include <haze/particles/network.h>

#include "network_internal.h"

#include <algorithm>

namespace haze::particles {

using namespace network_internal;

NetworkSolution update_network(NetworkSolution s, const ParticleField& field, const std::vector<Light>& lights, const NetworkSettings& settings) {
  const MaterialDesc& material = field.particles().material;
  const size_t n = field.size();
  const auto rebuild = [&](const char* reason) {
    NetworkSolution out = solve_network(field, lights, settings, &s, s.surfaces, s.emission);
    out.update.rebuilt = true, out.update.reason = reason;
    return out;
  };
  Rgb sky;
  const std::vector<const Light*> delta = delta_lights(lights, sky);
  if (n != s.gaussians.size() || static_cast<int>(n) != s.visibility.particles) return rebuild("the particle count changed");
  if (!s.directions || settings.directions != s.directions->size()) return rebuild("D changed");
  if (settings.window != 0 && settings.window != s.visibility.window.size) return rebuild("M changed");
  if (settings.terms != 0 && std::min(settings.terms, settings.directions) != s.terms) return rebuild("the separable terms changed");
  if (material.sigma_t != s.sigma_t || material.albedo != s.albedo) return rebuild("the extinction or the albedo changed");
  if ((grey_scene(material, s.emission, sky, delta) ? 1 : 3) != s.channels) return rebuild("the lights' colours changed the channel count");

  Stopwatch start;
  NetworkSolution::Update& u = s.update;
  u = {};
  std::vector<int> changed;
  std::vector<Gaussian> before, after;
  for (size_t p = 0; p < n; ++p) {
    const Gaussian now{field.position(p), field.h(p), field.weight(p)};
    const Gaussian& then = s.gaussians[p];
    if (now.x == then.x && now.h == then.h && now.w == then.w) continue;
    changed.push_back(static_cast<int>(p)), before.push_back(then), after.push_back(now);
  }
  u.changed = changed.size();
  if (4 * changed.size() > n) return rebuild("more than a quarter of the Gaussians changed");
  const NetworkWindow& window = s.visibility.window;
  for (const Gaussian& g : after)
    if (glm::length(g.x - window.centre) > window.radius) return rebuild("a particle left the window's sphere");

  // rho at every particle within a changed Gaussian's support, old or new.
  std::vector<char> moved(n, 0), dense(n, 0);
  std::vector<size_t> near;
  for (size_t k = 0; k < changed.size(); ++k) {
    moved[static_cast<size_t>(changed[k])] = before[k].x != after[k].x;
    for (const Gaussian& g : {before[k], after[k]}) {
      const std::vector<size_t> found = field.within(g.x, kCut * g.h * (1.0 + 1e-6));
      near.insert(near.end(), found.begin(), found.end());
    }
    near.push_back(static_cast<size_t>(changed[k]));
  }
  std::sort(near.begin(), near.end());
  near.erase(std::unique(near.begin(), near.end()), near.end());
  std::vector<float> rho(near.size());
  parallel_for(static_cast<long long>(near.size()), settings.threads, 64, [&](long long q0, long long q1) {
    for (auto q = static_cast<size_t>(q0); q < static_cast<size_t>(q1); ++q) rho[q] = static_cast<float>(field.density(field.position(near[q])));
  });
  for (size_t q = 0; q < near.size(); ++q) {
    if (rho[q] == s.rho[near[q]]) continue;
    s.rho[near[q]] = rho[q], dense[near[q]] = 1, ++u.density;
  }

  // In each direction, the columns a moved particle left or entered are sorted and linked again;
  // the others are copied to their new place in the sweep order, with the gaps of particles whose
  // rho (or whose upstream particle's rho) changed integrated again.
  VisibilityNetwork& v = s.visibility;
  const auto d = static_cast<size_t>(v.directions);
  const size_t pixels = static_cast<size_t>(window.size) * static_cast<size_t>(window.size);
  const auto channels = static_cast<size_t>(s.channels);
  std::vector<size_t> dirty_columns(d, 0);
  parallel_for(static_cast<long long>(d), settings.threads, 1, [&](long long i0, long long i1) {
    std::vector<char> dirty(pixels);
    std::vector<std::pair<int, int>> entering;  // (pixel, particle)
    std::vector<std::pair<double, int>> members;
    std::vector<int> order(n), column(pixels + 1);
    std::array<std::vector<float>, 3> t;
    for (size_t c = 0; c < channels; ++c) t[c].resize(n);
    for (auto i = static_cast<size_t>(i0); i < static_cast<size_t>(i1); ++i) {
      const Projector project(window, (*s.directions)[static_cast<int>(i)]);
      std::fill(dirty.begin(), dirty.end(), 0);
      entering.clear();
      for (size_t k = 0; k < changed.size(); ++k) {
        if (!moved[static_cast<size_t>(changed[k])]) continue;
        const int to = project.pixel(after[k].x);
        dirty[static_cast<size_t>(project.pixel(before[k].x))] = dirty[static_cast<size_t>(to)] = 1;
        entering.emplace_back(to, changed[k]);
      }
      std::sort(entering.begin(), entering.end());
      const size_t base = i * n;
      const int* old_start = v.column_start.data() + i * (pixels + 1);
      const int* old_order = v.order.data() + base;
      int cursor = 0;
      size_t e = 0;
      for (size_t b = 0; b < pixels; ++b) {
        column[b] = cursor;
        const int first = old_start[b], last = old_start[b + 1];
        if (!dirty[b]) {
          for (int k = first; k < last; ++k, ++cursor) {
            const auto p = static_cast<size_t>(old_order[k]), c_at = static_cast<size_t>(cursor);
            order[c_at] = old_order[k];
            const int up = v.upstream[base + p];
            if (up >= 0 && (dense[p] || dense[static_cast<size_t>(up)])) {
              const auto q = static_cast<size_t>(up);
              v.depth[base + p] = gap_depth(s.rho[p], s.rho[q], project.depth(field.position(p)), project.depth(field.position(q)));
              for (size_t c = 0; c < channels; ++c) t[c][c_at] = gap_transmittance(material.sigma_t[static_cast<int>(c)], up, v.depth[base + p]);
            } else {
              for (size_t c = 0; c < channels; ++c) t[c][c_at] = s.transmittance[c][base + static_cast<size_t>(k)];
            }
          }
          continue;
        }
        ++dirty_columns[i];
        members.clear();
        for (int k = first; k < last; ++k)
          if (!moved[static_cast<size_t>(old_order[k])]) members.emplace_back(project.depth(field.position(static_cast<size_t>(old_order[k]))), old_order[k]);
        for (; e < entering.size() && entering[e].first == static_cast<int>(b); ++e)
          members.emplace_back(project.depth(field.position(static_cast<size_t>(entering[e].second))), entering[e].second);
        link_column(members, order.data() + cursor, v.upstream.data() + base, v.depth.data() + base, s.rho);
        for (size_t k = 0; k < members.size(); ++k) {
          const size_t at = base + static_cast<size_t>(order[static_cast<size_t>(cursor) + k]);
          for (size_t c = 0; c < channels; ++c)
            t[c][static_cast<size_t>(cursor) + k] = gap_transmittance(material.sigma_t[static_cast<int>(c)], v.upstream[at], v.depth[at]);
        }
        cursor += static_cast<int>(members.size());
      }
      column[pixels] = cursor;
      std::copy(order.begin(), order.end(), v.order.begin() + static_cast<long>(base));
      std::copy(column.begin(), column.end(), v.column_start.begin() + static_cast<long>(i * (pixels + 1)));
      for (size_t c = 0; c < channels; ++c) std::copy(t[c].begin(), t[c].end(), s.transmittance[c].begin() + static_cast<long>(base));
    }
  });
  size_t dirty_total = 0;
  for (const size_t c : dirty_columns) dirty_total += c;
  u.columns = d && pixels ? static_cast<double>(dirty_total) / static_cast<double>(d * pixels) : 0.0;
  s.build_seconds = start.seconds();

  // Depth maps: the old Gaussians out, the new ones in; a light that moved gets a new map. Then
  // the direct light of every particle that reads a changed texel.
  start.restart();
  bool all_direct = delta.size() != s.light_maps.size();
  if (all_direct) {
    s.light_maps.clear();
    for (const Light* l : delta) s.light_maps.emplace_back(field, *l, settings.threads);
    u.maps = static_cast<int>(delta.size());
  } else {
    for (size_t l = 0; l < delta.size(); ++l)
      if (!(s.lights[l] == *delta[l]) || !s.light_maps[l].update(before, after, settings.threads)) {
        s.light_maps[l] = LightDepthMap(field, *delta[l], settings.threads);
        ++u.maps, all_direct = true;
      }
  }
  std::vector<char> lit(n, all_direct ? 1 : 0);
  for (const int p : changed) lit[static_cast<size_t>(p)] = 1;
  if (!all_direct)
    parallel_for(static_cast<long long>(n), settings.threads, 256, [&](long long p0, long long p1) {
      for (auto p = static_cast<size_t>(p0); p < static_cast<size_t>(p1); ++p) {
        if (lit[p]) continue;
        const Vec3 x = field.position(p);
        const std::array<Vec3, 8> nodes = gaussian_nodes(x, field.h(p));
        for (const LightDepthMap& map : s.light_maps)
          if (map.touched(x) || std::any_of(nodes.begin(), nodes.end(), [&](const Vec3& y) { return map.touched(y); })) lit[p] = 1;
      }
    });
  std::vector<int> relight;
  for (size_t p = 0; p < n; ++p)
    if (lit[p]) relight.push_back(static_cast<int>(p));
  direct_light(s, field, delta, relight, settings.threads);
  u.direct = relight.size();
  s.sky = sky;
  s.direct_seconds = start.seconds();

  start.restart();
  emission_source(s, field);
  iterate(s, settings);
  s.iterate_seconds = start.seconds();
  remember(s, field, delta);
  return s;
}

}  // namespace haze::particles
