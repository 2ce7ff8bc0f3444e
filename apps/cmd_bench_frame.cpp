// haze bench frame: a host renderer's frame (docs/HOST.md, "Frame time"; tracker issue 51). Each
// scene of bench/frame names its method: one solution is prepared, then the camera moves every
// frame on an orbit around it while the host's floor (y = -1.5) is its depth buffer, and each
// stage is timed frame by frame: the froxel build (build_froxels, 160 x 90 x 64 by default); the
// CPU composite of the froxels over the host's depth into the renderer's colour of the frame, in
// place (written just before, as a renderer's is), with the glow of lights in view added per
// pixel (add_glow, 4 columns by default); and the per-pixel layers (Solution::render_layers with
// the depth, into the renderer's buffers, reused). Medians over the frames, each stage's least
// memory traffic as a share of the copy bandwidth measured on the same threads first, and where
// its kernels' operations per item are counted, their share of the FMA peak measured there; with the
// per-pixel layers, the froxel composite's relative RMS difference from theirs over the host's
// floor and sky at frame 0, without history and with the temporal froxels' settled at frame 0's
// camera. Stage temporal_build times TemporalFroxels (jittered slices, the history reprojected
// and blended) on the orbit, and measures the flicker of the composite of a still camera under
// the jitter: the frame-to-frame relative RMS change, median over frames 20 to 39, with no
// history and with the blend.
#include "commands.h"

#include <haze/core/error.h>
#include <haze/core/stopwatch.h>
#include <haze/froxels/froxels.h>
#include <haze/froxels/temporal.h>
#include <haze/analytic/methods.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <thread>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace haze::app {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

namespace {

struct FrameArgs {
  std::string scenes = HAZE_FRAME_SCENES_DIR;
  std::vector<std::string> only;    // --scene: these scenes only (by file stem)
  std::vector<std::string> stages;  // --stage: these stages only
  int frames = 30, threads = 2, width = 1920, height = 1080;
  std::vector<int> froxels{160, 90, 64};
  double glow_columns = 4.0;  // FroxelGrid::glow_columns: the glow of lights in view added per pixel
  double blend = 0.1;         // TemporalFroxels::blend
  double stage_seconds = 60.0;  // a stage stops before this many seconds have passed, after 3 frames at least
  bool json = false;
};

constexpr const char* kStages[] = {"froxel_build", "composite", "per_pixel", "temporal_build"};
constexpr int kSettled = 40;  // frames of a still camera after which the temporal froxels count as settled

// Frame f's camera: an orbit of radius 6 at height 1.5 around the origin, 0.1 rad a frame.
Camera pose(const Camera& base, int f) {
  Camera c = base;
  const double a = 0.1 * f;
  c.position = Vec3(6.0 * std::sin(a), 1.5, 6.0 * std::cos(a)), c.look_at = Vec3(0.0, 0.5, 0.0);
  return c;
}

// The host's floor at y = -1.5 as the distance along each pixel's ray (+inf above the horizon).
std::vector<float> floor_depth(const Camera& camera) {
  std::vector<float> depth;
  depth.reserve(static_cast<size_t>(camera.width_px) * static_cast<size_t>(camera.height_px));
  std::vector<Ray> rays(static_cast<size_t>(camera.width_px));
  for (int y = 0; y < camera.height_px; ++y) {
    camera.row_rays(y, rays.data());
    for (const Ray& ray : rays)
      depth.push_back(ray.direction.y < 0.0 ? static_cast<float>((-1.5 - ray.origin.y) / ray.direction.y) : std::numeric_limits<float>::infinity());
  }
  return depth;
}

// The host's colour: its floor where the depth is finite, its sky beyond.
Image host_colour(const std::vector<float>& depth, int width, int height) {
  Image colour(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      colour.set(x, y, std::isinf(depth[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)]) ? Rgb(0.05, 0.1, 0.2) : Rgb(0.3, 0.25, 0.2));
  return colour;
}

struct StageRow {
  std::string scene, method, stage;
  std::vector<double> ms;  // per frame
  double items = 0.0;      // froxels or pixels a frame
  double bytes = 0.0;      // the least memory traffic a frame of the stage makes (what it must write and read)
  // Floating-point operations an item takes, counted from the kernels' source (an FMA 2, Highway's
  // Log and Exp as their polynomials, about 20 and 15): the composite's lookups, analytic's tails;
  // 0 where the count depends on the scene (a march's steps).
  double flops = 0.0;
  // per_pixel: the froxel composite's relative RMS difference from the layers' composite over the
  // host's colour, frame 0, without history and settled (NaN where not measured).
  double froxel_error = std::numeric_limits<double>::quiet_NaN(), settled_error = froxel_error;
  // temporal_build: the still camera's flicker without history and with it.
  double flicker_without = froxel_error, flicker_with = froxel_error;
};

// Times `stage` frame by frame; `frame(f)` runs frame f's work and returns its milliseconds.
template <class Frame>
std::vector<double> time_frames(const FrameArgs& a, Frame frame) {
  std::vector<double> ms;
  const Stopwatch total;
  for (int f = 0; f < a.frames; ++f) {
    ms.push_back(frame(f));
    if (f >= 2 && total.seconds() > a.stage_seconds) break;
  }
  return ms;
}

// The froxels composited over `colour` with the glow of lights in view added.
void composite_frame(const Solution& solution, const Camera& camera, const Froxels& froxels, const std::vector<float>& depth, const Image& colour,
                     Image& out, int threads) {
  out.data() = colour.data();
  const ImageSpan target{out.data().data(), out.width(), out.height()};
  composite_froxels(froxels, ConstImageSpan{out.data().data(), out.width(), out.height()}, depth, target, threads);
  add_glow(solution, camera, froxels, depth, target, threads);
}

// The composite of the temporal froxels of a still camera (frame 0's) with `blend` after kSettled
// frames; with `flicker`, the median over frames 20 to kSettled - 1 of the composite's
// frame-to-frame relative RMS change.
Image settle(const Solution& solution, const Camera& camera, const FroxelGrid& grid, double blend, const RenderOptions& options, double* flicker = nullptr) {
  const std::vector<float> depth = floor_depth(camera);
  const Image colour = host_colour(depth, camera.width_px, camera.height_px);
  TemporalFroxels temporal;
  temporal.blend = blend;
  Image last(camera.width_px, camera.height_px), now(camera.width_px, camera.height_px);
  std::vector<double> change;
  for (int f = 0; f < kSettled; ++f) {
    composite_frame(solution, camera, temporal.build(solution, camera, grid, options), depth, colour, now, options.threads);
    if (f >= 20) change.push_back(relative_rmse(now, last));
    std::swap(now, last);
  }
  if (flicker) *flicker = median(change);
  return last;
}

std::vector<StageRow> run_scene(const std::filesystem::path& file, const FrameArgs& a) {
  Scene scene = Scene::load(file);
  scene.camera.width_px = a.width, scene.camera.height_px = a.height;
  RenderOptions options;
  options.threads = a.threads;
  const Solution solution = prepare(scene, "", options);
  FroxelGrid grid{a.froxels[0], a.froxels[1], a.froxels[2]};
  grid.glow_columns = a.glow_columns;
  const Image host = host_colour(floor_depth(scene.camera), a.width, a.height);
  Image composed(a.width, a.height);  // the renderer's colour buffer and froxels, reused frame after frame
  Froxels froxels;
  const auto wanted = [&](const std::string& stage) { return a.stages.empty() || std::count(a.stages.begin(), a.stages.end(), stage) > 0; };
  std::vector<StageRow> rows;
  const std::string name = file.stem().string(), method = solution.method();
  const bool analytic = method == analytic::analytic_info().name;  // the kernels whose operations are counted per item
  const auto lights = static_cast<double>(scene.lights.size());
  const double pixels = static_cast<double>(a.width) * a.height;
  if (wanted(kStages[0]))
    rows.push_back({name, method, kStages[0], time_frames(a, [&](int f) {
                      const Camera camera = pose(scene.camera, f);
                      const Stopwatch watch;
                      build_froxels(solution, camera, froxels, grid, options);
                      return 1e3 * watch.seconds();
                    }), static_cast<double>(grid.nx) * grid.ny * grid.nz, 24.0 * grid.nx * grid.ny * grid.nz,  // L_in and T written
                    analytic ? 90.0 * lights + 30.0 : 0.0});  // a tail per light (UnitTail), then T and L_in
  if (wanted(kStages[1]))
    rows.push_back({name, method, kStages[1], time_frames(a, [&](int f) {
                      const Camera camera = pose(scene.camera, f);
                      const std::vector<float> depth = floor_depth(camera);
                      build_froxels(solution, camera, froxels, grid, options);
                      composed.data() = host.data();  // the renderer's colour of this frame, composited in place
                      const Stopwatch watch;
                      const ImageSpan target{composed.data().data(), a.width, a.height};
                      composite_froxels(froxels, ConstImageSpan{composed.data().data(), a.width, a.height}, depth, target, a.threads);
                      add_glow(solution, camera, froxels, depth, target, a.threads);
                      return 1e3 * watch.seconds();
                    }), pixels, 28.0 * pixels, 140.0});  // colour read and written, depth read; the lookup and its 8 taps (the glow not counted)
  if (wanted(kStages[2])) {
    double error = std::numeric_limits<double>::quiet_NaN(), settled = error;
    Image inscatter(a.width, a.height), transmittance(a.width, a.height);  // the renderer's layer buffers, reused
    rows.push_back({name, method, kStages[2], time_frames(a, [&](int f) {
                      const Camera camera = pose(scene.camera, f);
                      const std::vector<float> depth = floor_depth(camera);
                      const Stopwatch watch;
                      solution.render_layers(View{camera, depth}, {ImageSpan{inscatter.data().data(), a.width, a.height},
                                                                   ImageSpan{transmittance.data().data(), a.width, a.height}, ImageSpan{}},
                                             options);
                      const double ms = 1e3 * watch.seconds();
                      if (f == 0) {  // the froxels' composite against the layers', over the host's floor and sky
                        const Image colour = host_colour(depth, a.width, a.height);
                        build_froxels(solution, camera, froxels, grid, options);
                        Image froxel(a.width, a.height), exact(a.width, a.height);
                        composite_frame(solution, camera, froxels, depth, colour, froxel, a.threads);
                        for (int y = 0; y < a.height; ++y)
                          for (int x = 0; x < a.width; ++x) exact.set(x, y, inscatter.at(x, y) + transmittance.at(x, y) * colour.at(x, y));
                        error = relative_rmse(froxel, exact);
                        settled = relative_rmse(settle(solution, camera, grid, a.blend, options), exact);
                      }
                      return ms;
                    }), pixels, 28.0 * pixels, analytic ? 202.0 * lights + 25.0 : 0.0});  // L_in and T written, depth read; two tails and the geometry per light
    rows.back().froxel_error = error, rows.back().settled_error = settled;
  }
  if (wanted(kStages[3])) {
    TemporalFroxels temporal;
    temporal.blend = a.blend;
    rows.push_back({name, method, kStages[3], time_frames(a, [&](int f) {
                      const Camera camera = pose(scene.camera, f);
                      const Stopwatch watch;
                      temporal.build(solution, camera, grid, options);
                      return 1e3 * watch.seconds();
                    }), static_cast<double>(grid.nx) * grid.ny * grid.nz, 72.0 * grid.nx * grid.ny * grid.nz});  // written, then the history read and blended
    settle(solution, pose(scene.camera, 0), grid, 1.0, options, &rows.back().flicker_without);
    settle(solution, pose(scene.camera, 0), grid, a.blend, options, &rows.back().flicker_with);
  }
  return rows;
}

// The machine's peak arithmetic on the threads: 12 independent chains of FMAs per thread on the
// widest vectors the CPU has (AVX-512, else AVX2; 2 flops per lane and FMA), the best of 5; 0
// elsewhere.
#if defined(__x86_64__)
constexpr long long kFmaRounds = 1LL << 21;
__attribute__((target("avx512f"))) float chains512(float seed) {
  const __m512 b = _mm512_set1_ps(0.999999f), c = _mm512_set1_ps(1e-7f);
  __m512 a[12];
  for (int e = 0; e < 12; ++e) a[e] = _mm512_set1_ps(seed + 0.01f * static_cast<float>(e));  // equal chains would fold into one
  for (long long r = 0; r < kFmaRounds; ++r)
    for (__m512& v : a) v = _mm512_fmadd_ps(v, b, c);
  __m512 sum = a[0];
  for (int e = 1; e < 12; ++e) sum = _mm512_add_ps(sum, a[e]);
  alignas(64) float lanes[16];
  _mm512_store_ps(lanes, sum);
  return lanes[0];
}
__attribute__((target("avx2,fma"))) float chains256(float seed) {
  const __m256 b = _mm256_set1_ps(0.999999f), c = _mm256_set1_ps(1e-7f);
  __m256 a[12];
  for (int e = 0; e < 12; ++e) a[e] = _mm256_set1_ps(seed + 0.01f * static_cast<float>(e));
  for (long long r = 0; r < kFmaRounds; ++r)
    for (__m256& v : a) v = _mm256_fmadd_ps(v, b, c);
  __m256 sum = a[0];
  for (int e = 1; e < 12; ++e) sum = _mm256_add_ps(sum, a[e]);
  return _mm_cvtss_f32(_mm256_castps256_ps128(sum));
}
#endif

double fma_peak(int threads) {
#if defined(__x86_64__)
  const bool wide = __builtin_cpu_supports("avx512f"), avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (!wide && !avx2) return 0.0;
  const int lanes = wide ? 16 : 8, n = std::max(1, threads > 0 ? threads : static_cast<int>(std::thread::hardware_concurrency()));
  std::vector<float> sink(static_cast<size_t>(n));
  double best = 0.0;
  for (int r = 0; r < 5; ++r) {
    const Stopwatch watch;
    parallel_for(n, n, 1, [&](long long t0, long long t1) {
      for (auto t = t0; t < t1; ++t) sink[static_cast<size_t>(t)] = wide ? chains512(1.0f + 0.1f * static_cast<float>(t)) : chains256(1.0f + 0.1f * static_cast<float>(t));
    });
    best = std::max(best, 2.0 * 12 * lanes * static_cast<double>(kFmaRounds) * n / watch.seconds());
  }
  if (std::all_of(sink.begin(), sink.end(), [](float v) { return std::isnan(v); })) return 0.0;  // keeps the chains
  return best;
#else
  return 0.0;
#endif
}

// The machine's copy bandwidth on the threads (STREAM's copy: bytes read plus written per second),
// 2 x 128 MB, the best of 5.
double copy_bandwidth(int threads) {
  const size_t n = size_t(32) << 20, chunk = size_t(1) << 20;
  std::vector<float> from(n, 1.0f), to(n, 0.0f);
  double best = 0.0;
  for (int r = 0; r < 5; ++r) {
    const Stopwatch watch;
    parallel_for(static_cast<long long>(n / chunk), threads, 1, [&](long long c0, long long c1) {
      for (auto c = static_cast<size_t>(c0); c < static_cast<size_t>(c1); ++c) std::copy_n(from.data() + c * chunk, chunk, to.data() + c * chunk);
    });
    best = std::max(best, 2.0 * sizeof(float) * static_cast<double>(n) / watch.seconds());
  }
  return best;
}

int run(const FrameArgs& a) {
  for (const std::string& s : a.stages)
    if (std::find(std::begin(kStages), std::end(kStages), s) == std::end(kStages))
      throw Error("--stage", s, "froxel_build, composite, per_pixel or temporal_build");
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(a.scenes, ec))
    if (entry.path().extension() == ".json" && (a.only.empty() || std::count(a.only.begin(), a.only.end(), entry.path().stem().string())))
      files.push_back(entry.path());
  if (ec) throw Error("--scenes", a.scenes, "a directory of frame scenes (" + ec.message() + ")");
  if (files.empty()) throw Error("--scenes", a.scenes, "a directory holding the scenes asked for (bench/frame)");
  std::sort(files.begin(), files.end());
  nlohmann::json out = nlohmann::json::array();
  const double bandwidth = copy_bandwidth(a.threads), peak = fma_peak(a.threads);
  if (!a.json)
    std::printf("%dx%d, %d x %d x %d froxels, %d threads; medians over the frames; copy bandwidth %.1f GB/s, FMA peak %.0f GFLOP/s\n"
                "%-18s %-12s %-14s %10s %7s %12s %10s %11s\n",
                a.width, a.height, a.froxels[0], a.froxels[1], a.froxels[2], a.threads, 1e-9 * bandwidth, 1e-9 * peak, "scene", "method", "stage",
                "median ms", "frames", "ns per item", "of copy bw", "of FMA peak");
  for (const auto& file : files)
    for (const StageRow& r : run_scene(file, a)) {
      const double m = median(r.ms), ns = 1e6 * m / r.items, share = r.bytes / (1e-3 * m) / bandwidth;
      const double arithmetic = r.flops > 0.0 && peak > 0.0 ? r.flops * r.items / (1e-3 * m) / peak : std::numeric_limits<double>::quiet_NaN();
      out.push_back({{"scene", r.scene}, {"method", r.method}, {"stage", r.stage}, {"median_ms", m}, {"frames", r.ms.size()}, {"items", r.items},
                     {"ns_per_item", ns}, {"bytes", r.bytes}, {"bandwidth_share", share}});
      if (!std::isnan(arithmetic)) out.back()["flops_per_item"] = r.flops, out.back()["fma_peak_share"] = arithmetic;
      if (!std::isnan(r.froxel_error)) out.back()["froxel_error"] = r.froxel_error, out.back()["settled_error"] = r.settled_error;
      if (!std::isnan(r.flicker_with)) out.back()["flicker_without"] = r.flicker_without, out.back()["flicker_with"] = r.flicker_with;
      if (!a.json) {
        std::printf("%-18s %-12s %-14s %10.1f %7zu %12.2f %9.1f%%", r.scene.c_str(), r.method.c_str(), r.stage.c_str(), m, r.ms.size(), ns, 100.0 * share);
        if (std::isnan(arithmetic)) std::printf(" %11s", "-");
        else std::printf(" %10.1f%%", 100.0 * arithmetic);
        if (!std::isnan(r.froxel_error))
          std::printf("  (froxel composite %.2f%% off, %.2f%% with settled history)", 100.0 * r.froxel_error, 100.0 * r.settled_error);
        if (!std::isnan(r.flicker_with))
          std::printf("  (still camera's flicker %.3f%% without history, %.3f%% with: %.1fx less)", 100.0 * r.flicker_without, 100.0 * r.flicker_with,
                      r.flicker_without / r.flicker_with);
        std::printf("\n");
      }
      std::fflush(stdout);
    }
  if (a.json) std::cout << out.dump(2) << "\n";
  return 0;
}

}  // namespace

Command add_bench_frame(CLI::App& bench) {
  auto* sub = bench.add_subcommand("frame", "A host renderer's 1080p frame: froxel build, CPU composite and per-pixel layers, the camera moving");
  auto a = std::make_shared<FrameArgs>();
  sub->add_option("--scenes", a->scenes, "Directory of the frame scenes, each naming its method")->capture_default_str();
  sub->add_option("--scene", a->only, "Only these scenes (by file stem)");
  sub->add_option("--stage", a->stages, "Only these stages: froxel_build, composite, per_pixel, temporal_build");
  sub->add_option("--frames", a->frames, "Frames per stage")->capture_default_str()->check(CLI::Range(1, 100000));
  sub->add_option("--stage-seconds", a->stage_seconds, "A stage stops after this long (3 frames at least)")->capture_default_str()->check(CLI::PositiveNumber);
  sub->add_option("--threads", a->threads, "Thread cap (0: all cores)")->capture_default_str()->check(CLI::NonNegativeNumber);
  sub->add_option("--width", a->width, "Image width")->capture_default_str()->check(CLI::Range(1, 16384));
  sub->add_option("--height", a->height, "Image height")->capture_default_str()->check(CLI::Range(1, 16384));
  sub->add_option("--froxels", a->froxels, "Froxel columns across, down and slices")->expected(3)->capture_default_str()->check(CLI::Range(1, 4096));
  sub->add_option("--glow-columns", a->glow_columns, "FroxelGrid::glow_columns: lights' glow within this many columns added per pixel (0: none)")
      ->capture_default_str()->check(CLI::Range(0.0, 16.0));
  sub->add_option("--blend", a->blend, "TemporalFroxels::blend, the new frame's weight")->capture_default_str()->check(CLI::Range(1e-3, 1.0));
  sub->add_flag("--json", a->json, "Print a JSON list of {scene, method, stage, median_ms, frames, items, ns_per_item, bytes, bandwidth_share[, flops_per_item, fma_peak_share][, froxel_error, settled_error][, flicker_without, flicker_with]}");
  return {sub, [a] { return run(*a); }};
}

}  // namespace haze::app
