// Throughput of the reference path tracer: scattering events per second on a homogeneous medium
// (issue target: >= 10 million per second on 2 threads), reported as a counter with the median.
// Run: build/release/bench/haze_bench_reference --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <haze/core/method.h>
#include <haze/reference/methods.h>

#include <benchmark/benchmark.h>

namespace {

haze::Scene homogeneous_box(double albedo) {
  haze::Scene scene;
  scene.camera.position = haze::Vec3(0, 0, 4);
  scene.camera.width_px = scene.camera.height_px = 32;
  haze::MediumDesc m;
  m.bounds = {haze::Vec3(-1), haze::Vec3(1)};
  m.sigma_t = haze::Rgb(4.0);
  m.albedo = haze::Rgb(albedo);
  m.phase = haze::PhaseFunction::henyey_greenstein(0.5);
  scene.medium = m;
  scene.lights.push_back(haze::DirectionalLight{haze::Vec3(0.3, -1.0, -0.2) / std::sqrt(1.13), haze::Rgb(3.0)});
  return scene;
}

void BM_ReferenceHomogeneous(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  haze::reference::register_methods();
  haze::Scene scene = homogeneous_box(0.95);
  haze::RenderOptions options;
  options.threads = threads;
  options.settings = {{"spp", 64}};
  double events = 0.0;
  for (auto _ : state) {
    auto result = haze::render(scene, "reference", options);
    events += result.stats["scattering_events"].get<double>();
  }
  // Rates are per second of wall time (UseRealTime); the inverse is the grind time per event.
  state.counters["events_per_second"] = benchmark::Counter(events, benchmark::Counter::kIsRate);
  state.counters["events"] = events / static_cast<double>(state.iterations());
}
BENCHMARK(BM_ReferenceHomogeneous)->Name("reference/homogeneous/threads")->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
