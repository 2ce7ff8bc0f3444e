// The discrete-ordinate solver split over MPI processes (docs/SCALING.md): each rank of a
// communicator solves a slab of the grid's z planes, the sweeps pipelined over the ranks octant by
// octant (the z face leaving one rank enters the next, in non-blocking messages), GMRES's dot
// products summed over all ranks. The DOM's fields (first-collision source, moments, Krylov
// basis) are split; the density and the optical depths to the lights, a float per cell each,
// are whole on every rank. Call from the thread that initialized MPI (MPI_THREAD_FUNNELED).
#pragma once

#include <haze/grids/dom.h>

#include <mpi.h>

#include <array>
#include <cstddef>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::mpi {

// The z planes [first, last) that rank `rank` of `ranks` solves out of `planes`: in order, as
// equal as can be (the first planes % ranks ranks one more). haze::Error when a rank would get none.
std::array<int, 2> split_planes(int planes, int ranks, int rank);

// What one rank's part of a solve spent and sent.
struct DomPartStats {
  int ranks = 1;
  std::array<int, 2> planes{0, 0};
  std::size_t cells = 0;         // this rank's
  double wait_seconds = 0.0;     // blocked on faces from the rank upwind (the pipeline's fill and imbalance)
  double reduce_seconds = 0.0;   // in the dot products' all-gathers
  double seconds = 0.0;          // the whole call
  std::size_t messages = 0, bytes_sent = 0;  // faces sent downwind
};

// Every rank of `comm` calls it with the same volume, lights, depths and settings (checked: a
// mismatch is a haze::Error on every rank) and, for a warm start, its own part of the previous
// solution. Returns this rank's part: its planes' moments (DomSolution::first_plane), the
// iteration counts and changes of the whole solve, the same on every rank. settings.max_memory
// caps each rank; a rank that would not fit fails the call on every rank alike, before anything
// is allocated. Scheme sweep with accelerator gmres; settings.threads threads per rank. `planes`,
// when given (first < last), are this rank's instead of split_planes': the ranks' planes must
// follow each other in rank order from 0 to the grid's last (checked: a haze::Error on every
// rank), so a caller can give a rank more planes where they are cheap.
grids::DomSolution solve_dom(MPI_Comm comm, const grids::ExtinctionVolume& volume, const std::vector<Light>& lights,
                             const std::vector<grids::DenseGrid>& delta_depths, const grids::DomSettings& settings,
                             const grids::DomSolution* warm = nullptr, DomPartStats* stats = nullptr, std::array<int, 2> planes = {0, 0});

// The parts of every rank gathered on `root` into the whole grid's solution (render_dom takes it);
// the other ranks get their part back unchanged. Collective.
grids::DomSolution gather(MPI_Comm comm, const grids::DomSolution& part, int root = 0);

}  // namespace haze::mpi

#pragma GCC visibility pop
