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

#include <haze/core/error.h>
#include <haze/core/rng.h>
#include <haze/core/stopwatch.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
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

nlohmann::json camera_json(int width, int height, double fov) {
  return {{"position", {0.0, 0.5, 4.0}}, {"look_at", {0.0, 0.0, 0.0}}, {"fov_y_deg", fov}, {"width_px", width}, {"height_px", height}};
}

// The scenes rows.json's rows build. Seed 001, section 4: a cloud of N particles (albedo 0.9, g 0, 2 R tau = 20: sigma_t 10 over the
// unit ball's density 1), two suns (left-up and bottom-right) and a sky, 512 x 512.
nlohmann::json network_cloud(int count) {
  Rng rng(3);
  nlohmann::json positions = nlohmann::json::array();
  while (static_cast<int>(positions.size()) < count) {
    const Vec3 x(2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
    if (glm::dot(x, x) < 1.0) positions.push_back({x.x, x.y, x.z});
  }
  return {{"camera", camera_json(512, 512, 40.0)},
          {"particles", {{"positions", positions}, {"sigma_t", 10.0}, {"albedo", 0.9}, {"phase", {{"type", "hg"}, {"g", 0.0}}}}},
          {"lights",
           {{{"type", "directional"}, {"direction", {0.6, -0.7, -0.3}}, {"irradiance", 1.0}},
            {{"type", "directional"}, {"direction", {-0.5, 0.6, -0.4}}, {"irradiance", 0.6}},
            {{"type", "sky"}, {"radiance", {0.1, 0.15, 0.25}}}}},
          {"background", {0.0, 0.0, 0.0}}};
}

// Seed 002, section 5.2: lamps in homogeneous fog over a Lambert floor with a sphere (Lambert or
// Phong), 640 x 480: the trade suite's fog_lamps (bench/trade), its spot replaced by point lights.
nlohmann::json analytic_fog(int lights, double g, bool phong) {
  const nlohmann::json positions[4] = {{-1.2, 1.8, 0.0}, {1.6, 0.9, -1.5}, {0.3, 2.2, 1.4}, {-1.5, 0.7, -1.2}};
  const nlohmann::json colours[4] = {{14, 11, 7}, {3, 5, 10}, {8, 8, 8}, {6, 9, 5}};
  nlohmann::json l = nlohmann::json::array();
  for (int i = 0; i < lights; ++i) l.push_back({{"type", "point"}, {"position", positions[i]}, {"intensity", colours[i]}});
  nlohmann::json sphere = {{"type", "sphere"}, {"center", {0.4, 0.6, 0.8}}, {"radius", 0.6}, {"kd", {0.6, 0.25, 0.2}}};
  if (phong) sphere["ks"] = 0.4, sphere["shininess"] = 24;
  return {{"camera", camera_json(640, 480, 45.0)},
          {"medium", {{"density", {{"type", "constant"}, {"value", 1.0}}}, {"sigma_t", {0.22, 0.26, 0.32}}, {"albedo", 0.8},
                      {"phase", {{"type", "hg"}, {"g", g}}}, {"bounds", {{-4, 0, -4}, {4, 3.5, 4}}}}},
          {"lights", l},
          {"surfaces", {{{"type", "plane"}, {"point", {0, 0, 0}}, {"normal", {0, 1, 0}}, {"kd", 0.5}}, sphere}},
          {"background", {0.0, 0.0, 0.0}}};
}

// Seed 003, section 5: RBF fog (`blobs` Gaussians filling a unit box, sharpness from their spacing)
// in a box of side 2, point lights, 800 x 600.
nlohmann::json rbf_fog(int blobs, int lights) {
  Rng rng(5);
  const double spacing = 2.0 / std::cbrt(static_cast<double>(blobs));
  nlohmann::json b = nlohmann::json::array();
  for (int i = 0; i < blobs; ++i)
    b.push_back({{"center", {1.6 * rng.uniform() - 0.8, 1.6 * rng.uniform() - 0.8, 1.6 * rng.uniform() - 0.8}},
                 {"weight", 0.5 + 0.5 * rng.uniform()},
                 {"sharpness", std::min(8.0, 1.0 / spacing)}});
  const nlohmann::json positions[8] = {{1.4, 1.2, 1.0}, {-1.3, 0.9, 1.2}, {0.2, 1.5, -1.3}, {-1.2, -1.1, -0.9},
                                       {1.3, -1.0, -1.1}, {0.0, -1.4, 1.3}, {1.5, 0.1, -0.2}, {-1.5, 0.2, 0.1}};
  nlohmann::json l = nlohmann::json::array();
  for (int i = 0; i < lights; ++i) l.push_back({{"type", "point"}, {"position", positions[i]}, {"intensity", 6.0 / lights}});
  return {{"camera", camera_json(800, 600, 40.0)},
          {"medium", {{"bounds", {{-1.0, -1.0, -1.0}, {1.0, 1.0, 1.0}}},
                      {"density", {{"type", "rbf"}, {"blobs", b}}},
                      {"sigma_t", 2.0},
                      {"albedo", 0.9},
                      {"phase", {{"type", "isotropic"}}}}},
          {"lights", l},
          {"background", {0.0, 0.0, 0.0}}};
}

// Seed 000, section 5: a 64^3 grid lit from above (figure 1: uniform fog under a sun through a
// window, its density changing; figure 7: a cloud), albedo 0.9.
nlohmann::json dom_medium(bool cloud) {
  nlohmann::json density = {{"type", "constant"}, {"value", 1.0}};
  if (cloud) {
    Rng rng(9);
    nlohmann::json b = nlohmann::json::array();
    for (int i = 0; i < 40; ++i)
      b.push_back({{"center", {1.6 * rng.uniform() - 0.8, 0.8 * rng.uniform() - 0.4, 1.6 * rng.uniform() - 0.8}}, {"weight", 1.0}, {"sharpness", 2.4}});
    density = {{"type", "rbf"}, {"blobs", b}};
  }
  return {{"camera", camera_json(512, 512, 40.0)},
          {"medium", {{"bounds", {{-1.0, -1.0, -1.0}, {1.0, 1.0, 1.0}}}, {"density", density}, {"sigma_t", cloud ? 4.0 : 1.5}, {"albedo", 0.9},
                      {"phase", {{"type", "hg"}, {"g", cloud ? 0.3 : 0.0}}}}},
          {"lights", {{{"type", "directional"}, {"direction", {0.2, -1.0, 0.1}}, {"irradiance", 3.0}}}},
          {"background", {0.0, 0.0, 0.0}}};
}

// The scene a row's `scene` object names, built.
nlohmann::json build_scene(const nlohmann::json& spec) {
  const std::string build = spec.at("build").get<std::string>();
  if (build == "particle_cloud") return network_cloud(spec.at("particles").get<int>());
  if (build == "fog_lamps") return analytic_fog(spec.at("lights").get<int>(), spec.at("g").get<double>(), spec.at("phong").get<bool>());
  if (build == "rbf_fog") return rbf_fog(spec.at("blobs").get<int>(), spec.at("lights").get<int>());
  if (build == "lit_box") return dom_medium(spec.at("cloud").get<bool>());
  throw Error("scene.build", build, "particle_cloud, fog_lamps, rbf_fog or lit_box");
}

std::vector<SeedRow> seed_rows(const std::string& path) {
  std::vector<SeedRow> rows;
  std::ifstream in(path);
  if (!in) throw Error("--rows", path, "a readable JSON file (bench/seeds/rows.json)");
  for (const nlohmann::json& r : nlohmann::json::parse(in)) {
    SeedRow row;
    row.paper = r.at("paper").get<std::string>(), row.row = r.at("row").get<std::string>(), row.hardware = r.at("hardware").get<std::string>();
    row.paper_fps = r.at("paper_fps").is_null() ? std::numeric_limits<double>::quiet_NaN() : r.at("paper_fps").get<double>();
    row.settings = r.at("method");
    row.method = row.settings.at("name").get<std::string>();
    row.settings.erase("name");
    row.scene = build_scene(r.at("scene"));
    for (const auto& m : r.at("moves")) (m == "lights" ? row.lights_move : row.density_moves) = true;
    const auto at = r.at("look_at").get<std::vector<double>>();
    row.look_at = Vec3(at[0], at[1], at[2]);
    row.orbit_radius = r.at("orbit")[0].get<double>(), row.orbit_height = r.at("orbit")[1].get<double>();
    row.reference_spp = r.value("reference_spp", -1LL);
    rows.push_back(std::move(row));
  }
  return rows;
}

// Frame f's scene: the camera on its orbit (0.02 rad a frame), the lights turned about the vertical
// through the orbit's centre (1 degree a frame), the density moved (RBF centres drifting, a uniform
// density breathing by 20%, as paper 000's figure 1 varies it).
Scene frame_scene(const SeedRow& row, const Scene& base, int f) {
  Scene s = base;
  const double a = 0.02 * f;
  s.camera.position = row.look_at + Vec3(row.orbit_radius * std::sin(a), row.orbit_height, row.orbit_radius * std::cos(a));
  s.camera.look_at = row.look_at;
  if (row.lights_move) {
    const double b = f * kPi / 180.0, c = std::cos(b), sn = std::sin(b);
    const auto turn = [&](const Vec3& v) { return Vec3(c * v.x + sn * v.z, v.y, -sn * v.x + c * v.z); };
    for (Light& l : s.lights) {
      if (auto* d = std::get_if<DirectionalLight>(&l)) d->direction = turn(d->direction);
      if (auto* p = std::get_if<PointLight>(&l)) p->position = row.look_at + turn(p->position - row.look_at);
    }
  }
  if (row.density_moves && s.medium) {
    if (auto* rbf = std::get_if<RbfDensity>(&s.medium->density))
      for (size_t i = 0; i < rbf->blobs.size(); ++i) rbf->blobs[i].center.x += 0.05 * std::sin(0.1 * f + static_cast<double>(i));
    if (auto* constant = std::get_if<ConstantDensity>(&s.medium->density)) constant->value *= 1.0 + 0.2 * std::sin(0.2 * f);
  }
  return s;
}

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
    const Stopwatch watch;
    if (row.lights_move || row.density_moves) {
      SceneChange change;
      if (row.lights_move) change.lights = scene.lights;
      if (row.density_moves) change.medium = scene.medium;
      solution.update(change, render_options);
    }
    const double updated = watch.seconds();
    solution.render_layers(View{scene.camera}, out, render_options);
    ms.push_back(1e3 * watch.seconds()), update_ms.push_back(1e3 * updated);
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
