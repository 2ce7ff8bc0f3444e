// A host renderer's frame (tracker issue 24, docs/HOST.md): 1920 x 1080 pixels, 4 point lights,
// the host's floor given as its depth buffer, the camera moving every frame around one solution
// prepared before the loop. Stages: the per-pixel layers (Solution::render with the depth), the
// froxel build (160 x 90 x 64) and the CPU composite of the froxels at 1080p (the GL pass's work).
// Media: homogeneous fog (analytic, SIMD airlight) and a 128^3 heterogeneous cloud (propagation).
#include <haze/froxels/froxels.h>
#include <haze/core/rng.h>
#include <haze/all.h>

#include <benchmark/benchmark.h>

#include <cmath>
#include <limits>

namespace haze {
namespace {

constexpr int kWidth = 1920, kHeight = 1080, kPoses = 8;

Scene host_scene(bool cloud) {
  Scene scene;
  scene.camera.width_px = kWidth, scene.camera.height_px = kHeight, scene.camera.fov_y_deg = 45.0;
  MediumDesc m;
  m.albedo = Rgb(0.9);
  m.phase = PhaseFunction::henyey_greenstein(0.6);
  if (cloud) {
    // Gaussian blobs in a ball, 128^3 samples over [-1.5, 1.5]^3.
    constexpr int n = 128;
    GridDensity grid;
    grid.resolution = {n, n, n};
    grid.values.assign(static_cast<size_t>(n) * n * n, 0.0f);
    Rng rng(3, 0);
    std::vector<Vec3> centres;
    for (int b = 0; b < 40; ++b) centres.push_back(direction_around(Vec3(0, 1, 0), 2.0 * rng.uniform() - 1.0, 2.0 * kPi * rng.uniform()) * rng.uniform());
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const Vec3 x = 3.0 * (Vec3(i, j, k) + 0.5) / double(n) - 1.5;
          double d = 0.0;
          for (const Vec3& c : centres) d += std::exp(-glm::dot(x - c, x - c) / (2.0 * 0.09));
          grid.values[(static_cast<size_t>(k) * n + j) * n + i] = static_cast<float>(d);
        }
    m.density = grid;
    m.bounds = {Vec3(-1.5), Vec3(1.5)};
    m.sigma_t = Rgb(2.0);
  } else {
    m.sigma_t = Rgb(0.26);
  }
  scene.medium = m;
  scene.lights = {PointLight{Vec3(-1.2, 1.8, 0.0), Rgb(14, 11, 7)}, PointLight{Vec3(1.6, 0.9, -1.5), Rgb(3, 5, 10)},
                  PointLight{Vec3(0.3, 2.8, -0.5), Rgb(8)}, PointLight{Vec3(-2.0, 0.5, 1.5), Rgb(2, 1, 1)}};
  return scene;
}

// Pose p of the moving camera: an orbit around the origin, looking at it.
Camera pose(const Camera& base, int p) {
  Camera c = base;
  const double a = 0.1 * p;
  c.position = Vec3(6.0 * std::sin(a), 1.5, 6.0 * std::cos(a)), c.look_at = Vec3(0.0, 0.5, 0.0);
  return c;
}

// The host's floor at y = -1.5 as distances along each pixel's ray (+inf above the horizon).
std::vector<float> floor_depth(const Camera& camera) {
  std::vector<float> depth;
  for (int y = 0; y < camera.height_px; ++y)
    for (int x = 0; x < camera.width_px; ++x) {
      const Ray ray = camera.pixel_ray(x, y);
      depth.push_back(ray.direction.y < 0.0 ? static_cast<float>((-1.5 - ray.origin.y) / ray.direction.y) : std::numeric_limits<float>::infinity());
    }
  return depth;
}

// Args: medium (0 fog, analytic; 1 cloud, propagation 128^3), stage (0 per-pixel layers, 1 froxel
// build, 2 froxel composite).
void BM_HostFrame(benchmark::State& state) {
  const bool cloud = state.range(0) != 0;
  const int stage = static_cast<int>(state.range(1));
  register_all();
  const Scene scene = host_scene(cloud);
  RenderOptions options;
  options.threads = 2;
  if (cloud) options.settings = {{"resolution", 128}};
  const Solution solution = prepare(scene, cloud ? "propagation" : "analytic", options);
  std::vector<Camera> cameras;
  std::vector<std::vector<float>> depths;
  for (int p = 0; p < kPoses; ++p) cameras.push_back(pose(scene.camera, p)), depths.push_back(floor_depth(cameras.back()));
  RenderOptions frame;
  frame.threads = 2;
  const Froxels froxels = stage == 2 ? build_froxels(solution, cameras[0], {}, frame) : Froxels{};
  const Image host(kWidth, kHeight);
  int p = 0;
  for (auto _ : state) {
    const Camera& camera = cameras[static_cast<size_t>(p)];
    const std::vector<float>& depth = depths[static_cast<size_t>(p)];
    if (stage == 0) benchmark::DoNotOptimize(solution.render(View{camera, depth, true}, frame).inscatter->data().data());
    if (stage == 1) benchmark::DoNotOptimize(build_froxels(solution, camera, {}, frame).inscatter.data());
    if (stage == 2) benchmark::DoNotOptimize(composite_froxels(froxels, host, depth).data().data());
    p = (p + 1) % kPoses;
  }
  const double rays = stage == 1 ? 160.0 * 90.0 * 64.0 : double(kWidth) * kHeight;
  state.counters["rays_per_second"] = benchmark::Counter(rays, benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(std::string(cloud ? "propagation 128^3" : "analytic fog") + ", " + (stage == 0 ? "per-pixel layers" : stage == 1 ? "froxel build" : "froxel composite (CPU)"));
}
BENCHMARK(BM_HostFrame)->Name("host/frame_1080p_4_lights/medium,stage")
    ->Args({0, 0})->Args({0, 1})->Args({0, 2})->Args({1, 0})->Args({1, 1})->Args({1, 2})
    ->UseRealTime()->Unit(benchmark::kMillisecond)->MinTime(2.0);

}  // namespace
}  // namespace haze
