// The `haze` command under mpirun (docs/SCALING.md, "Rendering"): MPI is started when a launcher
// started this process (OpenMPI's, MPICH's or a PMIx one), and `haze render --method dom` then
// splits the scene's grid over the ranks; rank 0 alone writes and prints.
#pragma once

#include <haze/core/solution.h>

#include <string>

namespace haze::app {

// MPI_Init_thread when launched by mpirun (a haze::Error when this build has no MPI and the
// launcher started more than one process); MPI_Finalize at the end.
class MpiWorld {
 public:
  MpiWorld(int& argc, char**& argv);
  ~MpiWorld();
  MpiWorld(const MpiWorld&) = delete;
  MpiWorld& operator=(const MpiWorld&) = delete;
};

int world_rank();   // 0 without MPI
int world_ranks();  // 1 without MPI

// `method` over the world's ranks (haze::mpi::render_dom; a haze::Error for any method but dom):
// the image on rank 0, an empty result on the others.
RenderResult render_split(const Scene& scene, const std::string& method, const RenderOptions& options, const View& view);

}  // namespace haze::app
