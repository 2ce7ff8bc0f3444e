// Multiple scattering in particle media by illumination networks (seed 001, Szirmay-Kalos et al.):
// for D global directions, each particle's upstream particle (the visibility network V), the light
// arriving at each particle from each direction (the illumination network I), iterated to
// convergence; camera rays then gather each particle's scattered radiance through its splat.
//
// Past the paper: V stores the optical depth of the gap between a particle and its upstream one,
// taken from the particles' continuous density (field.h), so the network and the reference path
// tracer solve the same medium; each iteration sweeps every direction's columns in upstream order
// (light crosses the volume in one iteration, not one particle per iteration); direct light is
// attenuated by the continuous density, not binary visibility; splats are exact line integrals of
// each particle's Gaussian along each pixel's ray.
#pragma once

#include <haze/core/directions.h>
#include <haze/core/light.h>
#include <haze/core/method.h>
#include <haze/core/phase_matrix.h>
#include <haze/particles/field.h>
#include <haze/particles/light_depth.h>

#include <memory>
#include <vector>

namespace haze::particles {

// V[p, i] over D directions: for direction i (propagation direction w_i), particles are projected
// orthographically onto an M x M window over the bounding sphere, binned per pixel and sorted by
// depth along w_i (the paper's depth peeling, on the CPU); each particle's upstream particle is the
// previous one in its pixel's column. Built threaded over directions.
struct VisibilityNetwork {
  int particles = 0, directions = 0, window = 0;
  std::vector<int> upstream;   // [i * particles + p]: the particle light comes from, or -1 (sky)
  std::vector<float> depth;    // [i * particles + p]: integral of rho over the gap from upstream to p
  std::vector<int> order;      // [i * particles + k]: particles of direction i in upstream-first order
};

// M from the paper's rule (section 3.2) would leave most columns with one particle at a thousand
// particles; Haze picks the window so that a column's mean gap is the mean particle diameter:
// M = sqrt(N mean(delta_s) / (2 R)), at least 1.
int default_window(const ParticleField& field);
// rho: the continuous density at each particle (ParticleField::density_at_particles).
VisibilityNetwork build_visibility(const ParticleField& field, const std::vector<float>& rho, const DirectionSet& directions, int window,
                                   int threads);

struct NetworkSettings {
  int directions = 128;   // D, spherical Fibonacci
  int window = 0;         // M; 0: default_window
  int max_iterations = 200;  // 0: single scattering only
  double tolerance = 1e-3;  // relative L2 change of I between iterations
  int threads = 0;
  ProgressCallback progress;
};

struct NetworkSolution {
  std::shared_ptr<const DirectionSet> directions;
  std::shared_ptr<const PhaseMatrix> matrix;
  VisibilityNetwork visibility;
  std::vector<float> rho;                 // the continuous density at each particle
  std::array<std::vector<float>, 3> incoming;  // I per channel, [i * particles + p]
  std::vector<Rgb> direct;                // [l * particles + p]: light l's irradiance at p after extinction
  std::vector<Vec3> to_light;             // [l * particles + p]
  std::vector<LightDepthMap> light_maps;  // per delta light l, in the scene's order (sky lights skipped)
  int iterations = 0;
  bool converged = false;
  std::vector<double> changes;
  double build_seconds = 0.0, direct_seconds = 0.0, iterate_seconds = 0.0;  // direct: the light maps and E
};

// Emission is not modelled. `warm` (same particles and directions) starts from its I.
NetworkSolution solve_network(const ParticleField& field, const std::vector<Light>& lights, const NetworkSettings& settings,
                              const NetworkSolution* warm = nullptr);

// Camera rays through the particles' splats, front to back: each particle scatters
//   albedo (sum_d c_d(w) I[p, d] + sum_lights p(w_light . w) E_l)
// toward the eye, with opacity 1 - exp(-sigma_t tau), tau its Gaussian's integral along the ray;
// then the background (plus any sky) through what is left. Surfaces are not drawn.
Image render_network(const Scene& scene, const ParticleField& field, const NetworkSolution& solution, const RenderOptions& options = {});

std::unique_ptr<Method> make_network_method();

}  // namespace haze::particles
