// haze::mpi::render_dom (haze/mpi/render.h): the split solve, each rank's stretch of every camera
// ray, and their composition on one rank.
#include <haze/mpi/render.h>

#include <haze/core/error.h>
#include <haze/core/method.h>
#include <haze/core/stopwatch.h>
#include <haze/grids/dom.h>
#include <haze/mpi/dom.h>

#include "exchange.h"

#include <atomic>

namespace haze::mpi {
namespace {

// `part` grown by the plane below its first and the plane above its last, from the ranks that
// solved them (the trilinear stencil of a step near the rank's faces reaches into them).
grids::DomSolution with_neighbour_planes(MPI_Comm comm, grids::DomSolution part, int nz) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const std::size_t plane = static_cast<std::size_t>(part.resolution[0]) * static_cast<std::size_t>(part.resolution[1]) *
                            static_cast<std::size_t>(part.terms());
  const int count = message_count(plane, "plane of moments");
  const bool below = part.first_plane > 0, above = part.first_plane + part.resolution[2] < nz;
  for (std::size_t c = 0; c < part.moments.size(); ++c) {
    const std::vector<float>& own = part.moments[c];
    std::vector<float> grown(own.size() + plane * ((below ? 1 : 0) + (above ? 1 : 0)));
    std::copy(own.begin(), own.end(), grown.begin() + static_cast<long>(below ? plane : 0));
    std::vector<MPI_Request> requests;
    auto exchange = [&](float* into, const float* from, int neighbour) {
      requests.resize(requests.size() + 2);
      MPI_Irecv(into, count, MPI_FLOAT, neighbour, static_cast<int>(c), comm, &requests[requests.size() - 2]);
      MPI_Isend(from, count, MPI_FLOAT, neighbour, static_cast<int>(c), comm, &requests.back());
    };
    if (below) exchange(grown.data(), own.data(), rank - 1);
    if (above) exchange(grown.data() + grown.size() - plane, own.data() + own.size() - plane, rank + 1);
    MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
    part.moments[c] = std::move(grown);
  }
  part.first_plane -= below ? 1 : 0;
  part.resolution[2] += (below ? 1 : 0) + (above ? 1 : 0);
  return part;
}

// A stretch per pixel as floats: L_in r, g, b, then T r, g, b.
std::vector<float> pack(const std::vector<PixelLayers>& layers) {
  std::vector<float> out(6 * layers.size());
  for (std::size_t i = 0; i < layers.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      out[6 * i + static_cast<std::size_t>(c)] = static_cast<float>(layers[i].inscatter[c]);
      out[6 * i + 3 + static_cast<std::size_t>(c)] = static_cast<float>(layers[i].transmittance[c]);
    }
  return out;
}

}  // namespace

RenderResult render_dom(MPI_Comm caller, const Scene& scene, const View& view, const RenderOptions& options, int root) {
  const Duplicate own(caller);
  const MPI_Comm comm = own.comm;
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  if (root < 0 || root >= ranks) throw Error("root", to_text(root), "a rank in [0, " + to_text(ranks) + ")");
  if (!scene.surfaces.empty())
    throw Error("surfaces", to_text(scene.surfaces.size()) + " surfaces",
                "none with the DOM split over MPI ranks (it carries no light between the medium and surfaces yet: render on one process)");
  check_scene(scene);
  RenderOptions setup = options;
  setup.settings = method_settings(scene, "dom", options.settings);  // as haze::prepare takes them
  grids::DomFields f = grids::dom_setup(scene, setup);  // its stats hold depth_seconds
  Stopwatch watch;
  grids::DomSettings settings = f.settings;
  const ProgressCallback& progress = options.progress;
  if (progress) settings.progress = [&](double x) { return progress(0.8 * x); };
  DomPartStats part_stats;
  grids::DomSolution part = solve_dom(comm, f.volume, scene.lights, f.delta_depths, settings, nullptr, &part_stats);
  const double solve_seconds = watch.lap();
  const std::array<int, 2> planes{part.first_plane, part.first_plane + part.resolution[2]};
  const grids::DomSolution grown = with_neighbour_planes(comm, std::move(part), f.volume.density.resolution()[2]);

  // The stretches; a cancel asked on any rank is agreed after them (no rank leaves the others waiting).
  std::atomic<bool> cancel{false};
  RenderOptions gather_options = options;
  gather_options.progress = [&](double x) {
    if (progress && !progress(0.8 + 0.15 * x)) cancel = true;
    return true;
  };
  const std::vector<float> stretch = pack(grids::gather_planes(scene, f.volume, f.delta_depths, grown, f.step_cells, planes, view, gather_options));
  const double gather_seconds = watch.lap();
  int cancelled = cancel ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &cancelled, 1, MPI_INT, MPI_LOR, comm);
  if (cancelled) throw Cancelled();

  const std::array<double, 8> mine{static_cast<double>(part_stats.cells), part_stats.wait_seconds, part_stats.reduce_seconds, solve_seconds,
                                   gather_seconds, static_cast<double>(part_stats.bytes_sent), grown.sweep_seconds, grown.first_collision_seconds};
  std::vector<double> all(mine.size() * static_cast<std::size_t>(ranks));
  MPI_Gather(mine.data(), static_cast<int>(mine.size()), MPI_DOUBLE, all.data(), static_cast<int>(mine.size()), MPI_DOUBLE, root, comm);
  if (rank != root) {
    send_floats(comm, stretch.data(), stretch.size(), root);
    return RenderResult{};
  }

  // Ranks in z order: front to back where a ray goes up the planes (L += T L_r), back to front
  // where it goes down (L = L_r + T_r L); T *= T_r either way.
  const Camera& camera = view.camera;
  const std::size_t pixels = stretch.size() / 6;
  std::vector<PixelLayers> scattered(pixels);
  std::vector<char> up(pixels);
  for (int y = 0; y < camera.height_px; ++y)
    for (int x = 0; x < camera.width_px; ++x)
      up[static_cast<std::size_t>(y) * static_cast<std::size_t>(camera.width_px) + static_cast<std::size_t>(x)] = camera.pixel_ray(x, y).direction.z >= 0.0;
  std::vector<float> received(rank == root && ranks > 1 ? stretch.size() : 0);
  for (int r = 0; r < ranks; ++r) {
    if (r != root) receive_floats(comm, received.data(), received.size(), r);
    const std::vector<float>& s = r == root ? stretch : received;
    for (std::size_t i = 0; i < pixels; ++i) {
      const Rgb light(s[6 * i], s[6 * i + 1], s[6 * i + 2]), through(s[6 * i + 3], s[6 * i + 4], s[6 * i + 5]);
      PixelLayers& p = scattered[i];
      p.inscatter = up[i] ? p.inscatter + p.transmittance * light : light + through * p.inscatter;
      p.transmittance *= through;
    }
  }
  RenderOptions march_options = options;
  march_options.progress = progress ? [&](double x) { return progress(0.95 + 0.05 * x); } : ProgressCallback();
  RenderResult result = grids::render_dom(scene, f.volume, f.delta_depths, grown.delta_m_fraction, f.step_cells, march_options, view, scattered);
  result.stats = f.stats;
  auto column = [&](std::size_t k) {
    nlohmann::json v = nlohmann::json::array();
    for (int r = 0; r < ranks; ++r) {
      const double x = all[static_cast<std::size_t>(r) * mine.size() + k];
      v.push_back(k == 0 || k == 5 ? nlohmann::json(static_cast<long long>(x)) : nlohmann::json(x));  // cells and bytes as integers
    }
    return v;
  };
  result.stats.update({{"ranks", ranks},
                       {"cells", f.volume.density.resolution()},
                       {"directions", settings.directions},
                       {"terms", grown.terms()},
                       {"iterations", grown.iterations},
                       {"converged", grown.converged},
                       {"final_change", grown.changes.empty() ? 0.0 : grown.changes.back()},
                       {"rank_cells", column(0)},
                       {"rank_wait_seconds", column(1)},
                       {"rank_reduce_seconds", column(2)},
                       {"rank_solve_seconds", column(3)},
                       {"rank_gather_seconds", column(4)},
                       {"rank_bytes_sent", column(5)},
                       {"rank_sweep_seconds", column(6)},
                       {"rank_first_collision_seconds", column(7)},
                       {"render_seconds", watch.lap()}});
  return result;
}

}  // namespace haze::mpi
