// MpiExchange: grids::DomExchange over an MPI communicator, a z slab per rank. Faces go to the
// next rank along each octant's z direction, block by block of rows, in non-blocking sends (each
// from its own copy, freed once sent; all waited on at finish()); sums are all-gathered and added
// in rank order, so every rank gets the same bits and takes the same decisions.
#pragma once

#include <haze/grids/dom.h>
#include <haze/mpi/dom.h>

#include <mpi.h>

#include <array>
#include <list>
#include <vector>

namespace haze::mpi {

class MpiExchange final : public grids::DomExchange {
 public:
  MpiExchange(MPI_Comm comm, std::array<int, 2> planes);
  ~MpiExchange() override;
  MpiExchange(const MpiExchange&) = delete;
  MpiExchange& operator=(const MpiExchange&) = delete;

  void begin() override;  // haze::Error on every rank when one called fail() instead
  void fail();            // in place of begin(), on a rank whose checks failed
  void sum(double* values, int count) override;
  bool receive(int octant, float* face, std::size_t count) override;
  void send(int octant, const float* face, std::size_t count) override;

  void finish();  // waits for every send
  const DomPartStats& stats() const { return stats_; }

 private:
  // The rank the octant's directions come from and go to: z increasing for octants 0-3.
  int upwind(int octant) const;
  int downwind(int octant) const;
  MPI_Comm comm_;
  int rank_ = 0, ranks_ = 1;
  struct Sent {
    std::vector<float> face;
    MPI_Request request = MPI_REQUEST_NULL;
  };
  std::list<Sent> sent_;  // faces on their way, kept until their sends complete
  std::vector<double> gathered_;
  bool met_ = false;  // begin() or fail() called
  void meet(int failed);
  DomPartStats stats_;
};

// A communicator of our own for a call's messages (their tags cannot meet the caller's).
struct Duplicate {
  MPI_Comm comm = MPI_COMM_NULL;
  explicit Duplicate(MPI_Comm from) { MPI_Comm_dup(from, &comm); }
  ~Duplicate() { MPI_Comm_free(&comm); }
  Duplicate(const Duplicate&) = delete;
  Duplicate& operator=(const Duplicate&) = delete;
};

// `count` floats in as many messages as MPI's int counts need (tag 0), and their receipt.
void send_floats(MPI_Comm comm, const float* values, std::size_t count, int to);
void receive_floats(MPI_Comm comm, float* values, std::size_t count, int from);

// A face holds at most 2^31 - 1 floats per message (MPI's int counts); haze::Error past that.
int message_count(std::size_t count, const char* what);

}  // namespace haze::mpi
