// MpiExchange (exchange.h).
#include "exchange.h"

#include <haze/core/error.h>
#include <haze/core/stopwatch.h>

#include <algorithm>
#include <climits>

namespace haze::mpi {

int message_count(std::size_t count, const char* what) {
  if (count > static_cast<std::size_t>(INT_MAX))
    throw Error(what, to_text(count) + " values", "at most " + to_text(INT_MAX) + " values in one MPI message (more ranks, fewer cells per face)");
  return static_cast<int>(count);
}

namespace {
constexpr std::size_t kChunk = std::size_t{1} << 28;  // floats per message, within MPI's int counts
}

void send_floats(MPI_Comm comm, const float* values, std::size_t count, int to) {
  for (std::size_t at = 0; at < count; at += kChunk)
    MPI_Send(values + at, static_cast<int>(std::min(kChunk, count - at)), MPI_FLOAT, to, 0, comm);
}

void receive_floats(MPI_Comm comm, float* values, std::size_t count, int from) {
  for (std::size_t at = 0; at < count; at += kChunk)
    MPI_Recv(values + at, static_cast<int>(std::min(kChunk, count - at)), MPI_FLOAT, from, 0, comm, MPI_STATUS_IGNORE);
}

MpiExchange::MpiExchange(MPI_Comm comm, std::array<int, 2> planes) : comm_(comm) {
  MPI_Comm_rank(comm, &rank_);
  MPI_Comm_size(comm, &ranks_);
  first_plane = planes[0], last_plane = planes[1];
  stats_.ranks = ranks_;
  stats_.planes = planes;
}

MpiExchange::~MpiExchange() { finish(); }

int MpiExchange::upwind(int octant) const {
  const int r = octant & 4 ? rank_ + 1 : rank_ - 1;
  return r >= 0 && r < ranks_ ? r : MPI_PROC_NULL;
}
int MpiExchange::downwind(int octant) const {
  const int r = octant & 4 ? rank_ - 1 : rank_ + 1;
  return r >= 0 && r < ranks_ ? r : MPI_PROC_NULL;
}

void MpiExchange::meet(int failed) {
  met_ = true;
  std::vector<int> failures(static_cast<std::size_t>(ranks_));
  MPI_Allgather(&failed, 1, MPI_INT, failures.data(), 1, MPI_INT, comm_);
  const auto first = std::find(failures.begin(), failures.end(), 1);
  if (!failed && first != failures.end())
    throw Error("ranks", "rank " + to_text(first - failures.begin()) + " of " + to_text(ranks_) + " refusing its part",
                "every rank's part valid and within its memory (that rank's error says why)");
}
void MpiExchange::begin() { meet(0); }
void MpiExchange::fail() {
  if (!met_) meet(1);
}

void MpiExchange::sum(double* values, int count) {
  const Stopwatch watch;
  gathered_.resize(static_cast<std::size_t>(count) * static_cast<std::size_t>(ranks_));
  MPI_Allgather(values, count, MPI_DOUBLE, gathered_.data(), count, MPI_DOUBLE, comm_);
  for (int i = 0; i < count; ++i) {
    double total = 0.0;
    for (int r = 0; r < ranks_; ++r) total += gathered_[static_cast<std::size_t>(r) * static_cast<std::size_t>(count) + static_cast<std::size_t>(i)];
    values[i] = total;
  }
  stats_.reduce_seconds += watch.seconds();
}

bool MpiExchange::receive(int octant, float* face, std::size_t count) {
  const int from = upwind(octant);
  if (from == MPI_PROC_NULL) return false;
  const Stopwatch watch;
  MPI_Recv(face, message_count(count, "face"), MPI_FLOAT, from, octant, comm_, MPI_STATUS_IGNORE);
  stats_.wait_seconds += watch.seconds();
  return true;
}

void MpiExchange::send(int octant, const float* face, std::size_t count) {
  const int to = downwind(octant);
  if (to == MPI_PROC_NULL) return;
  // Messages of one octant (one tag) arrive in the order sent: the blocks in sweep order.
  sent_.remove_if([](Sent& s) {
    int done = 0;
    MPI_Test(&s.request, &done, MPI_STATUS_IGNORE);
    return done != 0;
  });
  Sent& s = sent_.emplace_back();
  s.face.assign(face, face + count);
  MPI_Isend(s.face.data(), message_count(count, "face"), MPI_FLOAT, to, octant, comm_, &s.request);
  stats_.messages += 1;
  stats_.bytes_sent += count * sizeof(float);
}

void MpiExchange::finish() {
  for (Sent& s : sent_) MPI_Wait(&s.request, MPI_STATUS_IGNORE);
  sent_.clear();
}

}  // namespace haze::mpi
