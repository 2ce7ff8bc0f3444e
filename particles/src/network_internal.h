// Internal: the pieces of the network that a full build (network.cpp) and an update of moved
// particles (network_update.cpp) share.
#pragma once

#include <haze/particles/network.h>

#include <array>
#include <cmath>
#include <utility>
#include <vector>

namespace haze::particles::network_internal {

// Direction w's view of the window: a particle's pixel (its column) and its depth along w.
struct Projector {
  Vec3 c, w, t1, t2;
  double r;
  int m;
  Projector(const NetworkWindow& window, const Vec3& direction);
  int pixel(const Vec3& x) const;
  double depth(const Vec3& x) const { return glm::dot(x - c, w); }
};

// A column's particles as (depth, index): sorted by depth (ties by index), written to `out` in
// upstream-first order, and each linked to the one before it: V's upstream ([p], -1 for the
// first) and the gap's density integral (the trapezoid of rho at both ends).
void link_column(std::vector<std::pair<double, int>>& members, int* out, int* upstream, float* depth, const std::vector<float>& rho);

// The density integral over the gap between particles at depths `upstream` and `p` along a
// direction: the trapezoid of rho at both ends.
inline float gap_depth(float rho_p, float rho_upstream, double p, double upstream) {
  return static_cast<float>(0.5 * (static_cast<double>(rho_p) + static_cast<double>(rho_upstream)) * (p - upstream));
}

// exp(-sigma_t depth) over a particle's gap, or -1 where nothing is upstream (the sweep's marker).
inline float gap_transmittance(double sigma_t, int upstream, float depth) {
  return upstream < 0 ? -1.0f : static_cast<float>(std::exp(-sigma_t * static_cast<double>(depth)));
}

// Where a particle's direct light is sampled: its Gaussian's 2-point Gauss-Hermite nodes per axis,
// x +- h / sqrt(2).
std::array<Vec3, 8> gaussian_nodes(const Vec3& x, double h);

// The delta lights of `lights` (point, spot, directional), and the sky radiance summed.
std::vector<const Light*> delta_lights(const std::vector<Light>& lights, Rgb& sky);

// Whether the medium, its emission, the sky and every light are grey (one channel serves three).
bool grey_scene(const MaterialDesc& material, const Emission& emission, const Rgb& sky, const std::vector<const Light*>& delta);

// s.emitted from s.emission and s.rho.
void emission_source(NetworkSolution& s, const ParticleField& field);

// S[c][i * n + p] for the listed particles p from the solution's light maps:
// the direct light scattered into each direction, per unit albedo, overwriting what was there.
void direct_light(NetworkSolution& s, const ParticleField& field, const std::vector<const Light*>& delta, const std::vector<int>& particles,
                  int threads);

// The transmittance of every gap in sweep order, per solved channel, from V.
void all_transmittance(NetworkSolution& s, const MaterialDesc& material, int threads);

// Iterates from s.incoming until the change is under the tolerance or the iterations run out.
void iterate(NetworkSolution& s, const NetworkSettings& settings);

// What update_network compares the next frame against.
void remember(NetworkSolution& s, const ParticleField& field, const std::vector<const Light*>& delta);

}  // namespace haze::particles::network_internal
