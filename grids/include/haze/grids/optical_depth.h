// Optical depth from a light to every cell of an extinction volume (seed 003 sec. 4.3: the opacity
// propagation volume), three ways. Values are density integrals, integral of rho ds from the cell
// centre to the light in scene units; multiply by sigma_t per channel. The density is the grid's,
// constant over each cell (zero outside the grid).
#pragma once

#include <haze/core/light.h>
#include <haze/core/names.h>
#include <haze/core/surface.h>
#include <haze/grids/grid.h>

#include <string>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::grids {

enum class DepthScheme {
  exact,  // a DDA walk from each cell centre to the light: the ground truth, O(n^4)
  paper,  // seed 003 eq. 6-7: 6-neighbour weighted gathering, iterated as a wavefront until converged
  sweep,  // short characteristics: one ordered pass outward from the light (BEYOND.md)
};
inline constexpr Named<DepthScheme> kDepthSchemes[] = {{DepthScheme::exact, "exact"}, {DepthScheme::paper, "paper"}, {DepthScheme::sweep, "sweep"}};
DepthScheme depth_scheme_from_name(const std::string& name);
const char* name(DepthScheme scheme);

struct DepthOptions {
  DepthScheme scheme = DepthScheme::sweep;
  // sweep: how many cell layers each short characteristic walks exactly before it interpolates;
  // more layers mean fewer interpolations along a path (less blurring of shadows) for more work
  // per cell (docs/PROPAGATION.md measures the trade).
  int sweep_layers = 4;
  bool scalar_kernel = false;  // sweep: the scalar reference kernel instead of the SIMD one (tests, benchmarks)
  int threads = 0;  // 0: every core oneTBB offers
};

struct DepthStats {
  int iterations = 0;  // paper: wavefront iterations until converged; 1 otherwise
};

// One volume of the density's size per light: point and spot lights (the cone does not matter
// here) inside or outside the grid, and directional lights. A light exactly at a cell centre is
// fine (that cell's depth is 0). Throws haze::Error for a sky light or a non-finite position or
// direction. The result does not depend on the thread count.
DenseGrid optical_depth(const DenseGrid& density, const Light& light, const DepthOptions& options = {}, DepthStats* stats = nullptr);

// Before making the depth volumes of `lights` (the sky's excepted) over `density`: a haze::Error
// naming `lights` when they would not fit in memory_budget(max_memory) (progress.h).
void check_depth_memory(const DenseGrid& density, const std::vector<Light>& lights, std::size_t max_memory);

// Every light's volume, the lights spread over threads (the paper packs four lights per texture
// and pass; here each light is one pass over its own volume, lights in parallel).
std::vector<DenseGrid> optical_depths(const DenseGrid& density, const std::vector<Light>& lights, const DepthOptions& options = {},
                                      DepthStats* stats = nullptr);

// Surface shadows (docs/ARCHITECTURE.md, "Surfaces in the transport"): per light of `lights` (point,
// spot or directional, as optical_depths), 1 at the cell centres of `grid` that see the light past
// every surface and 0 where a surface is in the way. Empty when there are no surfaces. Gathers
// read it trilinear and multiply the light's E e^-tau by it; first-collision sources, at cell
// centres, read shadowed_depths.
std::vector<DenseGrid> surface_visibility(const DenseGrid& grid, const std::vector<Light>& lights, const std::vector<Surface>& surfaces,
                                          int threads = 0);
// `depths` with kShadowDepth added where `visibility` is 0 (the cells a surface hides from the
// light: e^(-sigma_t depth) is 0 there); unchanged when visibility is empty.
inline constexpr float kShadowDepth = 1e30f;
std::vector<DenseGrid> shadowed_depths(std::vector<DenseGrid> depths, const std::vector<DenseGrid>& visibility);

// integral of the grid's piecewise-constant density along the segment a -> b (DDA, exact).
double density_integral_dda(const DenseGrid& density, const Vec3& a, const Vec3& b);

// Trilinear sample of cell-centred values (clamped to the edge cells), and 0 outside the bounds.
float sample_trilinear(const DenseGrid& grid, const Vec3& p);

// The lights' unscattered light a surface point p (unit normal n) reflects toward wo:
//   sum_l brdf(w_l, wo) E_l (n . w_l) e^(-sigma_t depth_l)   where no surface is in the way,
// depth_l the density integral to light l: depths[l] trilinear inside the density's bounds, a DDA
// walk through the density outside them (past any grid for a directional light).
Rgb surface_direct(const std::vector<Light>& lights, const std::vector<Surface>& surfaces, const DenseGrid& density,
                   const std::vector<DenseGrid>& depths, const Rgb& sigma_t, const Surface& surface, const Vec3& p, const Vec3& n,
                   const Vec3& wo);

}  // namespace haze::grids

#pragma GCC visibility pop
