// Method "dom" rendered by the ranks of an MPI communicator (docs/SCALING.md, "Rendering"): each
// rank solves its z planes (solve_dom) and marches the stretch of every camera ray through them;
// one rank composes the stretches front to back into the image. What `mpirun haze render` runs.
#pragma once

#include <haze/core/solution.h>

#include <mpi.h>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::mpi {

// Every rank of `comm` calls it with the same scene, view and options (options.settings the dom
// method's; threads per rank). Each rank makes the volume and the depths to the lights (whole),
// solves its planes of the moments, takes the plane next to its own from each neighbour and
// gathers the scattered light along its stretch of each ray (grids::gather_planes); `root`
// composes the stretches in each ray's order, adds the unscattered light of the whole volume
// (grids::render_dom) and returns the image, its layers when the view asks, and stats: the
// solve's figures and "ranks", per rank "rank_cells", "rank_wait_seconds" (for faces from the
// rank upwind), "rank_reduce_seconds", "rank_solve_seconds" (of which "rank_sweep_seconds",
// "rank_first_collision_seconds"), "rank_gather_seconds", "rank_bytes_sent". The other
// ranks return an empty result. Scenes with surfaces are refused (haze::Error on every rank):
// the split solve carries no light between medium and surfaces yet. Cancelling through
// options.progress on any rank cancels every rank (haze::Cancelled).
RenderResult render_dom(MPI_Comm comm, const Scene& scene, const View& view, const RenderOptions& options, int root = 0);

}  // namespace haze::mpi

#pragma GCC visibility pop
