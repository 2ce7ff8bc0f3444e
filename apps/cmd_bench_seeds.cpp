// haze bench seeds: each source paper's own setting at its own frame rate (tracker issue 52,
// docs/PERFORMANCE.md "The papers at their own settings"). The rows are bench/seeds/rows.json's: a
// row builds a paper's scene (the builders below) with its method and settings and prepares it
// once; then each frame moves the camera on an orbit and, where the paper's row is dynamic, turns
// the lights and moves the density, and is timed: the solution's update (what changed) and its
// layers at the paper's resolution into a renderer's buffers (Solution::render_layers). The row's
// error is the last frame's, the solution as those updates left it, rendered small
// (--error-width) against the reference path tracer of that frame's scene (--spp), its noise
// removed (lit_pixel_error, docs/TRADEOFFS.md's measure).
#include "commands.h"
#include "seed_rows.h"

#include <haze/core/error.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <memory>

namespace haze::app {
namespace {

struct SeedsArgs {
  std::string rows = HAZE_SEEDS_ROWS;
  std::vector<std::string> papers;  // --paper: these papers only ("001")
  int frames = 30, threads = 2, error_width = 64;
  long long spp = 1024;
  bool json = false;
};

constexpr double kNotMeasured = std::numeric_limits<double>::quiet_NaN();

struct SeedResult {
  double ms = 0.0, update_ms = 0.0, error = 0.0, noise = 0.0;
};

SeedResult run_row(const SeedRow& row, const SeedsArgs& a, std::map<std::string, RenderResult>& references) {
  const Scene base = Scene::from_json(row.scene);
  RenderOptions options;
  options.threads = a.threads;
  options.settings = row.settings;
  Solution solution = prepare(frame_scene(row, base, 0), row.method, options);
  RenderOptions render_options;
  render_options.threads = a.threads;
  std::vector<double> ms, update_ms;
  Scene scene = frame_scene(row, base, 0);
  // The layers a renderer composites, into its own buffers, reused frame after frame.
  const int width = scene.camera.width_px, height = scene.camera.height_px;
  std::vector<float> layers[3];
  for (auto& l : layers) l.resize(static_cast<size_t>(width) * static_cast<size_t>(height) * 3);
  const LayerSpans out{{layers[0].data(), width, height}, {layers[1].data(), width, height}, {layers[2].data(), width, height}};
  for (int f = 1; f <= a.frames; ++f) {
    scene = frame_scene(row, base, f);
    const FrameTime t = play_frame(row, solution, scene, out, render_options);
    ms.push_back(t.ms), update_ms.push_back(t.update_ms);
  }
  // The last frame, small, against the reference of its scene.
  const long long spp = row.reference_spp >= 0 ? row.reference_spp : a.spp;
  if (spp == 0) return {median(ms), median(update_ms), kNotMeasured, kNotMeasured};
  Scene small = scene;
  small.camera.width_px = a.error_width;
  small.camera.height_px = std::max(1, static_cast<int>(std::lround(a.error_width * static_cast<double>(scene.camera.height_px) / scene.camera.width_px)));
  const RenderResult image = solution.render(View{small.camera}, render_options);
  const std::string key = row.scene.dump() + (row.lights_move ? "L" : "") + (row.density_moves ? "D" : "");  // the last frame's scene
  auto found = references.find(key);
  if (found == references.end()) {
    RenderOptions reference;
    reference.threads = a.threads;
    reference.settings = {{"spp", spp}, {"seed", 7}};
    found = references.emplace(key, render(small, method_with_role(MethodInfo::Role::reference), reference)).first;
  }
  const LitPixelError e = lit_pixel_error(image.radiance, found->second.radiance, &*found->second.std_error);
  return {median(ms), median(update_ms), e.rms_noise_removed, e.noise_rms};
}

int run(const SeedsArgs& a) {
  std::vector<SeedRow> rows = seed_rows(a.rows);
  if (!a.papers.empty())
    std::erase_if(rows, [&](const SeedRow& r) { return std::find(a.papers.begin(), a.papers.end(), r.paper) == a.papers.end(); });
  if (rows.empty()) throw Error("--paper", a.papers.empty() ? "" : a.papers[0], "one of 000, 001, 002, 003");
  std::map<std::string, RenderResult> references;
  nlohmann::json out = nlohmann::json::array();
  if (!a.json) {
    std::printf("| paper | row | its hardware | its fps | Haze fps (ms: update + render) | ratio | error (reference noise) |\n|---|---|---|---|---|---|---|\n");
    std::fflush(stdout);
  }
  for (const SeedRow& row : rows) {
    const SeedResult r = run_row(row, a, references);
    const double fps = 1e3 / r.ms;
    out.push_back({{"paper", row.paper}, {"row", row.row}, {"paper_fps", std::isnan(row.paper_fps) ? nlohmann::json() : nlohmann::json(row.paper_fps)},
                   {"fps", fps}, {"median_ms", r.ms}, {"update_ms", r.update_ms}, {"error", std::isnan(r.error) ? nlohmann::json() : nlohmann::json(r.error)},
                   {"reference_noise", std::isnan(r.noise) ? nlohmann::json() : nlohmann::json(r.noise)}, {"method", row.method}, {"settings", row.settings}});
    if (!a.json) {
      const std::string paper_fps = std::isnan(row.paper_fps) ? "not stated" : to_text(row.paper_fps);
      const std::string ratio = std::isnan(row.paper_fps) ? "" : to_text(std::round(100.0 * fps / row.paper_fps) / 100.0) + "x";
      char error[64] = "not measured";
      if (!std::isnan(r.error)) std::snprintf(error, sizeof error, "%.1f%% (%.1f%%)", 100.0 * r.error, 100.0 * r.noise);
      std::printf("| %s | %s | %s | %s | %.1f (%.1f + %.1f ms) | %s | %s |\n", row.paper.c_str(), row.row.c_str(), row.hardware.c_str(), paper_fps.c_str(), fps,
                  r.update_ms, r.ms - r.update_ms, ratio.c_str(), error);
      std::fflush(stdout);
    }
  }
  if (a.json) std::cout << out.dump(1) << "\n";
  return 0;
}

}  // namespace

Command add_bench_seeds(CLI::App& bench) {
  auto* sub = bench.add_subcommand("seeds", "Each source paper's own setting at its own frame rate: Haze's fps and error against the reference");
  auto a = std::make_shared<SeedsArgs>();
  sub->add_option("--rows", a->rows, "The rows (bench/seeds/README.md)")->capture_default_str()->check(CLI::ExistingFile);
  sub->add_option("--paper", a->papers, "Only these papers (000, 001, 002, 003)");
  sub->add_option("--frames", a->frames, "Frames timed per row (the median is reported)")->capture_default_str()->check(CLI::Range(1, 100000));
  sub->add_option("--threads", a->threads, "Thread cap (0: all cores)")->capture_default_str()->check(CLI::NonNegativeNumber);
  sub->add_option("--spp", a->spp, "The reference's samples per pixel for each row's error")->capture_default_str()->check(CLI::Range(1LL, 1LL << 24));
  sub->add_option("--error-width", a->error_width, "Width of the last frame rendered for its error (height keeps the aspect)")
      ->capture_default_str()
      ->check(CLI::Range(8, 1024));
  sub->add_flag("--json", a->json, "Print a JSON list of {paper, row, paper_fps, fps, error, median_ms, update_ms, reference_noise, method, settings}");
  return {sub, [a] { return run(*a); }};
}

}  // namespace haze::app
