// haze_mpi_scaling: one distributed DOM solve under mpirun, each rank's time, wait and messages
// printed by rank 0 as one JSON line (docs/SCALING.md). A cloud of Gaussian density (the DOM
// tests' shape) on nx x ny x nz cells lit by a sun, one grey channel, one thread per rank.
// Usage: mpirun -np R haze_mpi_scaling [nx ny nz] [directions] [terms] [rows per message: 4; ny for whole faces]
#include <haze/grids/optical_depth.h>
#include <haze/mpi/dom.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  auto arg = [&](int i, int fallback) { return argc > i ? std::atoi(argv[i]) : fallback; };
  const std::array<int, 3> n{arg(1, 48), arg(2, 48), arg(3, 48)};
  using namespace haze;
  grids::ExtinctionVolume volume{grids::DenseGrid(n, {Vec3(-1.0), Vec3(1.0)}), Rgb(4.0), Rgb(0.9), PhaseFunction::henyey_greenstein(0.5)};
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        const Vec3 x = volume.density.cell_center(i, j, k);
        volume.density.at(i, j, k) = static_cast<float>(std::exp(-2.0 * glm::dot(x, x)));
      }
  const std::vector<Light> lights{DirectionalLight{glm::normalize(Vec3(0.3, -1.0, 0.2)), Rgb(1.0)}};
  const std::vector<grids::DenseGrid> depths{grids::optical_depth(volume.density, lights[0], {grids::DepthScheme::exact})};
  grids::DomSettings settings;
  settings.directions = arg(4, 128);
  settings.terms = arg(5, 25);
  settings.threads = 1;
  settings.rows_per_message = arg(6, 4);
  mpi::DomPartStats stats;
  MPI_Barrier(MPI_COMM_WORLD);
  const grids::DomSolution part = mpi::solve_dom(MPI_COMM_WORLD, volume, lights, depths, settings, nullptr, &stats);
  // Per rank: cells, whole time, sweep time, waiting, reducing, messages and bytes sent.
  const double mine[7] = {static_cast<double>(stats.cells), stats.seconds, part.sweep_seconds, stats.wait_seconds, stats.reduce_seconds,
                          static_cast<double>(stats.messages), static_cast<double>(stats.bytes_sent)};
  std::vector<double> all(7 * static_cast<size_t>(ranks));
  MPI_Gather(mine, 7, MPI_DOUBLE, all.data(), 7, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  if (rank == 0) {
    std::printf("{\"ranks\": %d, \"cells\": [%d, %d, %d], \"directions\": %d, \"terms\": %d, \"rows_per_message\": %d, \"sweeps\": %d, \"per_rank\": [", ranks, n[0], n[1],
                n[2], settings.directions, settings.terms, settings.rows_per_message, part.iterations);
    for (int r = 0; r < ranks; ++r) {
      const double* v = all.data() + 7 * r;
      // Grind time: sweep seconds, less the waiting inside them, per cell, direction and sweep.
      const double grind_ns = 1e9 * (v[2] - v[3]) / (v[0] * settings.directions * part.iterations);
      std::printf("%s{\"cells\": %.0f, \"seconds\": %.3f, \"sweep_seconds\": %.3f, \"wait_seconds\": %.3f, \"reduce_seconds\": %.4f, "
                  "\"messages\": %.0f, \"bytes_sent\": %.0f, \"grind_ns\": %.2f}",
                  r ? ", " : "", v[0], v[1], v[2], v[3], v[4], v[5], v[6], grind_ns);
    }
    std::printf("]}\n");
  }
  MPI_Finalize();
  return 0;
}
