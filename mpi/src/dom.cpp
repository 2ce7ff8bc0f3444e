// haze::mpi::solve_dom and gather (haze/mpi/dom.h): grids::solve_dom on each rank's z planes
// through an MpiExchange, with the checks that keep every rank taking the same path.
#include <haze/mpi/dom.h>

#include <haze/core/error.h>
#include <haze/core/stopwatch.h>

#include "exchange.h"

#include <algorithm>

namespace haze::mpi {
namespace {

// What must be the same on every rank, as numbers: sizes, settings and a checksum of the density
// and the depths.
std::vector<double> fingerprint(const grids::ExtinctionVolume& volume, const std::vector<Light>& lights,
                                const std::vector<grids::DenseGrid>& depths, const grids::DomSettings& s) {
  auto checksum = [](const std::vector<float>& v) {
    double sum = 0.0;
    for (size_t i = 0; i < v.size(); ++i) sum += static_cast<double>(v[i]) * static_cast<double>(1 + i % 7);
    return sum;
  };
  const auto& n = volume.density.resolution();
  std::vector<double> f{static_cast<double>(n[0]), static_cast<double>(n[1]), static_cast<double>(n[2]),
                        static_cast<double>(s.directions), static_cast<double>(s.terms), static_cast<double>(s.max_iterations),
                        s.tolerance, static_cast<double>(s.scheme), static_cast<double>(s.spatial), static_cast<double>(s.accelerator),
                        static_cast<double>(s.storage), s.delta_m ? 1.0 : 0.0, static_cast<double>(s.rows_per_message), static_cast<double>(lights.size()),
                        static_cast<double>(depths.size()), checksum(volume.density.values())};
  for (int c = 0; c < 3; ++c) f.push_back(volume.sigma_t_scale[c]), f.push_back(volume.albedo[c]);
  for (const auto& d : depths) f.push_back(checksum(d.values()));
  return f;
}

}  // namespace

std::array<int, 2> split_planes(int planes, int ranks, int rank) {
  if (ranks < 1 || rank < 0 || rank >= ranks) throw Error("rank", to_text(rank) + " of " + to_text(ranks), "a rank in [0, ranks)");
  if (planes < ranks)
    throw Error("ranks", to_text(ranks), "at most as many ranks as the grid's " + to_text(planes) + " z planes (each solves at least one)");
  const int base = planes / ranks, extra = planes % ranks;
  const int first = rank * base + std::min(rank, extra);
  return {first, first + base + (rank < extra ? 1 : 0)};
}

grids::DomSolution solve_dom(MPI_Comm comm, const grids::ExtinctionVolume& volume, const std::vector<Light>& lights,
                             const std::vector<grids::DenseGrid>& delta_depths, const grids::DomSettings& settings,
                             const grids::DomSolution* warm, DomPartStats* stats, std::array<int, 2> planes) {
  const Stopwatch watch;
  const Duplicate own(comm);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(own.comm, &rank);
  MPI_Comm_size(own.comm, &ranks);
  // The same inputs everywhere, or every rank says so (a mismatch would hang the pipeline).
  const std::vector<double> mine = fingerprint(volume, lights, delta_depths, settings);
  const int size = static_cast<int>(mine.size());
  int largest = size;
  MPI_Allreduce(MPI_IN_PLACE, &largest, 1, MPI_INT, MPI_MAX, own.comm);
  std::vector<double> padded(mine);
  padded.resize(static_cast<size_t>(largest), -1.0);
  std::vector<double> all(static_cast<size_t>(largest) * static_cast<size_t>(ranks));
  MPI_Allgather(padded.data(), largest, MPI_DOUBLE, all.data(), largest, MPI_DOUBLE, own.comm);
  for (int r = 1; r < ranks; ++r)
    if (!std::equal(all.begin(), all.begin() + largest, all.begin() + static_cast<long>(r) * largest))
      throw Error("ranks", "rank " + to_text(r) + " with another volume, lights or settings than rank 0",
                  "the same volume, depths, lights and settings on every rank");

  // The ranks' planes, given or split, in rank order from the first plane to the last.
  const int nz = volume.density.resolution()[2];
  if (!(planes[0] < planes[1])) planes = split_planes(nz, ranks, rank);
  std::vector<int> all_planes(2 * static_cast<size_t>(ranks));
  MPI_Allgather(planes.data(), 2, MPI_INT, all_planes.data(), 2, MPI_INT, own.comm);
  for (int r = 0; r < ranks; ++r) {
    const int first = all_planes[2 * static_cast<size_t>(r)], last = all_planes[2 * static_cast<size_t>(r) + 1];
    const int expected = r == 0 ? 0 : all_planes[2 * static_cast<size_t>(r) - 1];
    if (first != expected || !(first < last) || last > nz || (r == ranks - 1 && last != nz))
      throw Error("planes", "[" + to_text(first) + ", " + to_text(last) + ") on rank " + to_text(r) + " of " + to_text(ranks),
                  "planes following each other in rank order, from 0 to the grid's " + to_text(nz) + " (rank " + to_text(r) + " from " +
                      to_text(expected) + ")");
  }
  MpiExchange exchange(own.comm, planes);
  exchange.rows_per_message = settings.rows_per_message;
  grids::DomSettings part = settings;
  part.exchange = &exchange;
  // Cancelling is collective: every rank stops at the same iteration when any callback says stop.
  part.progress = [&](double fraction) { return exchange.all(settings.progress ? settings.progress(fraction) : true); };
  grids::DomSolution out;
  try {
    out = grids::solve_dom(volume, lights, delta_depths, part, warm);
  } catch (...) {
    exchange.fail();  // when the checks failed here, the other ranks hear of it at begin()
    throw;
  }
  exchange.finish();
  if (stats) {
    *stats = exchange.stats();
    stats->cells = static_cast<size_t>(out.resolution[0]) * static_cast<size_t>(out.resolution[1]) * static_cast<size_t>(out.resolution[2]);
    stats->seconds = watch.seconds();
  }
  return out;
}

grids::DomSolution gather(MPI_Comm comm, const grids::DomSolution& part, int root) {
  const Duplicate own(comm);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(own.comm, &rank);
  MPI_Comm_size(own.comm, &ranks);
  if (root < 0 || root >= ranks) throw Error("root", to_text(root), "a rank in [0, " + to_text(ranks) + ")");
  std::array<int, 2> mine{part.first_plane, part.resolution[2]};
  std::vector<int> planes(2 * static_cast<size_t>(ranks));
  MPI_Allgather(mine.data(), 2, MPI_INT, planes.data(), 2, MPI_INT, own.comm);
  unsigned long long bytes = part.bytes;
  MPI_Allreduce(MPI_IN_PLACE, &bytes, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, own.comm);
  const size_t plane = static_cast<size_t>(part.resolution[0]) * static_cast<size_t>(part.resolution[1]) * static_cast<size_t>(part.terms());
  if (rank != root) {
    for (const auto& m : part.moments) send_floats(own.comm, m.data(), m.size(), root);
    return part;
  }
  grids::DomSolution whole = part;
  whole.first_plane = 0;
  whole.resolution[2] = 0;
  for (int r = 0; r < ranks; ++r) whole.resolution[2] += planes[2 * static_cast<size_t>(r) + 1];
  whole.bytes = bytes;
  for (size_t c = 0; c < whole.moments.size(); ++c) {
    std::vector<float>& m = whole.moments[c];
    m.assign(plane * static_cast<size_t>(whole.resolution[2]), 0.0f);
    for (int r = 0; r < ranks; ++r) {
      float* to = m.data() + plane * static_cast<size_t>(planes[2 * static_cast<size_t>(r)]);
      const size_t count = plane * static_cast<size_t>(planes[2 * static_cast<size_t>(r) + 1]);
      if (r == root) {
        std::copy(part.moments[c].begin(), part.moments[c].end(), to);
        continue;
      }
      receive_floats(own.comm, to, count, r);
    }
  }
  return whole;
}

}  // namespace haze::mpi
