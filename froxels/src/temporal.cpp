// TemporalFroxels: jittered slices blended with the previous frame's froxels, reprojected.
#include <haze/core/error.h>
#include <haze/core/progress.h>
#include <haze/froxels/temporal.h>

#include <haze/froxels/reproject_row.h>

#include "build.h"

#include <algorithm>
#include <cmath>

namespace haze {

namespace {

bool same_shape(const FroxelGrid& a, const FroxelGrid& b) {
  return a.nx == b.nx && a.ny == b.ny && a.nz == b.nz && a.near == b.near && a.far == b.far;
}

// A still camera: the froxels are where they were, so the blend is element by element.
void blend_still(Froxels& next, const Froxels& previous, float w, int threads) {
  const auto body = [&](long long a, long long b) {
    for (auto e = static_cast<size_t>(a); e < static_cast<size_t>(b); ++e) {
      next.inscatter[e] += (1.0f - w) * (previous.inscatter[e] - next.inscatter[e]);
      next.transmittance[e] += (1.0f - w) * (previous.transmittance[e] - next.transmittance[e]);
    }
  };
  // A body of one reference: std::function keeps it without allocating.
  parallel_for(static_cast<long long>(next.inscatter.size()), threads, 1 << 14, [&body](long long a, long long b) { body(a, b); });
}

// A moved camera: each froxel's point (column (i, j)'s ray at boundary(k)) is found in the
// previous frame's grid, which is looked up there (reproject_row); outside the previous frustum
// nothing blends. Per column first (its ray in the previous clip space and from the previous eye),
// then rows of froxels.
void blend_moved(Froxels& next, const Froxels& previous, const Camera& columns, const Camera& previous_columns, float w, int threads,
                 std::vector<float>& kept) {
  const FroxelGrid& g = next.grid;
  const size_t nx = static_cast<size_t>(g.nx), plane = nx * static_cast<size_t>(g.ny);
  kept.resize(8 * plane);
  float* const ax = kept.data();  // then ay, aw, bx, by, bw, dd, du2, each plane long
  const glm::dmat4 to_clip = previous_columns.projection * previous_columns.view;
  const Vec3 eye = Vec3(previous_columns.view_inverse[3]);
  const auto each_column = [&](long long j0, long long j1) {
    for (auto j = static_cast<int>(j0); j < j1; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const Ray ray = columns.generate_ray(i + 0.5, j + 0.5);
        const glm::dvec4 A = to_clip * glm::dvec4(ray.origin, 1.0), B = to_clip * glm::dvec4(ray.direction, 0.0);
        const Vec3 delta = ray.origin - eye;
        const double values[8] = {A.x, A.y, A.w, B.x, B.y, B.w, glm::dot(delta, delta), 2.0 * glm::dot(delta, ray.direction)};
        const size_t at = static_cast<size_t>(j) * nx + static_cast<size_t>(i);
        for (size_t q = 0; q < 8; ++q) ax[q * plane + at] = static_cast<float>(values[q]);
      }
  };
  parallel_for(g.ny, threads, 1, [&each_column](long long a, long long b) { each_column(a, b); });
  const froxels_detail::CompositeVolume volume{&previous.inscatter.data()->x, &previous.transmittance.data()->x, g.nx, g.ny, g.nz,
                                               static_cast<float>(g.near), std::log(static_cast<float>(g.near)),
                                               static_cast<float>(g.nz / std::log(g.far / g.near))};
  const auto each_row = [&](long long r0, long long r1) {
    for (auto r = r0; r < r1; ++r) {
      const size_t at = static_cast<size_t>(r % g.ny) * nx;
      const float* c = ax + at;
      froxels_detail::reproject_row(volume, {c, c + plane, c + 2 * plane, c + 3 * plane, c + 4 * plane, c + 5 * plane, c + 6 * plane, c + 7 * plane,
                                             static_cast<float>(g.boundary(static_cast<int>(r / g.ny))), 1.0f - w, g.nx,
                                             &next.inscatter[static_cast<size_t>(r) * nx].x, &next.transmittance[static_cast<size_t>(r) * nx].x});
    }
  };
  parallel_for(static_cast<long long>(g.nz) * g.ny, threads, 16, [&each_row](long long a, long long b) { each_row(a, b); });
}

bool reprojects(const Camera& c) { return c.type == Camera::Type::pinhole || (c.type == Camera::Type::matrices && c.projection[2][3] != 0.0); }

}  // namespace

double TemporalFroxels::jitter_of(long long n) {
  constexpr double kInverseGolden = 0.6180339887498949;  // R1: the golden ratio's low-discrepancy sequence
  const double u = 0.5 + static_cast<double>(n % (1LL << 40)) * kInverseGolden;
  return u - std::floor(u) - 0.5;
}

const Froxels& TemporalFroxels::build(const Solution& solution, const Camera& camera, const FroxelGrid& grid, const RenderOptions& options) {
  if (!(blend > 0.0 && blend <= 1.0)) throw Error("temporal.blend", to_text(blend), "the new frame's weight, in (0, 1]");
  Froxels& next = frames_[static_cast<size_t>(1 - current_)];
  const Froxels& previous = frames_[static_cast<size_t>(current_)];
  froxels_detail::build(solution, camera, next, grid, jitter ? jitter_of(frame_) : 0.0, options);
  ++frame_;
  const bool history = frames_built_ > 0 && blend < 1.0 && same_shape(previous.grid, grid) && camera.width_px == camera_.width_px &&
                       camera.height_px == camera_.height_px;
  const auto w = static_cast<float>(blend);
  if (history && camera == camera_) {
    blend_still(next, previous, w, options.threads);
  } else if (history && reprojects(camera) && reprojects(camera_)) {
    blend_moved(next, previous, froxels_detail::column_camera(camera, grid.nx, grid.ny), froxels_detail::column_camera(camera_, grid.nx, grid.ny), w,
                options.threads, columns_);
  }
  camera_ = camera;
  current_ = 1 - current_;
  ++frames_built_;
  return frames_[static_cast<size_t>(current_)];
}

}  // namespace haze
