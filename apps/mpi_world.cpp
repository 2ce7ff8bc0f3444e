// MpiWorld and world (mpi_world.h): haze::mpi where this build has it.
#include "mpi_world.h"

#include <haze/core/error.h>

#include <cstdlib>

#ifdef HAZE_WITH_MPI
#include <haze/mpi/methods.h>

#include <mpi.h>
#endif

namespace haze::app {
namespace {

// The number of processes a launcher says it started, 0 when none did.
int launched_ranks() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
    if (const char* v = std::getenv(name)) return std::atoi(v);
  return std::getenv("PMIX_RANK") ? 1 : 0;
}

#ifdef HAZE_WITH_MPI
bool started = false;  // MPI_Init_thread called
#endif

}  // namespace

MpiWorld::MpiWorld([[maybe_unused]] int& argc, [[maybe_unused]] char**& argv) {
  if (launched_ranks() == 0) return;
#ifdef HAZE_WITH_MPI
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  started = true;
  mpi::register_methods();
#else
  if (launched_ranks() > 1)
    throw Error("mpirun", to_text(launched_ranks()) + " processes", "one: this haze was built without MPI (scripts/setup installs OpenMPI)");
#endif
}

MpiWorld::~MpiWorld() {
#ifdef HAZE_WITH_MPI
  if (started) MPI_Finalize();
#endif
}

int world_rank() {
  int rank = 0;
#ifdef HAZE_WITH_MPI
  if (started) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
#endif
  return rank;
}

int world_ranks() {
  int ranks = 1;
#ifdef HAZE_WITH_MPI
  if (started) MPI_Comm_size(MPI_COMM_WORLD, &ranks);
#endif
  return ranks;
}

std::shared_ptr<const Ranks> world() {
#ifdef HAZE_WITH_MPI
  if (started) return mpi::ranks(MPI_COMM_WORLD);
#endif
  return nullptr;
}

}  // namespace haze::app
