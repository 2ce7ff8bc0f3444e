// Heap allocations in a frame (issue 51: after the first frame, a frame allocates nothing). This
// program replaces the global operator new to count every allocation made through it, on any
// thread. The CPU composite into the caller's memory allocates nothing; the froxel build's count
// per frame is printed (it is not yet zero: the methods' one-pass paths keep per-row scratch).
#include <haze/froxels/froxels.h>

#include <gtest/gtest.h>

#include "scenes/fog_box.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <new>

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
  const long long before = allocations.load();
  build_froxels(solution, scene.camera, froxels, grid, RenderOptions{});
  std::printf("froxel build (%s, %d x %d x %d): %lld allocations a frame after the first\n", solution.method().c_str(), grid.nx, grid.ny,
              grid.nz, allocations.load() - before);
}

}  // namespace
}  // namespace haze
