// The analytic airlight over a 1920 x 1080 frame from 4 point lights (one grey channel), SIMD
// against the scalar reference, on 1 and 2 threads; rows are split over threads.
// Run: build/release/bench/haze_bench_analytic --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <haze/core/camera.h>
#include <haze/core/method.h>
#include <haze/core/progress.h>
#include <haze/all.h>
#include <haze/analytic/airlight_batch.h>
#include <haze/simd/phase_batch.h>

#include <benchmark/benchmark.h>

#include <filesystem>

namespace {

using namespace haze;
using namespace haze::analytic;

struct Frame {
  int width = 1920, height = 1080;
  std::vector<float> ox, oy, oz, dx, dy, dz, length;
};

// A pinhole camera over a floor at y = 0: rays that hit the floor end there, the rest are infinite.
const Frame& frame() {
  static const Frame f = [] {
    Frame fr;
    Camera camera;
    camera.position = Vec3(0, 1.5, 6);
    camera.look_at = Vec3(0, 1, 0);
    camera.width_px = fr.width, camera.height_px = fr.height;
    for (int y = 0; y < fr.height; ++y)
      for (int x = 0; x < fr.width; ++x) {
        Ray r = camera.pixel_ray(x, y);
        fr.ox.push_back(static_cast<float>(r.origin.x)), fr.oy.push_back(static_cast<float>(r.origin.y));
        fr.oz.push_back(static_cast<float>(r.origin.z)), fr.dx.push_back(static_cast<float>(r.direction.x));
        fr.dy.push_back(static_cast<float>(r.direction.y)), fr.dz.push_back(static_cast<float>(r.direction.z));
        fr.length.push_back(r.direction.y < 0.0 ? static_cast<float>(-r.origin.y / r.direction.y) : INFINITY);
      }
    return fr;
  }();
  return f;
}

template <bool kSimd>
void BM_AirlightFrame(benchmark::State& state) {
  static const AirlightTable table(PhaseFunction::henyey_greenstein(0.6));
  const Frame& f = frame();
  const int threads = static_cast<int>(state.range(0));
  const AirlightChannel lights[4] = {{-0.6f, 1.6f, 0.4f, 0.3f, 0.27f, 10.0f}, {1.5f, 0.8f, -1.0f, 0.3f, 0.27f, 6.0f},
                                           {0.5f, 2.5f, -3.0f, 0.3f, 0.27f, 8.0f}, {-2.0f, 0.4f, 1.5f, 0.3f, 0.27f, 3.0f}};
  std::vector<float> out(f.ox.size());
  for (auto _ : state) {
    std::fill(out.begin(), out.end(), 0.0f);
    parallel_for(f.height, threads, 8, [&](long long y0, long long y1) {
      size_t begin = static_cast<size_t>(y0) * static_cast<size_t>(f.width), n = static_cast<size_t>(y1 - y0) * static_cast<size_t>(f.width);
      SegmentBatch batch{f.ox.data() + begin, f.oy.data() + begin, f.oz.data() + begin, f.dx.data() + begin,
                               f.dy.data() + begin, f.dz.data() + begin, f.length.data() + begin, n};
      for (const auto& light : lights) {
        if constexpr (kSimd) {
          add_airlight(table, light, batch, out.data() + begin);
        } else {
          add_airlight_reference(table, light, batch, out.data() + begin);
        }
      }
    });
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["segment_lights_per_second"] =
      benchmark::Counter(4.0 * static_cast<double>(f.ox.size()), benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(kSimd ? simd::selected_target() : "scalar float32 reference");
}
BENCHMARK(BM_AirlightFrame<true>)->Name("analytic/airlight_1080p_4_lights/simd/threads")->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AirlightFrame<false>)->Name("analytic/airlight_1080p_4_lights/scalar/threads")->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

// The frame: 1920 x 1080, 4 point lights, airlight plus Lambert and Phong surface radiance
// with dynamic g changing every frame (0.58 and 0.62 in turn), one method object kept across
// frames (its Legendre tables stay in memory; they come from a disk cache built before timing).
// Arg 1: the Highway airlight (setting kernel "simd"); arg 0: the float64 airlight loop ("float64").
Scene frame_scene() {
  Scene scene;
  scene.camera.position = Vec3(0, 1.5, 6);
  scene.camera.look_at = Vec3(0, 1, 0);
  scene.camera.width_px = 1920, scene.camera.height_px = 1080;
  MediumDesc m;
  m.sigma_t = Rgb(0.26);
  m.albedo = Rgb(0.9);
  m.phase = PhaseFunction::henyey_greenstein(0.6);
  scene.medium = m;
  scene.lights = {PointLight{Vec3(-1.2, 1.8, 0.0), Rgb(14, 11, 7)}, PointLight{Vec3(1.6, 0.9, -1.5), Rgb(3, 5, 10)},
                  PointLight{Vec3(0.3, 2.8, -0.5), Rgb(8)}, PointLight{Vec3(-2.0, 0.5, 1.5), Rgb(2, 1, 1)}};
  scene.surfaces = {{Plane{Vec3(0), Vec3(0, 1, 0)}, Rgb(0.5), Rgb(0.0), 1.0},
                    {Sphere{Vec3(0.4, 0.6, 0.8), 0.6}, Rgb(0.6, 0.25, 0.2), Rgb(0.4), 24.0}};
  return scene;
}

void BM_AnalyticFrame(benchmark::State& state) {
  Scene scene = frame_scene();
  RenderOptions options;
  options.threads = static_cast<int>(state.range(1));
  options.settings = {{"dynamic_g_tolerance", 1e-2}, {"kernel", state.range(0) ? "simd" : "float64"}};
  options.cache_dir = std::filesystem::temp_directory_path() / "haze_bench_analytic_cache";
  register_all();
  Solution solution = prepare(scene, "analytic", options);  // fills the cache and the method's tables
  int frame = 0;
  for (auto _ : state) {
    scene.medium->phase = PhaseFunction::henyey_greenstein(++frame % 2 ? 0.58 : 0.62);
    solution.update({.medium = scene.medium});
    benchmark::DoNotOptimize(solution.render().radiance.data().data());
  }
  state.SetLabel(state.range(0) ? "simd airlight" : "float64 airlight");
}
BENCHMARK(BM_AnalyticFrame)->Name("analytic/frame_1080p_4_lights_dynamic_g/simd,threads")->Args({1, 2})->Args({0, 2})->UseRealTime()->Unit(benchmark::kMillisecond);

// Every table the frame needs, built from scratch (no cache, a fresh method object): the dynamic-g
// airlight orders and the per-order J1 and J_24 tables. The budget is 2 s.
void BM_FrameTables(benchmark::State& state) {
  register_all();
  Scene scene = frame_scene();
  scene.camera.width_px = 4, scene.camera.height_px = 4;
  RenderOptions options;
  options.threads = 2;
  options.settings = {{"dynamic_g_tolerance", 1e-2}};
  for (auto _ : state) benchmark::DoNotOptimize(prepare(scene, "analytic", options).stats());
}
BENCHMARK(BM_FrameTables)->Name("analytic/frame_tables_dynamic_g/threads:2")->UseRealTime()->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
