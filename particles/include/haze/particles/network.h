// Multiple scattering in particle media by illumination networks (seed 001, Szirmay-Kalos et al.):
// for D global directions, each particle's upstream particle (the visibility network V), the light
// arriving at each particle from each direction (the illumination network I), iterated to
// convergence; camera rays then gather each particle's scattered radiance through its splat.
//
// Past the paper: V stores the optical depth of the gap between a particle and its upstream one,
// taken from the particles' continuous density (field.h), so the network and the reference path
// tracer solve the same medium; each iteration sweeps every direction's columns in upstream order
// (light crosses the volume in one iteration, not one particle per iteration); direct light is
// attenuated by the continuous density (light_depth.h), not binary visibility, and evaluated along
// camera rays by the exact march (NetworkRender), not only at particle centres; a splat's
// opacity along each pixel's ray is the exact line integral of the particle's Gaussian.
#pragma once

#include <haze/core/directions.h>
#include <haze/core/light.h>
#include <haze/core/method.h>
#include <haze/core/phase_matrix.h>
#include <haze/particles/field.h>
#include <haze/particles/light_depth.h>

#include <memory>
#include <string>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::particles {

// The window particles are projected onto for each direction: M x M pixels over the sphere
// (centre, radius), which holds every particle.
struct NetworkWindow {
  int size = 1;
  Vec3 centre{0.0};
  double radius = 0.0;
};

// V[p, i] over D directions: for direction i (propagation direction w_i), particles are projected
// orthographically onto the window, binned per pixel and sorted by depth along w_i (the paper's
// depth peeling, on the CPU); each particle's upstream particle is the previous one in its pixel's
// column. Built threaded over directions.
struct VisibilityNetwork {
  int particles = 0, directions = 0;
  NetworkWindow window;
  std::vector<int> upstream;   // [i * particles + p]: the particle light comes from, or -1 (sky)
  std::vector<float> depth;    // [i * particles + p]: integral of rho over the gap from upstream to p
  std::vector<int> order;      // [i * particles + k]: particles of direction i in upstream-first order
  std::vector<int> column_start;  // [i * (M^2 + 1) + c]: where pixel c's column starts in direction i's order
};

// M from the paper's rule (section 3.2) would leave most columns with one particle at a thousand
// particles; Haze picks the window so that a column's mean gap is the mean particle diameter:
// M = sqrt(N mean(delta_s) / (2 R)), at least 1.
int default_window(const ParticleField& field);
// An M x M window over the field's bounding sphere (M = size).
NetworkWindow network_window(const ParticleField& field, int size);
// rho: the continuous density at each particle (ParticleField::density_at_particles).
VisibilityNetwork build_visibility(const ParticleField& field, const std::vector<float>& rho, const DirectionSet& directions,
                                   const NetworkWindow& window, int threads);

struct NetworkSettings {
  int directions = 128;   // D, spherical Fibonacci
  int window = 0;         // M; 0: default_window
  int max_iterations = 200;  // 0: single scattering only
  // In-scattering through the phase matrix's N largest eigenpairs (core's SeparablePhase, seed 000
  // eq. 8) in O(D N) per particle: 0 keeps those of |lambda| >= 0.01 (16 for HG g = 0.3) and uses
  // the full O(D^2) matrix when that would be more than D / 4; N = D is the full matrix.
  int terms = 0;
  double tolerance = 1e-3;  // relative L2 change of I between iterations
  int threads = 0;
  ProgressCallback progress;
  std::size_t max_memory = 0;  // bytes the networks and light maps may take (RenderOptions::max_memory); 0: what is available
};

struct NetworkSolution {
  std::shared_ptr<const DirectionSet> directions;
  std::shared_ptr<const PhaseMatrix> matrix;
  VisibilityNetwork visibility;
  std::vector<float> rho;                 // the continuous density at each particle
  // The medium's emission (docs/SCENES.md, "medium.emission") where the particles are: per channel, each
  // particle's source function L_e / (sigma_t rho) at its centre (exact where L_e follows the
  // density: strength color / sigma_t), added to the gaps' source in the iteration and to what
  // each particle sends to the eye; empty when the medium does not emit.
  Emission emission;
  std::array<std::vector<float>, 3> emitted;
  // 1 when the medium and every light are grey (one solve serves all three), else 3.
  int channels = 3;
  std::array<std::vector<float>, 3> incoming;  // I per channel, [i * particles + p] (all three filled)
  std::vector<LightDepthMap> light_maps;  // per delta light l, in the scene's order (sky lights skipped)
  std::vector<Surface> surfaces;          // what shadows the particles' direct light (solve_network's)
  // The iteration's state (iterate_network): S, the direct light scattered into each direction per
  // unit albedo, and each gap's transmittance in sweep order ([i * particles + k] for the k-th
  // particle of visibility.order, -1 where no particle is upstream), per solved channel; the product
  // J = I A (B): A = P^T, or A = Q and B = diag(lambda) Q^T with `terms` eigenpairs.
  std::array<std::vector<float>, 3> source, transmittance;
  Eigen::MatrixXf scatter_a, scatter_b;
  std::vector<float> inscattered;         // J of the last channel iterated: kept so iterations reuse the memory
  int terms = 0;                          // eigenpairs used, or D for the full matrix
  Rgb albedo{0.0}, sky{0.0};
  int iterations = 0;
  bool converged = false;
  std::vector<double> changes;
  double build_seconds = 0.0, direct_seconds = 0.0, iterate_seconds = 0.0;  // direct: the light maps and E
  // What the networks were built for, so that update_network can tell what changed: each
  // particle's Gaussian, the delta lights, the extinction.
  std::vector<Gaussian> gaussians;
  std::vector<Light> lights;
  Rgb sigma_t{0.0};
  // What the last update_network did.
  struct Update {
    bool rebuilt = false;   // everything built again; `reason` says why
    std::string reason;
    size_t changed = 0;     // Gaussians moved, resized or re-weighted
    size_t density = 0;     // particles whose rho changed
    size_t direct = 0;      // particles whose direct light was computed again
    double columns = 0.0;   // fraction of the columns sorted again, over all directions
    int maps = 0;           // light depth maps built again (the others were updated in place)
  } update;
};

// `warm` (same particles and directions) starts from its I. `surfaces` shadow the direct light at
// the particles (at each point of their Gaussians' quadrature). `emission`: the medium's (a
// channel whose sigma_t is 0 emits nothing here).
NetworkSolution solve_network(const ParticleField& field, const std::vector<Light>& lights, const NetworkSettings& settings,
                              const NetworkSolution* warm = nullptr, const std::vector<Surface>& surfaces = {}, const Emission& emission = {});
// One iteration of the network (every direction swept once, threaded over directions; the
// in-scattering product threaded over particles): updates solution.incoming for the solved
// channels and returns the relative L2 change of I. solve_network calls it until converged.
double iterate_network(NetworkSolution& solution, int threads);

// The next frame of a simulation: the same particles, in the same order, some moved, resized or
// re-weighted, and the lights, moved or not. `field` is the field over the new positions;
// `previous` the last frame's solution (moved in: its arrays are reused). Instead of building
// everything again, only what the changed Gaussians reach is redone:
// - rho at the particles within their supports (old and new);
// - in each direction, the columns a moved particle left or entered (sorted and linked again, with
//   their transmittance); the other columns are copied, their gaps integrated again only where rho
//   changed at either end;
// - each light's depth map, by subtracting the old Gaussians and adding the new ones;
// - the direct light of the particles whose depth-map texels changed;
// then iterates from the previous I. The result is the network a full build with the previous
// window would give (rho, V and the transmittance to float rounding). Everything is rebuilt (and
// `update.reason` says why) when the particle count, D, M, the extinction or albedo changed, more
// than a quarter of the Gaussians changed, or a changed one left the window's sphere; a light's
// map alone is rebuilt when that light moved or a Gaussian left its map. Same settings as
// solve_network; the phase function is assumed unchanged.
NetworkSolution update_network(NetworkSolution previous, const ParticleField& field, const std::vector<Light>& lights,
                               const NetworkSettings& settings);

// How camera rays gather the particles' light (render_network):
// - splat, the paper's (seed 001 section 3.4): each particle's radiance toward the eye (its
//   scattered light and the direct light at its centre) composited front to back in the order of
//   the particles' distances from the eye, with its opacity along each ray (splat.h);
// - march: the formal solution through the overlapping Gaussians, front to back in steps of at most
//   half the narrowest active width (each step's optical depth exact, its source the particles'
//   radiance weighted by their share of it), the single-scattered direct light from the depth maps
//   at every step's middle with the exact phase function.
// Both add the background (plus any sky) through what is left; surfaces are lit as the method's
// handles say. docs/NETWORKS.md gives both errors and costs.
enum class NetworkRender { splat, march };

Image render_network(const Scene& scene, const ParticleField& field, const NetworkSolution& solution, const RenderOptions& options = {},
                     NetworkRender render = NetworkRender::splat);
// The same for `view`: its camera (one eye: per-pixel rays are refused), its depth ending the
// rays, and with view.layers L_in, T and C per pixel.
RenderResult render_network(const Scene& scene, const ParticleField& field, const NetworkSolution& solution, const RenderOptions& options,
                            const View& view, NetworkRender render = NetworkRender::splat);

// Method "network": its settings, what it handles and its auto rule.
MethodInfo network_info();

}  // namespace haze::particles

#pragma GCC visibility pop
