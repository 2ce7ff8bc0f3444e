// Heap allocations in a frame (issue 51: after the first frame, a frame allocates nothing). This
// program replaces the global operator new to count every allocation made through it, on any
// thread. The CPU composite into the caller's memory allocates nothing, and neither do the
// froxel build of analytic, propagation or dom, the glow of lights in view and the per-pixel layers
// of all three into the caller's buffers once each thread's kept row buffers have grown; nor do the
// temporal froxels' reprojection and blend.
#include <haze/froxels/froxels.h>
#include <haze/froxels/temporal.h>

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

// Every form that malloc backs, so that whatever a delete frees came from one of them (the
// nothrow form too: std::stable_sort's temporary buffer takes it, and AddressSanitizer's own would
// pair with this free as a mismatch).
void* operator new(std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size ? size : 1);
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept { return operator new(size, tag); }
// The replacement pairs malloc with free by design; GCC, seeing this operator new inlined into a
// caller, can take free for a mismatch.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace haze {
namespace {

// Row buffers are kept per thread and grow once, when a thread first takes a row: on one thread
// nothing after the warm-up; on two, the worker may first take a row under a loaded machine's
// scheduling only later and grow its buffers then (about a dozen vectors over a froxel build and
// its glow: 13 seen under a parallel ctest), so fewer than one a frame.
// `frame(f)` for ten frames, then twenty counted.
template <class Frame>
void expect_none_per_frame(int threads, Frame frame) {
  for (int f = 0; f < 10; ++f) frame(f);
  const long long before = allocations.load();
  for (int f = 10; f < 30; ++f) frame(f);
  const long long allocated = allocations.load() - before;
  if (threads == 1) EXPECT_EQ(allocated, 0) << "1 thread";
  else EXPECT_LT(allocated, 20) << threads << " threads, 20 frames";
}

// expect_none_per_frame on 1 and 2 threads, frame(camera, options) with the camera moved along x
// by `step` a frame.
template <class Frame>
void expect_none_per_moving_frame(const Camera& start, double step, Frame frame) {
  for (int threads : {1, 2}) {
    RenderOptions options;
    options.threads = threads;
    Camera camera = start;
    expect_none_per_frame(threads, [&](int f) {
      camera.position.x = 0.2 + step * f;
      frame(camera, options);
    });
  }
}

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
// glow added per pixel: after ten frames (each thread's kept row buffers grown once it has taken
// a row), the analytic, propagation and dom paths allocate nothing.
TEST(FrameAllocations, TheFroxelBuildAllocatesNothingAfterTheFirstFrames) {
  const Scene scene = testing::fog_box(64, 36, Vec3(0.1, -0.1, 0.4));
  const FroxelGrid grid{16, 9, 12, 0.1, 20.0, 4.0};
  std::vector<float> out(3 * 64 * 36, 0.0f);
  const std::vector<float> depth(64 * 36, 3.0f);
  for (const char* method : {"analytic", "propagation", "dom"}) {
    RenderOptions prepared;
    if (std::string(method) == "propagation") prepared.settings = {{"resolution", 16}};
    if (std::string(method) == "dom") prepared.settings = {{"resolution", 12}, {"directions", 32}, {"terms", 9}};
    const Solution solution = prepare(scene, method, prepared);
    Froxels froxels;
    expect_none_per_moving_frame(scene.camera, 0.05, [&](const Camera& camera, const RenderOptions& options) {
      build_froxels(solution, camera, froxels, grid, options);
      add_glow(solution, camera, froxels, depth, ImageSpan{out.data(), 64, 36}, options.threads);
    });
  }
}

// The temporal froxels, the camera moving: the build, the history's reprojection and its blend
// reuse their two volumes.
TEST(FrameAllocations, TheTemporalFroxelsAllocateNothingAfterTheFirstFrames) {
  const Scene scene = testing::fog_box(64, 36, Vec3(0.1, -0.1, 0.4));
  const Solution solution = prepare(scene, "analytic");
  TemporalFroxels temporal;
  expect_none_per_moving_frame(scene.camera, 0.01, [&](const Camera& camera, const RenderOptions& options) {
    temporal.build(solution, camera, FroxelGrid{16, 9, 12, 0.1, 20.0, 4.0}, options);
  });
}

// The per-pixel layers into the caller's buffers (render_layers), the camera moving: analytic's
// one pass, propagation's march (and its lattice) and dom's gather allocate nothing once warm.
TEST(FrameAllocations, TheLayersIntoCallerMemoryAllocateNothing) {
  const Scene scene = testing::fog_box(64, 36, Vec3(0.1, -0.1, 0.4));
  std::vector<float> l(3 * 64 * 36), t(l.size()), c(l.size());
  const std::vector<float> depth(64 * 36, 3.0f);
  for (const char* method : {"analytic", "propagation", "dom"}) {
    RenderOptions prepared;
    if (std::string(method) == "propagation") prepared.settings = {{"resolution", 16}};
    if (std::string(method) == "dom") prepared.settings = {{"resolution", 12}, {"directions", 32}, {"terms", 9}};
    const Solution solution = prepare(scene, method, prepared);
    SCOPED_TRACE(method);
    expect_none_per_moving_frame(scene.camera, 0.05, [&](const Camera& camera, const RenderOptions& options) {
      solution.render_layers(View{camera, depth}, {ImageSpan{l.data(), 64, 36}, ImageSpan{t.data(), 64, 36}, ImageSpan{c.data(), 64, 36}}, options);
    });
  }
  // Propagation's lattice (no host depth, a coarse grid close up: a node every few pixels).
  Scene close = testing::fog_box(256, 144, Vec3(0.1, -0.1, 0.4));
  std::vector<float> wide(3 * 256 * 144), wide_t(wide.size());
  const Solution coarse = prepare(close, "propagation", RenderOptions{0, {{"resolution", 8}}, {}, {}});
  SCOPED_TRACE("propagation's lattice");
  expect_none_per_moving_frame(close.camera, 0.05, [&](const Camera& camera, const RenderOptions& options) {
    coarse.render_layers(View{camera}, {ImageSpan{wide.data(), 256, 144}, ImageSpan{wide_t.data(), 256, 144}, ImageSpan{}}, options);
  });
}

}  // namespace
}  // namespace haze
