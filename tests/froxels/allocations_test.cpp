// Heap allocations in a frame (issue 51: after the first frame, a frame allocates nothing). This
// program replaces the global operator new to count every allocation made through it, on any
// thread. The CPU composite into the caller's memory allocates nothing, and neither do the
// froxel build of analytic or propagation and the glow of lights in view once each thread's kept
// row buffers have grown.
#include <haze/froxels/froxels.h>

#include <gtest/gtest.h>

#include "scenes/fog_box.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <new>
#include <string>

namespace {
std::atomic<long long> allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace haze {
namespace {

TEST(FrameAllocations, TheCompositeIntoCallerMemoryAllocatesNothing) {
  const Scene scene = testing::fog_box(64, 36);
  const Solution solution = prepare(scene, "analytic");
  Froxels froxels;
  const FroxelGrid grid{16, 9, 12, 0.1, 20.0};
  build_froxels(solution, scene.camera, froxels, grid, RenderOptions{});
  std::vector<float> colour(3 * 64 * 36, 0.5f), out(colour.size()), depth(64 * 36, std::numeric_limits<float>::infinity());
  for (int threads : {1, 2}) {
    composite_froxels(froxels, ConstImageSpan{colour.data(), 64, 36}, depth, ImageSpan{out.data(), 64, 36}, threads);  // the first frame
    const long long before = allocations.load();
    for (int frame = 0; frame < 5; ++frame)
      composite_froxels(froxels, ConstImageSpan{colour.data(), 64, 36}, depth, ImageSpan{out.data(), 64, 36}, threads);
    EXPECT_EQ(allocations.load() - before, 0) << threads << " threads";
  }
}

// The froxel build into the same Froxels, the camera moving every frame, a light in view and its
// glow added per pixel: after a few frames (each thread's kept row buffers grown), the analytic
// and propagation paths allocate nothing.
TEST(FrameAllocations, TheFroxelBuildAllocatesNothingAfterTheFirstFrames) {
  const Scene scene = testing::fog_box(64, 36, Vec3(0.1, -0.1, 0.4));
  const FroxelGrid grid{16, 9, 12, 0.1, 20.0, 4.0};
  std::vector<float> out(3 * 64 * 36, 0.0f);
  const std::vector<float> depth(64 * 36, 3.0f);
  for (const char* method : {"analytic", "propagation"}) {
    RenderOptions prepared;
    if (std::string(method) == "propagation") prepared.settings = {{"resolution", 16}};
    const Solution solution = prepare(scene, method, prepared);
    Froxels froxels;
    for (int threads : {1, 2}) {
      RenderOptions options;
      options.threads = threads;
      Camera camera = scene.camera;
      const auto frame = [&](int f) {
        camera.position.x = 0.2 + 0.05 * f;
        build_froxels(solution, camera, froxels, grid, options);
        add_glow(solution, camera, froxels, depth, ImageSpan{out.data(), 64, 36}, threads);
      };
      for (int f = 0; f < 4; ++f) frame(f);
      const long long before = allocations.load();
      for (int f = 4; f < 9; ++f) frame(f);
      EXPECT_EQ(allocations.load() - before, 0) << method << ", " << threads << " threads";
    }
  }
}

}  // namespace
}  // namespace haze
