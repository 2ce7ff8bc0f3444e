// haze demo: the source papers' showcase (tracker issue 52). Each paper's own scene
// (examples/demo/showcase.json names rows of bench/seeds/rows.json) at its own resolution, the
// camera moving on its orbit and the lights or the density where the paper moves them, as
// `haze bench seeds` runs it: each frame's update and layers timed, and written (outside the time)
// into an animated GIF. Then the last frame, small, against the low-noise references shipped in
// examples/demo (made once by `haze demo --make-references`), and a table of paper, setting, the
// paper's frame rate, Haze's and that error. `--sheets`: the contact sheets of every method on
// examples/*.json instead (cmd_demo_sheets.cpp).
#include "commands.h"
#include "demo.h"
#include "gif.h"
#include "progress_bar.h"
#include "seed_rows.h"

#include <haze/core/error.h>
#include <haze/core/math.h>
#include <haze/core/stopwatch.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

namespace haze::app {
namespace {

constexpr int kGifDelayCs = 4;  // the preview at 25 frames a second

struct Showcase {
  std::filesystem::path dir;  // examples/demo: the references beside showcase.json
  std::string made_by;
  int frames = 60, error_width = 48;
  double target_noise = 0.01;
  std::vector<SeedRow> rows;
};

Showcase load_showcase(const std::string& examples) {
  Showcase s;
  s.dir = std::filesystem::path(examples) / "demo";
  const auto file = s.dir / "showcase.json";
  std::ifstream in(file);
  if (!in) throw Error("--examples", examples, "a directory with demo/showcase.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  s.made_by = j.at("made_by"), s.frames = j.at("frames"), s.error_width = j.at("error_width"), s.target_noise = j.at("target_noise");
  const std::vector<SeedRow> all = seed_rows(HAZE_SEEDS_ROWS);
  for (const nlohmann::json& r : j.at("rows")) {
    const auto found = std::find_if(all.begin(), all.end(), [&](const SeedRow& row) { return row.paper == r.at("paper") && row.row == r.at("row"); });
    if (found == all.end()) throw Error(file.string() + ": rows", r.dump(), "a paper and row of bench/seeds/rows.json");
    s.rows.push_back(*found);
  }
  return s;
}

// The reference a row's last frame is compared with: the full transport, or (`single`) the light
// paths a single-scattering method computes (one medium scattering event and one reflection).
struct Reference {
  std::filesystem::path exr, json;
  std::string key;  // the last frame's scene, the size and the light paths: a stale file differs
};

Reference reference_of(const Showcase& s, const SeedRow& row, bool single) {
  const std::string stem = "paper" + row.paper + (single ? "_single" : "");
  const std::string what = row.scene.dump() + (row.lights_move ? "L" : "") + (row.density_moves ? "D" : "") + to_text(s.frames) + "x" +
                           to_text(s.error_width) + (single ? "single" : "full");
  return {s.dir / (stem + ".exr"), s.dir / (stem + ".json"), to_text(std::hash<std::string>{}(what))};
}

// The row's last frame at the error's width (the height keeps the aspect).
Scene error_scene(const Showcase& s, const SeedRow& row) {
  Scene scene = frame_scene(row, Scene::from_json(row.scene), s.frames);
  const double aspect = static_cast<double>(scene.camera.height_px) / scene.camera.width_px;
  scene.camera.width_px = s.error_width;
  scene.camera.height_px = std::max(1, static_cast<int>(std::lround(s.error_width * aspect)));
  return scene;
}

bool single_scattering(const SeedRow& row) {
  for (const MethodInfo& m : registered_methods())
    if (m.name == row.method) return m.single_scattering;
  return false;
}

// The row's reference: a 64-spp pilot gives the noise and the time per sample, then the samples
// that bring the noise to the showcase's target, or those `seconds` buys if fewer.
void make_reference(const Showcase& s, const SeedRow& row, bool single, int threads, double seconds) {
  const Reference r = reference_of(s, row, single);
  const Scene scene = error_scene(s, row);
  auto render_at = [&](long long spp, const std::string& label) {
    RenderOptions options;
    options.threads = threads;
    options.settings = {{"spp", spp}, {"seed", 11}};
    if (single) options.settings["max_scattering"] = 1, options.settings["max_bounces"] = 1;
    ProgressBar bar(label);
    options.progress = bar.callback();
    return render(scene, method_with_role(MethodInfo::Role::reference), options);
  };
  auto noise_of = [](const RenderResult& result) { return lit_pixel_error(result.radiance, result.radiance, &*result.std_error).noise_rms; };
  const std::string label = "paper " + row.paper + (single ? " single-scattering" : "") + " reference";
  constexpr long long kPilot = 64;
  Stopwatch watch;
  const double pilot_noise = std::max(noise_of(render_at(kPilot, label + " pilot")), 1e-6);
  const double per_sample = watch.seconds() / kPilot;
  const double want = kPilot * (pilot_noise / s.target_noise) * (pilot_noise / s.target_noise);
  const long long spp = static_cast<long long>(std::ceil(std::clamp(std::min(want, seconds / per_sample), 256.0, 1e9) / 64.0)) * 64;
  std::printf("%s: %lld spp, about %.0f s (noise %.1f%% at %lld spp; %.0f spp would reach %.1f%%)\n", r.exr.string().c_str(), spp, per_sample * spp,
              100.0 * pilot_noise, kPilot, want, 100.0 * s.target_noise);
  std::fflush(stdout);
  watch.restart();
  const RenderResult result = render_at(spp, label);
  const double noise = noise_of(result);
  write_exr(r.exr, result.radiance, &*result.std_error);
  std::ofstream(r.json) << nlohmann::json{{"key", r.key}, {"paper", row.paper},      {"row", row.row},           {"single_scattering", single},
                                          {"spp", spp},   {"noise", noise},          {"seconds", watch.seconds()}, {"made_by", s.made_by}}
                               .dump(1)
                        << "\n";
  std::printf("%s: noise %.2f%%, %.0f s\n", r.exr.string().c_str(), 100.0 * noise, watch.seconds());
  std::fflush(stdout);
}

// A row's last frame against a shipped reference: "12.3% (0.9%)", the error over the lit pixels
// with the reference's noise removed and that noise, or why there is none.
std::string error_against(const Showcase& s, const SeedRow& row, bool single, const Image& image) {
  const Reference r = reference_of(s, row, single);
  std::ifstream in(r.json);
  if (!in || !std::filesystem::exists(r.exr)) return "no reference (" + s.made_by + ")";
  if (nlohmann::json::parse(in).at("key") != r.key) return "stale reference (" + s.made_by + ")";
  std::optional<Image> se;
  const Image reference = read_exr(r.exr, &se);
  const LitPixelError e = lit_pixel_error(image, reference, &*se);
  char text[64];
  std::snprintf(text, sizeof text, "%.1f%% (%.1f%%)", 100.0 * e.rms_noise_removed, 100.0 * e.noise_rms);
  return text;
}

// The exposure the preview shows a row with: the 95th percentile of the first frame's luminance
// over its lit pixels (above 1% of its peak) at 1 (Reinhard's half grey).
double preview_exposure(const Image& frame) {
  std::vector<double> lum;
  double peak = 0.0;
  for (int y = 0; y < frame.height(); ++y)
    for (int x = 0; x < frame.width(); ++x) lum.push_back(luminance(frame.at(x, y))), peak = std::max(peak, lum.back());
  std::erase_if(lum, [&](double l) { return l <= 0.01 * peak; });
  if (lum.empty()) return 1.0;
  std::nth_element(lum.begin(), lum.begin() + static_cast<std::ptrdiff_t>(lum.size() * 95 / 100), lum.end());
  return 1.0 / std::max(lum[lum.size() * 95 / 100], 1e-12);
}

struct RowRun {
  double ms = 0.0, update_ms = 0.0;  // the median frame's
  Image last;                        // the last frame at the error's size
};

RowRun run_row(const Showcase& s, const SeedRow& row, const std::filesystem::path& gif_path, const std::filesystem::path& png_path, int threads) {
  const Scene base = Scene::from_json(row.scene);
  RenderOptions options;
  options.threads = threads;
  options.settings = row.settings;
  RowRun run;
  Solution solution = prepare(frame_scene(row, base, 0), row.method, options);
  RenderOptions render_options;
  render_options.threads = threads;
  const int width = base.camera.width_px, height = base.camera.height_px;
  std::vector<float> layers[3];
  for (auto& l : layers) l.resize(static_cast<size_t>(width) * static_cast<size_t>(height) * 3);
  const LayerSpans out{{layers[0].data(), width, height}, {layers[1].data(), width, height}, {layers[2].data(), width, height}};
  AnimatedGif gif(gif_path, width, height, kGifDelayCs);
  Image frame(width, height);
  double exposure = 1.0;
  std::vector<double> ms, update_ms;
  ProgressBar bar("paper " + row.paper + ": " + to_text(s.frames) + " frames");
  const ProgressCallback progress = bar.callback();
  Scene scene;
  for (int f = 1; f <= s.frames; ++f) {
    scene = frame_scene(row, base, f);
    const FrameTime t = play_frame(row, solution, scene, out, render_options);
    ms.push_back(t.ms), update_ms.push_back(t.update_ms);
    // The frame a renderer shows: L_in + T C.
    for (size_t i = 0; i < layers[0].size(); ++i) frame.data()[i] = layers[0][i] + layers[1][i] * layers[2][i];
    if (f == 1) exposure = preview_exposure(frame);
    gif.add(frame, exposure);
    if (progress) progress(static_cast<double>(f) / s.frames);
  }
  gif.close();
  write_png(png_path, frame, exposure);
  run.ms = median(ms), run.update_ms = median(update_ms);
  Scene small = error_scene(s, row);
  run.last = solution.render(View{small.camera}, render_options).radiance;
  return run;
}

int run_showcase(const DemoArgs& a) {
  const Showcase s = load_showcase(a.examples);
  if (a.make_references) {
    for (const SeedRow& row : s.rows) {
      make_reference(s, row, false, a.threads, a.reference_seconds);
      if (single_scattering(row)) make_reference(s, row, true, a.threads, a.reference_seconds);
    }
    return 0;
  }
  std::filesystem::create_directories(a.out);
  std::printf("haze demo: the source papers' own scenes at their resolutions, %d frames each, the camera moving (and the\n"
              "lights or the density where the paper moves them); each frame's update and layers timed on %s, the\n"
              "previews written beside (about a minute in all; `haze demo --sheets` compares every method instead).\n\n",
              s.frames, a.threads > 0 ? (to_text(a.threads) + " threads").c_str() : "all cores");
  std::printf("| paper | setting | its hardware | its fps | Haze fps (ms: update + render) | ratio | error (reference noise) | preview |\n"
              "|---|---|---|---|---|---|---|---|\n");
  std::fflush(stdout);
  for (const SeedRow& row : s.rows) {
    const auto gif = std::filesystem::path(a.out) / ("paper" + row.paper + ".gif");
    const RowRun run = run_row(s, row, gif, std::filesystem::path(gif).replace_extension(".png"), a.threads);
    const double fps = 1e3 / run.ms;
    std::string error = error_against(s, row, false, run.last);
    if (single_scattering(row)) error += "; single scattering: " + error_against(s, row, true, run.last);
    std::printf("| %s | %s | %s | %s | %.1f (%.1f + %.1f ms) | %.2fx | %s | %s |\n", row.paper.c_str(), row.row.c_str(), row.hardware.c_str(),
                to_text(row.paper_fps).c_str(), fps, run.update_ms, run.ms - run.update_ms, fps / row.paper_fps, error.c_str(), gif.string().c_str());
    std::fflush(stdout);
  }
  std::printf("\nHaze fps: the median frame (the solution's update and its layers at the paper's resolution into a\n"
              "renderer's buffers; preparing the solution before the first frame not counted). error: the last frame\n"
              "at %d pixels across against the reference path tracer's image of it (examples/demo, made by `%s`),\n"
              "relative RMS over the lit pixels with the reference's noise (in brackets) removed. Single-scattering\n"
              "methods (papers 002, 003) leave out the light scattered more than once: their error against the\n"
              "full transport is mostly that; against the single-scattering reference, their own.\n",
              s.error_width, s.made_by.c_str());
  return 0;
}

}  // namespace

Command add_demo(CLI::App& app) {
  auto* sub = app.add_subcommand("demo", "The source papers' scenes moving at their own resolutions: frame rates, errors, animated previews");
  auto a = std::make_shared<DemoArgs>();
  sub->add_option("--out", a->out, "Output directory")->capture_default_str();
  sub->add_option("--examples", a->examples, "The examples directory (demo/showcase.json and its references; --sheets: its scenes)")->capture_default_str();
  sub->add_option("--threads", a->threads, "Thread cap (0: all cores)")->check(CLI::NonNegativeNumber);
  sub->add_flag("--make-references", a->make_references, "Render the showcase's references into <examples>/demo (minutes to hours)");
  sub->add_flag("--sheets", a->sheets, "Instead: every method on examples/*.json against cached references, contact sheets");
  sub->add_option("--reference-seconds", a->reference_seconds,
                  "Time each reference may take (--make-references: the showcase's, stopping at its target noise; --sheets: each uncached one, at 1%)")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 86400.0));
  return {sub, [a] { return a->sheets ? run_sheets(*a) : run_showcase(*a); }};
}

}  // namespace haze::app
