// The `haze` command under mpirun (docs/SCALING.md, "Rendering"): MPI is started when a launcher
// started this process (OpenMPI's, MPICH's or a PMIx one), and `haze render` then splits the
// method over the ranks (those haze::mpi splits: dom); rank 0 alone writes and prints.
#pragma once

#include <haze/core/solution.h>

#include <memory>

namespace haze::app {

// MPI_Init_thread and the split methods registered (haze::mpi::register_methods) when launched
// by mpirun (a haze::Error when this build has no MPI and the launcher started more than one
// process); MPI_Finalize at the end.
class MpiWorld {
 public:
  MpiWorld(int& argc, char**& argv);
  ~MpiWorld();
  MpiWorld(const MpiWorld&) = delete;
  MpiWorld& operator=(const MpiWorld&) = delete;
};

int world_rank();   // 0 without MPI
int world_ranks();  // 1 without MPI

// The world's ranks for RenderOptions::ranks under mpirun (haze::mpi::ranks of MPI_COMM_WORLD,
// whose split methods MpiWorld registered), null without it.
std::shared_ptr<const Ranks> world();

}  // namespace haze::app
