// Method "network" (seed 001) on this machine, in the paper's setting scaled up: N particles
// uniform in a ball (optical radius 4, albedo 0.9, HG g = 0.3) lit by a sun, D directions.
// - Field: the kd-tree and the particle sizes from 8 nearest neighbours;
// - Build: the visibility network (the density at each particle, projection, sort, links);
// - LightMap: one light's depth map and the direct light at every particle;
// - Iteration: one sweep of every direction (grey: one channel; coloured: three), with the
//   separable phase (terms 0, automatic) or the full matrix (terms = D).
// - Update: the next frame after a fraction of the particles moved (diameters given, as a
//   simulation hands them over): update_network against solve_network over the new positions,
//   both without iterating (the networks, the depth map and the direct light only).
// - Render: a 512 x 512 image of the cloud (two suns and a sky, as the paper's figure 5), the
//   splat (the paper's renderer) against the exact march.
// - Frame: the paper's frame (section 4: "one iteration in each frame, and when the light sources
//   move, we take the solution of the previous light position as the initial value"): both suns
//   turned by a degree, update_network with one iteration, and the splat at 512 x 512.
// Run: build/release/bench/haze_bench_network --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
// Counters: grind, seconds per particle (Field, LightMap), per particle and direction (Build), per particle,
// direction and channel (Iteration), per pixel (Render), printed with SI prefixes (n: nanoseconds).
#include <haze/core/rng.h>
#include <haze/particles/network.h>

#include <benchmark/benchmark.h>

namespace {

using namespace haze;
using namespace haze::particles;

struct Cloud {
  std::vector<Vec3f> positions;
  ParticleView view;
  explicit Cloud(long long count, bool grey = true) {
    Rng rng(3);
    while (static_cast<long long>(positions.size()) < count) {
      const Vec3 x(2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
      if (glm::dot(x, x) < 1.0) positions.emplace_back(x);
    }
    view.positions = positions;
    view.material.sigma_t = grey ? Rgb(4.0) : Rgb(4.0, 4.4, 4.8);
    view.material.albedo = Rgb(0.9);
    view.material.phase = PhaseFunction::henyey_greenstein(0.3);
  }
};

const std::vector<Light> kSun{DirectionalLight{glm::normalize(Vec3(-0.5, -0.7, -0.5)), Rgb(1.0)}};

// Args: particles.
void BM_Field(benchmark::State& state) {
  const Cloud cloud(state.range(0));
  for (auto _ : state) {
    const ParticleField field(cloud.view);
    benchmark::DoNotOptimize(field.h(0));
  }
  state.counters["grind"] = benchmark::Counter(static_cast<double>(state.range(0)), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// Args: particles, directions.
void BM_Build(benchmark::State& state) {
  const Cloud cloud(state.range(0));
  const ParticleField field(cloud.view);
  const DirectionSet dirs = DirectionSet::fibonacci(static_cast<int>(state.range(1)));
  const NetworkWindow window = network_window(field, default_window(field));
  for (auto _ : state) {
    const VisibilityNetwork v = build_visibility(field, field.density_at_particles(0), dirs, window, 0);
    benchmark::DoNotOptimize(v.upstream.data());
  }
  state.counters["window"] = window.size;
  state.counters["grind"] = benchmark::Counter(static_cast<double>(state.range(0) * state.range(1)),
                                                  benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// Args: particles.
void BM_LightMap(benchmark::State& state) {
  const Cloud cloud(state.range(0));
  const ParticleField field(cloud.view);
  double texels = 0.0;
  for (auto _ : state) {
    const LightDepthMap map(field, kSun[0], 0);
    double sum = 0.0;
    for (size_t p = 0; p < field.size(); ++p) sum += map.depth(field.position(p));
    benchmark::DoNotOptimize(sum);
    texels = map.resolution();
  }
  state.counters["texels"] = texels;
  state.counters["grind"] = benchmark::Counter(static_cast<double>(state.range(0)), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// Args: particles, directions, terms (0: automatic; D: the full matrix), grey.
void BM_Iteration(benchmark::State& state) {
  const Cloud cloud(state.range(0), state.range(3) != 0);
  const ParticleField field(cloud.view);
  NetworkSettings settings;
  settings.directions = static_cast<int>(state.range(1));
  settings.terms = static_cast<int>(state.range(2));
  settings.max_iterations = 2;  // start from a lit state
  NetworkSolution s = solve_network(field, kSun, settings);
  for (auto _ : state) benchmark::DoNotOptimize(iterate_network(s, 0));
  state.counters["channels"] = s.channels;
  state.counters["terms"] = s.terms;
  state.counters["grind"] = benchmark::Counter(static_cast<double>(state.range(0) * state.range(1) * s.channels),
                                                  benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// Args: particles, particles moved per 1000, 1: update_network, 0: solve_network (a full build).
void BM_Update(benchmark::State& state) {
  Cloud cloud(state.range(0));
  const std::vector<double> sizes = ParticleField(cloud.view).diameters();
  std::vector<float> diameters(sizes.begin(), sizes.end());
  cloud.view.diameters = diameters;
  std::vector<Vec3f> next = cloud.positions;
  Rng rng(7);
  const auto stride = static_cast<size_t>(1000 / state.range(1));
  for (size_t p = 0; p < next.size(); p += stride) {  // moved by up to half a mean particle width
    const Vec3 x = Vec3(next[p]) + 0.02 * Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5);
    if (glm::length(x) < 0.99) next[p] = Vec3f(x);
  }
  ParticleView moved_view = cloud.view;
  moved_view.positions = next;
  const ParticleField field(cloud.view), moved(moved_view);
  NetworkSettings settings;
  settings.max_iterations = 0;
  const NetworkSolution previous = solve_network(field, kSun, settings);
  NetworkSolution::Update u;
  for (auto _ : state) {
    if (state.range(2)) {
      state.PauseTiming();
      NetworkSolution copy = previous;
      state.ResumeTiming();
      const NetworkSolution s = update_network(std::move(copy), moved, kSun, settings);
      u = s.update;
      state.PauseTiming();  // not the release of the arrays
    } else {
      benchmark::DoNotOptimize(solve_network(moved, kSun, settings).rho.data());
      state.PauseTiming();
    }
    state.ResumeTiming();
  }
  const auto n = static_cast<double>(state.range(0));
  state.counters["changed"] = static_cast<double>(u.changed);
  state.counters["rho%"] = 100.0 * static_cast<double>(u.density) / n;
  state.counters["columns%"] = 100.0 * u.columns;
  state.counters["direct%"] = 100.0 * static_cast<double>(u.direct) / n;
}

// Seed 001's figure 5: two suns (left-up and bottom-right) and a sky; turned by `degrees` about y.
std::vector<Light> two_suns(double degrees) {
  const double a = degrees * kPi / 180.0;
  const auto turned = [&](const Vec3& v) { return glm::normalize(Vec3(std::cos(a) * v.x + std::sin(a) * v.z, v.y, -std::sin(a) * v.x + std::cos(a) * v.z)); };
  return {DirectionalLight{turned(Vec3(0.6, -0.7, -0.3)), Rgb(1.0)}, DirectionalLight{turned(Vec3(-0.5, 0.6, -0.4)), Rgb(0.6)},
          SkyLight{Rgb(0.1, 0.15, 0.25)}};
}
Scene framing(const std::vector<Light>& lights, int size) {
  Scene scene;
  scene.lights = lights;
  scene.camera.position = Vec3(0.0, 0.5, 3.2), scene.camera.look_at = Vec3(0.0);
  scene.camera.fov_y_deg = 45.0;
  scene.camera.width_px = scene.camera.height_px = size;
  return scene;
}

// Args: particles, pixels on a side, 1: splat, 0: march.
void BM_Render(benchmark::State& state) {
  const Cloud cloud(state.range(0));
  const ParticleField field(cloud.view);
  const std::vector<Light> lights = two_suns(0.0);
  NetworkSettings settings;
  const NetworkSolution s = solve_network(field, lights, settings);
  const Scene scene = framing(lights, static_cast<int>(state.range(1)));
  const NetworkRender render = state.range(2) ? NetworkRender::splat : NetworkRender::march;
  for (auto _ : state) benchmark::DoNotOptimize(render_network(scene, field, s, {}, render).data());
  state.counters["grind"] = benchmark::Counter(static_cast<double>(state.range(1) * state.range(1)),
                                                  benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// Args: particles, pixels on a side.
void BM_Frame(benchmark::State& state) {
  const Cloud cloud(state.range(0));
  const ParticleField field(cloud.view);
  NetworkSettings settings;
  NetworkSolution s = solve_network(field, two_suns(0.0), settings);
  settings.max_iterations = 1;
  double degrees = 0.0;
  for (auto _ : state) {
    degrees += 1.0;
    const std::vector<Light> lights = two_suns(degrees);
    s = update_network(std::move(s), field, lights, settings);
    Scene scene = framing(lights, static_cast<int>(state.range(1)));
    scene.camera.position = Vec3(3.2 * std::sin(degrees * kPi / 180.0), 0.5, 3.2 * std::cos(degrees * kPi / 180.0));
    benchmark::DoNotOptimize(render_network(scene, field, s).data());
  }
}

}  // namespace

BENCHMARK(BM_Frame)->Args({1024, 512})->Args({512, 512})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Render)->Args({1024, 512, 1})->Args({512, 512, 1})->Args({1024, 128, 0})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Field)->Arg(1024)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Build)
    ->Args({1024, 128})
    ->Args({1024, 32})
    ->Args({1024, 512})
    ->Args({10000, 128})
    ->Args({100000, 128})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_LightMap)->Arg(1024)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Iteration)
    ->Args({1024, 128, 0, 1})
    ->Args({1024, 128, 128, 1})
    ->Args({1024, 128, 0, 0})
    ->Args({1024, 32, 0, 1})
    ->Args({1024, 512, 0, 1})
    ->Args({10000, 128, 0, 1})
    ->Args({100000, 128, 0, 1})
    ->Args({100000, 128, 0, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Update)
    ->Args({10000, 1, 1})
    ->Args({10000, 1, 0})
    ->Args({100000, 1, 1})
    ->Args({100000, 10, 1})
    ->Args({100000, 100, 1})
    ->Args({100000, 1, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
