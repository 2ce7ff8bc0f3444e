// Heterogeneous single scattering on grids (seed 003), the pieces of method "propagation" for
// callers who keep them between frames: the extinction volume (inject once, re-inject only what a
// moved blob touches), one optical-depth volume per light (re-propagate when lights move), and the
// ray marcher over both.
#pragma once

#include <haze/core/method.h>
#include <haze/core/scene.h>
#include <haze/grids/grid.h>
#include <haze/grids/optical_depth.h>

#include <array>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::grids {

// The medium's density on a grid over its bounds, with the medium's coefficients.
struct ExtinctionVolume {
  DenseGrid density;
  Rgb sigma_t_scale{1.0}, albedo{0.8};
  PhaseFunction phase;
  Emission emission{};  // the medium's; where it follows the density, the grid's density

  // The volume as a haze medium: core's grid medium over a view of `density` (valid while the
  // volume lives), the same trilinear lookup the marchers use; for the reference, quadrature or
  // a caller's own walk (Medium::majorants) on exactly the cells a grid method solved.
  MediumDesc medium() const;
};

struct VolumeReport {
  double truncation_bound = 0.0;  // RBF injection: see InjectionReport
};

// How many cells make_extinction_volume gives an RBF or constant density's bounds.
struct CellCount {
  int longest = 64;                  // along the longest side, the others in proportion (at least 2)
  std::array<int, 3> axes{0, 0, 0};  // when all are set: exactly these, `longest` unused
  // Cells per optical depth through the medium: an axis whose largest column optical depth (at
  // the largest sigma_t) asks for more cells than its share of `longest` gets them, up to
  // min(longest, most_for_depth). A thin, dense slab then still has cells through its thickness.
  // 0: off.
  double per_optical_depth = 0.0;
  int most_for_depth = 32;

  CellCount() = default;
  CellCount(int longest_side) : longest(longest_side) {}  // NOLINT: an int is the cells along the longest side
  bool per_axis() const { return axes[0] > 0 && axes[1] > 0 && axes[2] > 0; }
  std::string text() const;  // "64" or "[64, 64, 16]"
};

// From the scene's medium: an RBF density is injected into cells over its bounds (`cells`; an
// unbounded RBF medium gets the box where every blob has fallen below the injection cutoff), a
// grid density is taken as it is, a constant density fills a grid over the medium's bounds (it
// must have bounds). For those two, a plane surface along an axis that cuts the bounds ends them
// at the plane, on the camera's side: the other half is hidden behind the plane and exchanges no
// light with this one.
// Throws haze::Error for a scene without a medium or with an unbounded constant one.
ExtinctionVolume make_extinction_volume(const Scene& scene, const CellCount& cells = {}, double cutoff = 0.0, int threads = 0,
                                        VolumeReport* report = nullptr);

struct MarchSettings {
  double step_cells = 0.5;  // ray-march step as a fraction of the smallest cell side
  // The float64 reference, one pixel at a time, instead of the float32 SIMD kernel over each row
  // (which a tabulated phase function also falls back to).
  bool scalar = false;
  // Surfaces also receive the single-scattered light of the medium (the first bounce, medium to
  // surface): the march toward each visible surface point along 64 Fibonacci directions (32 over
  // its hemisphere), through the BRDF, a point light's irradiance capped at the cone each direction
  // stands for. Method "propagation"'s setting surface_light; the GL display has it not.
  bool surface_gather = false;
  // march_layers (a frame's per-pixel layers) from one eye: the directional lights, and the point
  // lights with no cell within kFarCells cells of them denser than kFarDensity of the volume's
  // largest, folded into a radiance per cell toward the eye (march_toward_eye, made each frame),
  // read trilinearly with the density from float16 records instead of every light's depth at
  // every step; spots and the other point lights stay in the steps (near a light the folded
  // radiance's curvature is more than its prefilter takes back: 1.5e-3 of the image for a light
  // 4.5 cells above a cloud's top). Within 4e-4 relative RMS of the steps' layers on the frame
  // benchmark's cloud (tests/grids/toward_eye_test.cpp).
  bool toward_eye = true;
  static constexpr int kFarCells = 8;
  static constexpr float kFarDensity = 0.01f;
  // march_layers from one eye without surfaces of Haze's own: where a cell spans two pixels or
  // more, the rays are marched on a lattice of at least kLatticeNodesPerCell nodes per cell as the
  // view sees it (its step in pixels the power of 2 at or below), the cells with a rough node at a
  // corner (kLatticeSpread) on a lattice of half the step, and so on down to 2 pixels, below which
  // the rough cells' pixels take their own rays; the others are bilinear between the nodes of the
  // finest level that holds them. Nodes within kLatticePeakNodes of a level's nodes of a light in
  // the steps (a near point light, a spot) in view count as rough. With a host's depth, a
  // first-level cell whose pixels' depths stray more than kLatticeDepth cells from the bilinear of
  // its corners' (an edge of the host's geometry) takes every pixel's own ray
  // (tests/grids/toward_eye_test.cpp measures the error). false: every pixel its own ray.
  bool lattice = true;
  static constexpr double kLatticeNodesPerCell = 0.9;
  static constexpr double kLatticeDepth = 0.1;
  static constexpr int kLatticePeakNodes = 4;
  // A lattice node whose second difference along x or y exceeds this (in T, or in L_in over its
  // largest) is rough: the volume's silhouette, the edge of a light's cone.
  static constexpr float kLatticeSpread = 0.007f;
};

// The per-light volumes as the marcher reads them, all lights of a cell together ([cell * lights +
// l]): the optical depths, and the surfaces' shadows (surface_visibility; empty without surfaces
// or where nothing scatters). 4 bytes a cell and light each: made once per solution, not per frame.
struct PackedLights {
  std::vector<float> depths, visibility;
  float density_max = 0.0f;  // the volume's largest cell (MarchSettings::toward_eye's measure)
  // In a grey medium, for each light MarchSettings::toward_eye folds (directional, or point with no
  // dense cell near): V e^(-sigma_t depth) per cell, a plane a light (attenuation_plane[l], -1 for
  // the others): the fold's per frame work without an exponential or a gather per cell and light.
  std::vector<float> attenuation;
  std::vector<int> attenuation_plane;
};
// `visibility` when given (one grid per light), else computed here.
PackedLights pack_lights(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths, int threads,
                         const std::vector<DenseGrid>* visibility = nullptr);

// Seed 003 eq. 8-10 in Haze's conventions: along each camera ray inside the volume, in steps,
//   L += T_cam albedo (1 - e^(-sigma_t rho step)) sum_lights p(wi . wo) E_light e^(-sigma_t depth_light),
// with density and depths trilinear at the step's midpoint and T_cam the transmittance so far
// (the (1 - e^-tau) form keeps thick steps energy-conserving, where eq. 8's K_t step does not).
// Surfaces (Lambert/Phong) are lit through the depth volume (or, outside it, a DDA walk through
// the density) where no other surface is in the way, and seen through T_cam; E_light is times its
// visibility past the surfaces (surface_visibility). depths[i] belongs to scene.lights[i]. The
// marcher reads them packed (PackedLights): `packed` when given, which a caller rendering many
// frames keeps, else made here.
Image march_image(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths,
                  const MarchSettings& settings, const RenderOptions& options, const PackedLights* packed = nullptr);
// The same for `view` (its camera in place of the scene's): rays end at its depth where no surface
// is nearer, and with view.layers the result holds L_in, T and C per pixel (PixelLayers).
RenderResult march_view(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths, const MarchSettings& settings,
                        const RenderOptions& options, const View& view, const PackedLights* packed = nullptr);
// L_in and T along each of view's rays to each of `distances` (ascending; MethodSolution::
// render_distances) in one march: each ray's stretch between consecutive distances is marched as
// its own segment (the SIMD kernel's, all of a row's in one packet) and the segments are chained,
// L(d_k) = L(d_k-1) + T(d_k-1) L_k, T(d_k) = T(d_k-1) T_k. Into out (slice-major, float32); false without the SIMD kernel.
// With `scattered` (dom's froxels), L_in also takes that radiance per cell and the steps its own
// extinction and albedo (MarchScattered).
struct MarchScattered {
  const float* radiance = nullptr;  // per cell, [c * cells + cell]: light scattered more than once, toward the eye
  int channels = 1;                 // 1: the same for every channel
  Rgb sigma_t{1.0};                 // the steps' extinction per density (the lights' depths keep the volume's)
  Rgb albedo{1.0};                  // what scatters the lights' light and `radiance` alike
};
bool march_distances(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths, const MarchSettings& settings,
                     const RenderOptions& options, const View& view, std::span<const double> distances, DistanceLayers out,
                     const PackedLights* packed = nullptr, const MarchScattered* scattered = nullptr);

// The same as march_view's layers (View::layers) into the caller's spans (LayerSpans, what
// Solution::render_layers takes), each thread's buffers kept: a frame allocates nothing once they
// have grown. False where the SIMD kernel cannot take the scene, or with surface_gather. With
// `scattered` (dom's layers), as march_distances (the lights then stay in the steps).
bool march_layers(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths, const MarchSettings& settings,
                  const RenderOptions& options, const View& view, LayerSpans out, const PackedLights* packed = nullptr,
                  const MarchScattered* scattered = nullptr);

// Setting step 0, the march's step chosen for the medium and lights: the longest of kAutoSteps
// cells whose march of kAutoStepProbes chords spread over the bounds (the SIMD kernel, every light
// in the steps) stays within kAutoStepTolerance relative RMS of kFinestAutoStep cells' in L_in and
// in T. The midpoint rule's error grows as the step squared times the fields' curvature: the frame
// benchmark's smooth cloud takes 3 cells, a grid of cell-sized noise keeps 0.5. So does a point or
// spot light near dense cells (MarchSettings::toward_eye's measure): the rays that pass closest to
// it, which few chords sample, peak as 1 / r^2 (the test cloud's light inside it: 3.7e-3 off at 1
// cell). kFinestAutoStep where the kernel cannot take the scene.
constexpr double kFinestAutoStep = 0.5, kAutoStepTolerance = 5e-4;
constexpr double kAutoSteps[] = {1.0, 2.0, 3.0, 4.0};
constexpr int kAutoStepProbes = 256;
double auto_step_cells(const Scene& scene, const ExtinctionVolume& volume, const std::vector<DenseGrid>& depths, const PackedLights& packed,
                       int threads);

// Everything method "propagation" computes before it marches, from the scene and the method's
// settings in options.settings (resolution, optical_depth, sweep_layers, step, cutoff; unknown
// keys are an error), with the stats it reports. The GL display (haze::gl) shows the same fields.
struct PropagationFields {
  ExtinctionVolume volume;
  std::vector<DenseGrid> depths;  // one per light
  MarchSettings march;
  nlohmann::json stats;
  PackedLights packed;  // the depths (and surface shadows) as the marcher reads them
  // The settings they were made with, for updates.
  int resolution = 64;
  double cutoff = 0.0;
  DepthOptions depth = {};
  bool auto_step = false;  // setting step 0: march.step_cells chosen by auto_step_cells
};
PropagationFields propagation_fields(const Scene& scene, const RenderOptions& options);

// Method "propagation": its settings, what it handles and its auto rule.
MethodInfo propagation_info();

}  // namespace haze::grids

#pragma GCC visibility pop
