// Method "propagation" (seed 003), stage by stage, at the sizes on this machine and at the
// seed's own table 2/3 settings (20^3 to 40^3 volumes, 1 to 8 lights, 800 x 600, up to 27000 RBFs).
// Run: build/release/bench/haze_bench_propagation --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <haze/core/rng.h>
#include <haze/grids/optical_depth.h>
#include <haze/grids/propagation.h>
#include <haze/grids/rbf.h>

#include <benchmark/benchmark.h>

namespace {

using namespace haze;
using namespace haze::grids;

const Aabb kBounds{Vec3(-1.0), Vec3(1.0)};

// count blobs on a jittered lattice filling the box, each reaching about 0.1 at the 1e-4 cutoff.
std::vector<RbfBlob> lattice_blobs(int count) {
  const int side = std::max(1, static_cast<int>(std::lround(std::cbrt(count))));
  Rng rng(11);
  std::vector<RbfBlob> blobs;
  for (int i = 0; i < count; ++i) {
    Vec3 cell(i % side, (i / side) % side, i / (side * side));
    Vec3 jitter(rng.uniform(), rng.uniform(), rng.uniform());
    blobs.push_back({-0.8 + 1.6 * (cell + jitter) / static_cast<double>(side), 0.5 + rng.uniform(), 1.6 * side});
  }
  return blobs;
}

std::vector<Light> lights(int count) {
  const std::vector<Light> all = {PointLight{Vec3(0.2, 0.3, -0.1)},  PointLight{Vec3(1.6, 1.2, 0.4)},
                                  PointLight{Vec3(-0.5, -0.2, 0.6)}, PointLight{Vec3(-1.5, 0.8, -1.9)},
                                  PointLight{Vec3(0.7, -0.6, 0.2)},  PointLight{Vec3(0.0, 2.0, 0.0)},
                                  PointLight{Vec3(-0.3, 0.5, -0.5)}, PointLight{Vec3(1.1, -1.4, 1.3)}};
  return {all.begin(), all.begin() + count};
}

DenseGrid cloud(int n, int blobs) {
  DenseGrid grid({n, n, n}, kBounds);
  inject_rbf(lattice_blobs(blobs), grid);
  return grid;
}

// Args: blobs, cells per side.
void BM_Inject(benchmark::State& state) {
  const auto blobs = lattice_blobs(static_cast<int>(state.range(0)));
  const int n = static_cast<int>(state.range(1));
  DenseGrid grid({n, n, n}, kBounds);
  size_t updates = 0;
  for (auto _ : state) {
    std::fill(grid.values().begin(), grid.values().end(), 0.0f);
    updates = inject_rbf(blobs, grid, 0.0, 2).cell_updates;
  }
  state.counters["cell_updates"] = static_cast<double>(updates);
  state.counters["updates_per_second"] = benchmark::Counter(static_cast<double>(updates), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_Inject)->Name("propagation/inject/blobs,cells")->Args({27000, 128})->Args({27000, 20})->Args({1000, 20})->Args({1, 20})
    ->UseRealTime()->Unit(benchmark::kMillisecond);

// Args: cells per side, lights, scheme (0 exact, 1 paper, 2 sweep), sweep layers.
void BM_OpticalDepth(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const DenseGrid grid = cloud(n, 1000);
  const auto ls = lights(static_cast<int>(state.range(1)));
  DepthOptions options;
  options.scheme = static_cast<DepthScheme>(state.range(2));
  options.sweep_layers = static_cast<int>(state.range(3));
  options.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(optical_depths(grid, ls, options));
  state.counters["cell_lights_per_second"] =
      benchmark::Counter(static_cast<double>(grid.cell_count() * ls.size()), benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(name(options.scheme));
}
BENCHMARK(BM_OpticalDepth)->Name("propagation/optical_depth/cells,lights,scheme,layers")
    ->Args({128, 4, 2, 4})->Args({128, 4, 2, 1})->Args({64, 4, 2, 4})->Args({64, 4, 0, 1})->Args({64, 4, 1, 1})
    ->Args({20, 1, 1, 1})->Args({40, 4, 1, 1})->Args({20, 1, 2, 4})->Args({40, 8, 2, 4})
    ->UseRealTime()->Unit(benchmark::kMillisecond);

// The sweep (128^3, 4 point lights) with the SIMD kernel against its scalar reference, on
// 1 and 2 threads. Args: threads, scalar kernel (0 or 1).
void BM_SweepKernel(benchmark::State& state) {
  const DenseGrid grid = cloud(128, 1000);
  const auto ls = lights(4);
  DepthOptions options;
  options.threads = static_cast<int>(state.range(0));
  options.scalar_kernel = state.range(1) != 0;
  for (auto _ : state) benchmark::DoNotOptimize(optical_depths(grid, ls, options));
  const double cell_lights = static_cast<double>(grid.cell_count() * ls.size());
  state.counters["cell_lights_per_second"] = benchmark::Counter(cell_lights, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["ns_per_cell_light"] = benchmark::Counter(1e-9 * cell_lights, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.SetLabel(options.scalar_kernel ? "scalar" : "simd");
}
BENCHMARK(BM_SweepKernel)->Name("propagation/sweep_128_4_lights/threads,scalar")->Args({1, 0})->Args({2, 0})->Args({1, 1})->Args({2, 1})
    ->UseRealTime()->Unit(benchmark::kMillisecond);

// Args: width, height, cells per side, lights, float64 reference marcher (0 or 1). Ray marching
// only (volumes built beforehand). Counters: march steps (samples) and the time per sample and light.
void BM_March(benchmark::State& state) {
  const int n = static_cast<int>(state.range(2));
  Scene scene;
  scene.camera.position = Vec3(0.4, 0.5, 3.4);
  scene.camera.look_at = Vec3(0.0);
  scene.camera.width_px = static_cast<int>(state.range(0)), scene.camera.height_px = static_cast<int>(state.range(1));
  scene.lights = lights(static_cast<int>(state.range(3)));
  ExtinctionVolume volume{cloud(n, 1000), Rgb(2.0), Rgb(0.9), PhaseFunction::henyey_greenstein(0.4)};
  const auto depths = optical_depths(volume.density, scene.lights);
  MarchSettings settings;
  settings.scalar = state.range(4) != 0;
  RenderOptions options;
  options.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(march_image(scene, volume, depths, settings, options).data().data());
  // The marcher's steps: ceil(length inside the volume / step) per pixel.
  const double step = settings.step_cells * volume.density.cell_size().x;
  double samples = 0.0;
  for (int y = 0; y < scene.camera.height_px; ++y)
    for (int x = 0; x < scene.camera.width_px; ++x) {
      double t0 = 0.0, t1 = kInfinity;
      if (volume.density.bounds().clip(scene.camera.pixel_ray(x, y), t0, t1)) samples += std::ceil((t1 - t0) / step);
    }
  state.counters["samples"] = samples;
  state.counters["ns_per_sample_light"] = benchmark::Counter(1e-9 * samples * static_cast<double>(scene.lights.size()),
                                                             benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.SetLabel(settings.scalar ? "float64" : "simd");
}
BENCHMARK(BM_March)->Name("propagation/march/width,height,cells,lights,float64")
    ->Args({512, 512, 64, 4, 0})->Args({512, 512, 64, 4, 1})->Args({512, 512, 128, 4, 0})
    ->Args({800, 600, 20, 1, 0})->Args({800, 600, 40, 4, 0})->Args({800, 600, 40, 8, 0})
    ->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
