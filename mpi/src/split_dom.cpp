// Method dom split over MPI ranks (haze/mpi/methods.h): the split solve at prepare; each rank's
// stretch of every camera ray, and their composition on rank 0, at render.
#include <haze/mpi/methods.h>

#include <haze/core/error.h>
#include <haze/core/method.h>
#include <haze/core/stopwatch.h>
#include <haze/grids/dom.h>
#include <haze/mpi/dom.h>

#include "exchange.h"

#include <atomic>
#include <memory>

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


int rank_of(MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  return rank;
}

class MpiRanks final : public Ranks {
 public:
  explicit MpiRanks(MPI_Comm comm) : comm_(comm) {}
  int rank() const override { return rank_of(comm_); }
  int size() const override {
    int ranks = 1;
    MPI_Comm_size(comm_, &ranks);
    return ranks;
  }
  MPI_Comm comm() const { return comm_; }

 private:
  MPI_Comm comm_;
};

// A column of per-rank figures gathered on rank 0 (an empty array elsewhere); cells and bytes as integers.
nlohmann::json per_rank(MPI_Comm comm, double mine, bool integer) {
  const int ranks = MpiRanks(comm).size();
  std::vector<double> all(static_cast<std::size_t>(ranks));
  MPI_Gather(&mine, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, 0, comm);
  nlohmann::json v = nlohmann::json::array();
  if (rank_of(comm) == 0)
    for (const double x : all) v.push_back(integer ? nlohmann::json(static_cast<long long>(x)) : nlohmann::json(x));
  return v;
}

class SplitDomSolution final : public MethodSolution {
 public:
  SplitDomSolution(MPI_Comm caller, const Scene& scene, const RenderOptions& options)
      : own_(caller), scene_(view_scene(scene, scene.camera)), fields_(setup(scene, options)) {
    const MPI_Comm comm = own_.comm;
    Stopwatch watch;
    grids::DomSettings settings = fields_.settings;
    if (options.progress) settings.progress = options.progress;
    DomPartStats part_stats;
    grids::DomSolution part = solve_dom(comm, fields_.volume, scene.lights, fields_.delta_depths, settings, nullptr, &part_stats);
    const double solve_seconds = watch.lap();
    planes_ = {part.first_plane, part.first_plane + part.resolution[2]};
    grown_ = with_neighbour_planes(comm, std::move(part), fields_.volume.density.resolution()[2]);
    stats = fields_.stats;
    stats.update({{"ranks", MpiRanks(comm).size()},
                  {"cells", fields_.volume.density.resolution()},
                  {"directions", settings.directions},
                  {"terms", grown_.terms()},
                  {"iterations", grown_.iterations},
                  {"converged", grown_.converged},
                  {"final_change", grown_.changes.empty() ? 0.0 : grown_.changes.back()},
                  {"rank_cells", per_rank(comm, static_cast<double>(part_stats.cells), true)},
                  {"rank_wait_seconds", per_rank(comm, part_stats.wait_seconds, false)},
                  {"rank_reduce_seconds", per_rank(comm, part_stats.reduce_seconds, false)},
                  {"rank_solve_seconds", per_rank(comm, solve_seconds, false)},
                  {"rank_bytes_sent", per_rank(comm, static_cast<double>(part_stats.bytes_sent), true)},
                  {"rank_sweep_seconds", per_rank(comm, grown_.sweep_seconds, false)},
                  {"rank_first_collision_seconds", per_rank(comm, grown_.first_collision_seconds, false)}});
  }

  bool renders_layers() const override { return true; }

  RenderResult render(const View& view, const RenderOptions& options) const override {
    const MPI_Comm comm = own_.comm;
    const int rank = rank_of(comm), ranks = MpiRanks(comm).size();
    Stopwatch watch;
    // The stretches; a cancel asked on any rank is agreed after them (no rank leaves the others waiting).
    const ProgressCallback& progress = options.progress;
    std::atomic<bool> cancel{false};
    RenderOptions gather_options = options;
    gather_options.progress = [&](double x) {
      if (progress && !progress(0.9 * x)) cancel = true;
      return true;
    };
    const Scene scene = view_scene(scene_, view.camera);
    const std::vector<float> stretch =
        pack(grids::gather_planes(scene, fields_.volume, fields_.delta_depths, grown_, fields_.step_cells, planes_, view, gather_options));
    const double gather_seconds = watch.lap();
    int cancelled = cancel ? 1 : 0;
    MPI_Allreduce(MPI_IN_PLACE, &cancelled, 1, MPI_INT, MPI_LOR, comm);
    if (cancelled) throw Cancelled();
    nlohmann::json gathered = per_rank(comm, gather_seconds, false);
    if (rank != 0) {
      send_floats(comm, stretch.data(), stretch.size(), 0);
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
    std::vector<float> received(ranks > 1 ? stretch.size() : 0);
    for (int r = 0; r < ranks; ++r) {
      if (r != 0) receive_floats(comm, received.data(), received.size(), r);
      const std::vector<float>& s = r == 0 ? stretch : received;
      for (std::size_t i = 0; i < pixels; ++i) {
        const Rgb light(s[6 * i], s[6 * i + 1], s[6 * i + 2]), through(s[6 * i + 3], s[6 * i + 4], s[6 * i + 5]);
        PixelLayers& p = scattered[i];
        p.inscatter = up[i] ? p.inscatter + p.transmittance * light : light + through * p.inscatter;
        p.transmittance *= through;
      }
    }
    RenderOptions march_options = options;
    march_options.progress = progress ? [&](double x) { return progress(0.9 + 0.1 * x); } : ProgressCallback();
    RenderResult result = grids::add_unscattered(scene, fields_.volume, fields_.delta_depths, grown_.delta_m_fraction, fields_.step_cells, march_options, view, scattered);
    result.stats = {{"rank_gather_seconds", std::move(gathered)}, {"render_seconds", watch.lap()}};
    return result;
  }

 private:
  // The volume and the depths to the lights, whole on every rank; stats["depth_seconds"].
  static grids::DomFields setup(const Scene& scene, const RenderOptions& options) {
    if (!scene.surfaces.empty())
      throw Error("surfaces", to_text(scene.surfaces.size()) + " surfaces",
                  "none with the DOM split over MPI ranks (it carries no light between the medium and surfaces yet: render on one process)");
    return grids::dom_setup(scene, options);
  }

  Duplicate own_;  // the solution's own communicator
  Scene scene_;    // lights and background, without the medium
  grids::DomFields fields_;
  std::array<int, 2> planes_{0, 0};
  grids::DomSolution grown_;  // this rank's planes and its neighbours' next to them
};

class SplitDom final : public Method {
 public:
  std::unique_ptr<MethodSolution> prepare(const Scene& scene, const RenderOptions& options) const override {
    const auto* ranks = dynamic_cast<const MpiRanks*>(options.ranks.get());
    if (!ranks) throw Error("options.ranks", "ranks not made by haze::mpi::ranks", "an MPI communicator's ranks (haze::mpi::ranks)");
    return std::make_unique<SplitDomSolution>(ranks->comm(), scene, options);
  }
};

}  // namespace

std::shared_ptr<const Ranks> ranks(MPI_Comm comm) { return std::make_shared<MpiRanks>(comm); }

void register_methods() {
  register_split(grids::dom_info().name, [] { return std::make_unique<SplitDom>(); });
}

}  // namespace haze::mpi
