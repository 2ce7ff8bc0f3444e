// The source papers' own settings (bench/seeds/rows.json, its README): a row's scene at the paper's
// resolution, Haze's method and settings, and what moves frame to frame; read by `haze bench seeds`
// and `haze demo`.
#pragma once

#include <haze/core/scene.h>
#include <haze/core/method.h>

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace haze::app {

// One paper's setting (a row of bench/seeds/rows.json): the scene at the paper's resolution, Haze's
// method and settings, what moves frame to frame, and the frame rate the paper states (NaN: none).
struct SeedRow {
  std::string paper, row, hardware;
  double paper_fps;
  std::string method;
  nlohmann::json settings, scene;
  bool lights_move = false, density_moves = false;
  Vec3 look_at{0.0};
  double orbit_radius = 4.0, orbit_height = 0.5;
  long long reference_spp = -1;  // the row's own (0: no error measured), else --spp
};

// The rows of a rows.json file, their scenes built; throws haze::Error naming a bad row's field.
std::vector<SeedRow> seed_rows(const std::string& path);

// Frame f's scene: the camera on its orbit (0.02 rad a frame), the lights turned about the vertical
// through the orbit's centre (1 degree a frame), the density moved (RBF centres drifting, a uniform
// density breathing by 20%, as paper 000's figure 1 varies it).
Scene frame_scene(const SeedRow& row, const Scene& base, int f);

// One timed frame as a renderer runs it: the solution updated with what the row moves in `scene`
// (its lights, its medium), then its layers of `scene`'s camera into `out`.
struct FrameTime {
  double ms = 0.0, update_ms = 0.0;
};
FrameTime play_frame(const SeedRow& row, Solution& solution, const Scene& scene, const LayerSpans& out, const RenderOptions& options);

}  // namespace haze::app
