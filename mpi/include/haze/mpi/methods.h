// Methods split over the ranks of an MPI communicator (docs/SCALING.md, "Rendering"), reached
// through haze::prepare and Solution like every method: RenderOptions::ranks = mpi::ranks(comm).
// Method dom: each rank solves its z planes (solve_dom) and marches the stretch of every camera
// ray through them; rank 0 composes the stretches front to back into the image. What `mpirun
// haze render` runs.
#pragma once

#include <haze/core/solution.h>

#include <mpi.h>

#include <memory>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::mpi {

// The ranks of `comm` for RenderOptions::ranks. The communicator must outlive every solution
// prepared with them (each holds a duplicate of it, for messages of its own).
std::shared_ptr<const Ranks> ranks(MPI_Comm comm);

// Registers the split forms (haze::register_split) of the methods this module splits: dom. Each
// rank makes the volume and the depths to the lights (whole) and solves its planes of the
// moments at prepare; a render takes the plane next to its own from each neighbour's part and
// gathers the scattered light along its stretch of each ray (grids::gather_planes), and rank 0
// composes the stretches in each ray's order, adds the unscattered light of the whole volume
// (grids::render_dom) and returns the image, its layers when the view asks, and stats: the
// solve's figures and "ranks", per rank "rank_cells", "rank_wait_seconds" (for faces from the
// rank upwind), "rank_reduce_seconds", "rank_solve_seconds" (of which "rank_sweep_seconds",
// "rank_first_collision_seconds"), "rank_gather_seconds", "rank_bytes_sent". The other ranks'
// renders return an empty result. Scenes with surfaces are refused (haze::Error on every rank):
// the split solve carries no light between medium and surfaces yet. Cancelling through
// options.progress on any rank cancels every rank (haze::Cancelled). A split solution's calls are
// collective: every rank makes them in the same order, from the thread that initialized MPI
// (MPI_THREAD_FUNNELED), one at a time, not from several threads at once as other solutions
// allow. Safe to call more than once.
void register_methods();

}  // namespace haze::mpi

#pragma GCC visibility pop
