// haze::gl on whatever driver the headless context finds (llvmpipe on a machine without a GPU):
// texture upload bandwidth through the pixel-buffer ring, whole volumes and 10% of their bricks,
// against memcpy of the same bytes in the same run; and the ray-march display's frame time.
// Run: build/dev/bench/haze_bench_gl --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <haze/gl/context.h>
#include <haze/gl/display.h>
#include <haze/grids/optical_depth.h>
#include <haze/grids/propagation.h>
#include <haze/grids/rbf.h>

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstring>

namespace {

using namespace haze;

gl::HeadlessContext& context() {
  static gl::HeadlessContext c;
  return c;
}

std::vector<float> field(size_t count) {
  std::vector<float> v(count);
  for (size_t i = 0; i < count; ++i) v[i] = 0.5f + 0.5f * std::sin(0.001f * static_cast<float>(i));
  return v;
}

// The same bytes copied by the CPU: the machine's memory bandwidth for this size, in this run.
void BM_Memcpy(benchmark::State& state) {
  const auto n = static_cast<size_t>(state.range(0));
  const size_t count = n * n * n * static_cast<size_t>(state.range(1));
  const std::vector<float> from = field(count);
  std::vector<float> to(count);
  for (auto _ : state) {
    std::memcpy(to.data(), from.data(), count * sizeof(float));
    benchmark::DoNotOptimize(to.data());
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * count * sizeof(float)));
}

// args: side, channels, float16 (0/1). Bytes counted are the float32 field's.
void BM_UploadFull(benchmark::State& state) {
  context();
  const int n = static_cast<int>(state.range(0)), channels = static_cast<int>(state.range(1));
  const auto format = state.range(2) ? gl::TexelFormat::float16 : gl::TexelFormat::float32;
  gl::Texture texture = gl::Texture::volume({n, n, n}, channels, format);
  const std::vector<float> values = field(static_cast<size_t>(n) * static_cast<size_t>(n) * static_cast<size_t>(n) * static_cast<size_t>(channels));
  for (auto _ : state) {
    texture.upload(values);
    context().finish();
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * values.size() * sizeof(float)));
  state.SetLabel(std::string(gl::name(format)) + (texture.stats().persistent ? ", persistent" : ", mapped per upload"));
}

// One 16^3 brick in ten changed (args: side, float16); bytes counted are the changed cells'.
void BM_UploadPartial(benchmark::State& state) {
  context();
  const int n = static_cast<int>(state.range(0));
  const auto format = state.range(1) ? gl::TexelFormat::float16 : gl::TexelFormat::float32;
  gl::Texture texture = gl::Texture::volume({n, n, n}, 1, format);
  const size_t cells = static_cast<size_t>(n) * static_cast<size_t>(n) * static_cast<size_t>(n);
  const std::vector<float> values = field(cells);
  std::vector<unsigned char> all(cells, 1);
  std::vector<gl::Brick> bricks;
  size_t changed = 0, i = 0;
  for (const gl::Brick& b : gl::changed_bricks({n, n, n}, all, 16))
    if (i++ % 10 == 0) bricks.push_back(b), changed += static_cast<size_t>(b.size[0] * b.size[1] * b.size[2]);
  texture.upload(values);
  for (auto _ : state) {
    texture.upload(values, bricks);
    context().finish();
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * changed * sizeof(float)));
  state.counters["bricks"] = static_cast<double>(bricks.size());
}

// A 24-blob cloud at n^3 cells, two point lights and a sun, side x side pixels, step half a cell.
struct DisplayScene {
  Scene scene;
  grids::ExtinctionVolume volume;
  std::vector<grids::DenseGrid> depths;
};

DisplayScene display_scene(int n, int side) {
  Scene scene;
  scene.camera.position = Vec3(0.4, 0.5, 3.4);
  scene.camera.width_px = scene.camera.height_px = side;
  MediumDesc medium;
  medium.sigma_t = Rgb(3.0, 3.3, 3.6);
  medium.albedo = Rgb(0.9);
  medium.phase = PhaseFunction::henyey_greenstein(0.4);
  scene.medium = medium;
  scene.lights = {PointLight{Vec3(1.2, 1.0, 0.8), Rgb(3.0)}, PointLight{Vec3(-1.5, -0.4, 1.0), Rgb(2.0, 2.0, 2.6)},
                  DirectionalLight{glm::normalize(Vec3(0.3, -0.9, -0.3)), Rgb(0.8)}};
  grids::ExtinctionVolume volume{grids::DenseGrid({n, n, n}, {Vec3(-1.0), Vec3(1.0)}), medium.sigma_t, medium.albedo, medium.phase};
  std::vector<RbfBlob> blobs;
  for (int i = 0; i < 24; ++i) {
    const double t = 0.7 * i;
    blobs.push_back({Vec3(0.5 * std::cos(t), 0.4 * std::sin(1.7 * t), 0.45 * std::cos(1.3 * t + 0.5)), 0.6 + 0.3 * std::sin(2.0 * t), 3.0 + (i % 3)});
  }
  grids::inject_rbf(blobs, volume.density);
  std::vector<grids::DenseGrid> depths = grids::optical_depths(volume.density, scene.lights);
  return {scene, std::move(volume), std::move(depths)};
}

// args: side of the volume, side of the image. Time per frame, the shader run to completion.
void BM_Display(benchmark::State& state) {
  context();
  const DisplayScene s = display_scene(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  gl::VolumeDisplay display(s.scene, s.volume, s.depths);
  display.draw(s.scene.camera);  // the driver compiles the shader on the first draw
  for (auto _ : state) display.draw(s.scene.camera);
  state.SetLabel(context().info().renderer);
}

// The CPU's SIMD marcher on the same fields and image, every core: what the display replaces.
void BM_CpuMarch(benchmark::State& state) {
  const DisplayScene s = display_scene(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  for (auto _ : state) benchmark::DoNotOptimize(grids::march_image(s.scene, s.volume, s.depths, {}, {}));
}

BENCHMARK(BM_Memcpy)->Args({64, 1})->Args({128, 1})->Args({64, 4})->Args({128, 4})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_UploadFull)
    ->ArgsProduct({{64, 128}, {1, 4}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_UploadPartial)->ArgsProduct({{64, 128}, {0, 1}})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Display)->ArgsProduct({{64, 128}, {256, 512}})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_CpuMarch)->ArgsProduct({{64, 128}, {256}})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
