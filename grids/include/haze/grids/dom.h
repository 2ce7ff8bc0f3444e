// Multiple scattering on grids by discrete ordinates (seed 000, Gong et al.): diffuse radiance over
// D directions in every cell, iterated to convergence, the in-scattering integral taken through the
// N-term separable factorization of the phase matrix (core's SeparablePhase; N = D is the full
// matrix). Lights enter as a first-collision source from the exact optical depth to each light, so
// point lights show no ray effects; the solver carries only light scattered at least once.
#pragma once

#include <cstdint>
#include <unordered_map>

#include <haze/core/light.h>
#include <haze/core/method.h>
#include <haze/core/names.h>
#include <haze/core/phase_matrix.h>
#include <haze/core/progress.h>
#include <haze/grids/optical_depth.h>
#include <haze/grids/propagation.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::grids {

enum class DomScheme {
  // Seed 000 eq. 7/9: every cell updates from its upwind neighbours' previous values (Jacobi), so
  // radiance moves one cell per iteration. The cell's own attenuation is implicit, as in `sweep`,
  // so both schemes converge to the same discrete solution and the paper's one is stable at any
  // optical thickness per cell.
  paper,
  // Source iteration: per iteration one upwind transport sweep per direction (Gauss-Seidel in
  // space), so light crosses the whole grid in one iteration; only the N moments of the previous
  // iteration are kept (flux-moment form of SN codes).
  sweep,
};
inline constexpr Named<DomScheme> kDomSchemes[] = {{DomScheme::paper, "paper"}, {DomScheme::sweep, "sweep"}};
DomScheme dom_scheme_from_name(const std::string& name);
const char* name(DomScheme scheme);

// How a cell's radiance leaves through its faces in scheme `sweep` (simd/dom_sweep.h).
enum class DomSpatial {
  step,     // seed 000: every face leaves with the cell's mean; first order in the cell size
  // Weighted diamond difference, its weight following the cell's optical thickness: second order;
  // the positivity bound only in the cells (per octant) where the first-collision sweep would send
  // radiance below 0 (the fix-up).
  diamond,
  // The same with the positivity bound in every cell: first order on oblique directions, whose
  // numerical diffusion damps the ray effects of lamps in fog (docs/DOM.md).
  bounded,
};
inline constexpr Named<DomSpatial> kDomSpatials[] = {{DomSpatial::step, "step"}, {DomSpatial::diamond, "diamond"}, {DomSpatial::bounded, "bounded"}};
DomSpatial dom_spatial_from_name(const std::string& name);
const char* name(DomSpatial spatial);

enum class DomAccelerator {
  none,
  gmres,  // restarted GMRES on the moments (a Krylov method on the source-iteration operator)
};
inline constexpr Named<DomAccelerator> kDomAccelerators[] = {{DomAccelerator::none, "none"}, {DomAccelerator::gmres, "gmres"}};
DomAccelerator dom_accelerator_from_name(const std::string& name);
const char* name(DomAccelerator accelerator);

enum class DomStorage {
  float32,
  // float16 (simd/half.h) for the two fields that dominate memory: the first-collision source
  // (D values per cell, scaled per cell by its largest) and GMRES's basis vectors (unit length).
  // Arithmetic, the iterate and the solution's moments stay float32. Scheme `sweep` only.
  float16,
};
inline constexpr Named<DomStorage> kDomStorages[] = {{DomStorage::float32, "float32"}, {DomStorage::float16, "float16"}};
DomStorage dom_storage_from_name(const std::string& name);
const char* name(DomStorage storage);

// A solve split over processes by z planes (haze::mpi implements one over MPI; docs/SCALING.md):
// this process solves planes [first_plane, last_plane) of the volume's grid, the rest belongs to
// others. The sweeps take the z face entering its planes from the process upwind and hand the
// leaving one to the process downwind, octant by octant in blocks of rows; the dot products are summed
// over all processes. Each process calls solve_dom with the same volume, lights, depths and
// settings, its own exchange, and (warm) its own part's solution; the solution holds its planes.
// Scheme sweep with accelerator gmres, no boundary (refused otherwise, on every process alike).
class DomExchange {
 public:
  virtual ~DomExchange() = default;
  int first_plane = 0, last_plane = 0;
  // Called once, after the solve's checks (memory included) passed, before anything else: where
  // the processes meet, so that one that failed its checks (and meets them otherwise) can stop all.
  virtual void begin() {}
  // values[i] summed over every process, the same on each (in rank order: deterministic).
  virtual void sum(double* values, int count) = 0;
  // True on every process when `ok` is true on every process (through sum).
  bool all(bool ok) {
    double failed = ok ? 0.0 : 1.0;
    sum(&failed, 1);
    return failed == 0.0;
  }
  // The sweeps go through this part's planes in blocks of this many y rows, trading each block's
  // z face on its own: the process downwind starts on a block while this one sweeps the next.
  int rows_per_message = 4;
  // The radiance entering this part's first plane (its last, for octants going -z: octant & 4)
  // for octant `octant` over the next block of rows in the octant's sweep order, P values per face
  // cell as Transport's faces hold them; false where that face is the grid's own (the sky's
  // radiance enters there).
  virtual bool receive(int octant, float* face, std::size_t count) = 0;
  // The radiance leaving the part's last (first) plane over that block, toward the next process.
  virtual void send(int octant, const float* face, std::size_t count) = 0;
};

struct DomSettings {
  int directions = 128;  // D, spherical Fibonacci
  // N separable terms of the phase matrix, at most D; 0 (or D) keeps the full matrix. Eigenvalues
  // come in groups of 2l + 1, so N = (L + 1)^2 cuts cleanly (25: l <= 4); seed 000 used 24.
  int terms = 25;
  DomScheme scheme = DomScheme::sweep;
  DomSpatial spatial = DomSpatial::diamond;  // step with scheme paper (its Jacobi update is the step scheme's)
  DomAccelerator accelerator = DomAccelerator::gmres;
  int max_iterations = 500;  // per solved channel, the first-collision sweep included
  // Stop when a source iteration would change the moments by less than this, relative (L2 over
  // every cell and term); the error to the converged answer can be larger by 1 / (1 - albedo).
  double tolerance = 1e-3;
  int threads = 0;  // 0: every core oneTBB offers
  // Delta-M scaling (Wiscombe 1977) when N < D: with M = floor(sqrt(N)) Legendre orders the N
  // terms can hold, the fraction f = b_M of the phase function is treated as unscattered
  // (sigma_t' = sigma_t (1 - albedo f), albedo' = albedo (1 - f) / (1 - albedo f)) and the rest
  // has moments (b_k - f) / (1 - f), k < M, which N terms represent well. The first-collision
  // source keeps the exact phase function.
  bool delta_m = true;
  // Source iteration (accelerator none, and warm updates with a sweep budget) corrects each sweep
  // by diffusion synthetic acceleration (grids/src/dom_diffusion.h): the slow, diffusive part of
  // the error that each sweep reduces only by the scattering ratio.
  bool diffusion_acceleration = true;
  // Warm source iteration with the diamond's fix-up: set the marks in the sweeps of b + K x (where
  // first-collision and scattered light together would go below 0) instead of in a sweep of the
  // first-collision source alone, as a cold solve does: a sweep fewer per solve. Its fixed point
  // differs near point lights inside the medium (7% in the moments' L2 on the solver tests' small
  // cloud, 0.3% in examples/sim's image); warm updates with a sweep budget use it.
  bool fold_first_collision = false;
  DomStorage storage = DomStorage::float32;
  bool scalar_kernel = false;  // sweep: the scalar reference kernel instead of the SIMD one (tests, benchmarks)
  ProgressCallback progress;  // once per iteration, with the fraction of max_iterations done
  std::size_t max_memory = 0;  // bytes the solve may take (RenderOptions::max_memory); 0: what is available
  DomExchange* exchange = nullptr;  // a part of a solve split over processes (DomExchange); null: the whole grid
  int rows_per_message = 4;          // with haze::mpi: its exchange's DomExchange::rows_per_message
};

// The irradiance E_s the DOM solution's scattered light, the sky through the medium and (after the
// first surface pass) other surfaces' reflected light give the surfaces (dom_fields, the surface
// passes; gathered along 64 directions like a camera pixel's), at texel centres: over a rectangle of each plane, the grid's bounds widened by their extent on
// every side, texels at least two cells wide, at most 48 a side; over each sphere in latitude
// and longitude, n x 2n, n about a cell apart along a meridian (8 to 16); on each mesh's triangles
// about two cells apart within the same widened bounds (at most 4096 a mesh), on both sides.
struct SurfaceTexels {
  struct Rectangle {
    Vec3 origin, u, v;
    double u0 = 0.0, v0 = 0.0, size = 1.0;
    int nu = 0, nv = 0;
    std::vector<Rgb> values;  // [j * nu + i]
    bool lookup(const Vec3& p, Rgb& e) const;  // bilinear; false outside the rectangle
  };
  struct Globe {
    Vec3 centre{0.0};
    double radius = 1.0;
    int nt = 0, np = 0;
    std::vector<Rgb> values;  // [t * np + p], t along the polar angle from +y, p the azimuth from +x
    Rgb lookup(const Vec3& p) const;  // bilinear, wrapping in azimuth
  };
  // A mesh's texels: points on its triangles about `size` apart, E_s on both sides of each.
  struct Patches {
    double size = 1.0;
    std::vector<Vec3> points, normals;  // normals by the triangles' winding
    std::vector<Rgb> front, back;       // E_s on the normal's side and on the other
    std::unordered_map<std::int64_t, std::vector<std::uint32_t>> cells;  // texels by cell of `size`
    // Weighted over the texels within 1.5 size on p's face with normal n (either side); false
    // where there are none.
    bool lookup(const Vec3& p, const Vec3& n, Rgb& e) const;
    void index();  // fills `cells`
    std::int64_t cell_key(const Vec3& p) const;
  };
  std::vector<Rectangle> planes;  // per surface; empty but for planes
  std::vector<Globe> spheres;     // per surface; empty but for spheres
  std::vector<Patches> meshes;    // per surface; empty but for meshes
};
// The converged diffuse radiance in moment form: per solved channel (1 when medium and lights are
// grey, else 3) and cell, the N moments m_k = sum_d Q[d][k] L_d (seed 000 eq. 10). The in-scattered
// radiance toward any direction w follows from them (inscatter_weights).
struct DomSolution {
  std::shared_ptr<const DirectionSet> directions;
  std::shared_ptr<const PhaseMatrix> matrix;
  std::shared_ptr<const SeparablePhase> separable;
  PhaseFunction phase;             // the one the matrix holds: the medium's, or its delta-M remainder
  double delta_m_fraction = 0.0;   // f: 0 without delta-M scaling
  std::string factorization;       // what the directions, matrix and separable phase were made from
  std::array<int, 3> resolution{0, 0, 0};  // with an exchange, of this process's planes
  int first_plane = 0;                       // with an exchange: its first plane in the whole grid
  int channels = 0;
  std::vector<std::vector<float>> moments;  // [channel][cell * N + k], cells in public x-fastest order

  int iterations = 0;              // transport sweeps over all channels, the first-collision sweeps included
  bool converged = false;
  std::vector<double> changes;     // the relative change after each iteration
  size_t bytes = 0;                // peak memory the solver held for its fields
  double sweep_seconds = 0.0;      // wall time in transport sweeps (paper: in its iterations)
  // The share of cell visits the sweeps skipped: empty cells that no radiance had reached yet
  // (exact; the sweep scheme without sky light only).
  double skipped_fraction = 0.0;
  double seconds = 0.0;            // wall time of the whole solve (phase matrix, first collision, sweeps)
  double first_collision_seconds = 0.0;  // of which the first-collision source, every channel
  // With surfaces (dom_fields): the irradiance the medium's light gives them, which render_dom's
  // surfaces reflect toward each other; without, surfaces light each other not at all.
  std::shared_ptr<const SurfaceTexels> surfaces;
  // render_dom shades visible surfaces with the texels' irradiance through (kd + ks) / pi (what
  // the GL display shows) instead of gathering along 64 directions per pixel through the BRDF.
  bool texel_surfaces = false;

  int terms() const { return separable ? separable->terms() : 0; }
};

// Radiance entering the grid through its faces from outside: radiance(point, w) for a point on a
// face and a direction w pointing into the grid (surfaces the grid sees, the sky). Called
// concurrently, once per face cell and direction of each solve. Without one the sky's radiance
// enters through every face.
struct DomBoundary {
  std::function<Rgb(const Vec3& point, const Vec3& w)> radiance;
  bool grey = true;  // the same in every channel: a grey medium and lights still solve one channel
};

// Checks sizes and memory (a solve that would not fit in the memory available throws haze::Error
// before allocating). `delta_depths` holds, for each point, spot or directional light of `lights`
// in order, the density integral from every cell to it (exact or propagated, optical_depth.h), as
// render_dom takes them; sky lights enter through the boundary and have none. `warm`, when given and of the same shape, starts the iteration from its moments (the
// paper's one-iteration-per-frame mode when density or lights change a little); with accelerator
// none each iteration is then one sweep with the first-collision source in it (x <- b + K x).
// `boundary`, when given, replaces the sky's radiance at the faces. `spare`, when given, holds
// buffers the warm iteration may take for its moments and its next iterate (their contents are
// overwritten) and gets back the one it leaves: a caller that hands it the previous solution's
// moments solves frame after frame without allocating them.
DomSolution solve_dom(const ExtinctionVolume& volume, const std::vector<Light>& lights, const std::vector<DenseGrid>& delta_depths,
                      const DomSettings& settings, const DomSolution* warm = nullptr, const DomBoundary* boundary = nullptr,
                      std::vector<std::vector<float>>* spare = nullptr);

// For a direction w (propagation direction of the scattered light): c_k with
// sum_j P(w, w_j) L_j ~ sum_k c_k m_k, the row of P at w extended off the direction set
// (PhaseMatrix::row) and projected on the kept eigenvectors.
Eigen::VectorXd inscatter_weights(const DomSolution& solution, const Vec3& w);
// The same into `out`, through `row` (the phase matrix's row at w): no allocation once both have
// their sizes.
void inscatter_weights(const DomSolution& solution, const Vec3& w, Eigen::VectorXd& row, Eigen::VectorXd& out);

// The image of a solved scene seen in `view` (its camera and depth; with view.layers, L_in, T and
// C per pixel: the gathered and unscattered light summed, seen through the unscattered march's
// transmittance): unscattered light (surfaces lit through `delta_depths`, as solve_dom takes them;
// the background plus any sky) through the medium, plus, along each camera ray, the
// single-scattered light and the in-scattered diffuse radiance sum_k c_k m_k (c from
// inscatter_weights toward the eye), both carried by the delta-M scaled extinction when the solve
// used it (the formal solution of the scaled equation; with f = 0 it is the propagation marcher's
// estimator plus the gather). One solution serves any camera. Method dom's one render path: the
// gather (gather_planes' over all planes) and then add_unscattered.
RenderResult render_dom(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& delta_depths,
                        const DomSolution& solution, double step_cells, const RenderOptions& options, const View& view);

// render_dom in parts, for a solution split over processes (haze::mpi): the scattered light of
// the steps of each camera ray whose midpoints lie in z planes [planes[0], planes[1]) of the grid,
// from `part`, which holds the moments of those planes and one more on each side (DomSolution::
// first_plane): per pixel, the light those steps gather seen from the first of them, and their
// transmittance. Front to back, the stretches of a ray compose as L = L_1 + T_1 L_2 + T_1 T_2 L_3 ...
// No surfaces (a haze::Error): their light gathers over the whole grid.
std::vector<PixelLayers> gather_planes(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& delta_depths,
                                       const DomSolution& part, double step_cells, std::array<int, 2> planes, const View& view,
                                       const RenderOptions& options);
// render_dom's second part, the image given the scattered light per pixel (render_dom's own
// gather, or a split solve's composed stretches): the unscattered march of the whole volume, plus
// `scattered`.
RenderResult add_unscattered(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& delta_depths, double delta_m_fraction,
                             double step_cells, const RenderOptions& options, const View& view, const std::vector<PixelLayers>& scattered);

// Everything method "dom" computes before it renders, from the scene and the method's settings in
// options.settings (resolution, directions, terms, scheme, accelerator, iterations, tolerance,
// delta_m, storage, optical_depth, step; unknown keys are an error), with the stats it reports.
// options.progress follows the solve. The GL display (haze::gl) shows the same fields.
struct DomFields {
  ExtinctionVolume volume;
  std::vector<DenseGrid> delta_depths;  // per point, spot or directional light, in order
  DomSolution solution;
  double step_cells = 0.5;
  nlohmann::json stats;
  // The settings they were made with, for updates.
  CellCount cells;
  DomSettings settings;
  DepthOptions depth;
  int warm_iterations = 0;  // sweeps per update (source iteration; with spatial diamond after a first-collision sweep); 0: GMRES to the tolerance
  int surface_passes = 2;   // solves with the surfaces' reflected light entering the grid (dom_fields)
};
DomFields dom_fields(const Scene& scene, const RenderOptions& options);
// Its first part: the settings read, the volume and the depths made, stats["depth_seconds"]; no
// solution yet (what a split solve, haze::mpi, starts from).
DomFields dom_setup(const Scene& scene, const RenderOptions& options);

// The memory a solve with these settings needs, in bytes (what solve_dom checks).
size_t dom_memory_bytes(const std::array<int, 3>& resolution, int channels, const DomSettings& settings);

// Method "dom": its settings, what it handles and its auto rule.
MethodInfo dom_info();

}  // namespace haze::grids

#pragma GCC visibility pop
