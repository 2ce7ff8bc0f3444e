// TemporalFroxels: jittered slices blended with the previous frame's froxels, reprojected.
#include <haze/core/error.h>
#include <haze/core/progress.h>
#include <haze/froxels/temporal.h>

#include "build.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>

namespace haze {

namespace {

bool same_shape(const FroxelGrid& a, const FroxelGrid& b) {
  return a.nx == b.nx && a.ny == b.ny && a.nz == b.nz && a.near == b.near && a.far == b.far;
}

// Froxels::sample in float at grid coordinates: x, y in columns (i at column i's centre), z in
// slices (k at boundary(k), -1 at near).
void sample(const Froxels& f, float x, float y, float z, Vec3f& l, Vec3f& t) {
  const FroxelGrid& g = f.grid;
  x = std::clamp(x, 0.0f, static_cast<float>(g.nx - 1)), y = std::clamp(y, 0.0f, static_cast<float>(g.ny - 1));
  z = std::clamp(z, -1.0f, static_cast<float>(g.nz - 1));
  const int i = std::min(static_cast<int>(x), std::max(g.nx - 2, 0)), j = std::min(static_cast<int>(y), std::max(g.ny - 2, 0));
  const int k = std::min(static_cast<int>(std::floor(z)), g.nz - 1);
  const float a = g.nx > 1 ? x - static_cast<float>(i) : 0.0f, b = g.ny > 1 ? y - static_cast<float>(j) : 0.0f;
  const float c = z - static_cast<float>(k);
  const int di = g.nx > 1 ? 1 : 0;
  const size_t row = static_cast<size_t>(g.nx) * (g.ny > 1 ? 1 : 0);
  auto column = [&](int kk, Vec3f& cl, Vec3f& ct) {
    if (kk < 0) {  // near: nothing in-scattered yet
      cl = Vec3f(0.0f), ct = Vec3f(1.0f);
      return;
    }
    const size_t at = (static_cast<size_t>(kk) * static_cast<size_t>(g.ny) + static_cast<size_t>(j)) * static_cast<size_t>(g.nx) + static_cast<size_t>(i);
    const Vec3f* fl = f.inscatter.data() + at;
    const Vec3f* ft = f.transmittance.data() + at;
    cl = (1.0f - b) * ((1.0f - a) * fl[0] + a * fl[di]) + b * ((1.0f - a) * fl[row] + a * fl[row + di]);
    ct = (1.0f - b) * ((1.0f - a) * ft[0] + a * ft[di]) + b * ((1.0f - a) * ft[row] + a * ft[row + di]);
  };
  column(k, l, t);
  if (c > 0.0f && k + 1 < g.nz) {
    Vec3f l1, t1;
    column(k + 1, l1, t1);
    l += c * (l1 - l), t += c * (t1 - t);
  }
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

// ln x for x > 0 normal, within 2e-5 absolute: the exponent and a fifth-degree fit of ln over
// the mantissa in [1, 2) (a lookup coordinate needs no more).
float fast_log(float x) {
  const auto bits = std::bit_cast<std::uint32_t>(x);
  const auto e = static_cast<float>(static_cast<int>(bits >> 23) - 127);
  const float m = std::bit_cast<float>((bits & 0x7FFFFFu) | 0x3F800000u) - 1.0f;
  // ln(1 + m), m in [0, 1): least-squares fit.
  const float p = m * (0.99949556f + m * (-0.49190896f + m * (0.28947478f + m * (-0.13606275f + m * 0.03215845f))));
  return e * 0.69314718f + p;
}

using ColumnToPrevious = TemporalFroxels::ColumnToPrevious;

// A moved camera: each froxel's point (column (i, j)'s ray at boundary(k)) is found in the
// previous frame's grid, which is sampled there; outside the previous frustum nothing blends.
// Row by row of froxels, contiguous, after a pass over the columns.
void blend_moved(Froxels& next, const Froxels& previous, const Camera& columns, const Camera& previous_columns, float w, int threads,
                 std::vector<ColumnToPrevious>& scratch) {
  const FroxelGrid& g = next.grid;
  const size_t nx = static_cast<size_t>(g.nx), plane = nx * static_cast<size_t>(g.ny);
  scratch.resize(plane);
  const glm::dmat4 to_clip = previous_columns.projection * previous_columns.view;
  const Vec3 eye = Vec3(previous_columns.view_inverse[3]);
  const auto each_column = [&](long long j0, long long j1) {
    for (auto j = static_cast<int>(j0); j < j1; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const Ray ray = columns.generate_ray(i + 0.5, j + 0.5);
        const Vec3 delta = ray.origin - eye;
        scratch[static_cast<size_t>(j) * nx + static_cast<size_t>(i)] = {glm::vec4(to_clip * glm::dvec4(ray.origin, 1.0)), glm::vec4(to_clip * glm::dvec4(ray.direction, 0.0)),
                                                                        static_cast<float>(glm::dot(delta, delta)), static_cast<float>(2.0 * glm::dot(delta, ray.direction))};
      }
  };
  parallel_for(g.ny, threads, 1, [&each_column](long long a, long long b) { each_column(a, b); });
  const auto slices_per_log = static_cast<float>(g.nz / std::log(g.far / g.near)), log_near = static_cast<float>(std::log(g.near));
  const auto near = static_cast<float>(g.near), nx_f = static_cast<float>(g.nx), ny_f = static_cast<float>(g.ny);
  const auto each_row = [&](long long r0, long long r1) {
    for (auto r = r0; r < r1; ++r) {
      const int k = static_cast<int>(r / g.ny), j = static_cast<int>(r % g.ny);
      const auto d = static_cast<float>(g.boundary(k));
      const ColumnToPrevious* column = scratch.data() + static_cast<size_t>(j) * nx;
      Vec3f* l = next.inscatter.data() + static_cast<size_t>(r) * nx;
      Vec3f* t = next.transmittance.data() + static_cast<size_t>(r) * nx;
      for (size_t i = 0; i < nx; ++i) {
        const glm::vec4 clip = column[i].A + d * column[i].B;
        if (!(clip.w > 0.0f)) continue;
        const float inverse_w = 1.0f / clip.w;
        const float x = (0.5f * clip.x * inverse_w + 0.5f) * nx_f - 0.5f, y = (0.5f - 0.5f * clip.y * inverse_w) * ny_f - 0.5f;
        if (!(x >= -0.5f && x <= nx_f - 0.5f && y >= -0.5f && y <= ny_f - 0.5f)) continue;
        const float d_then2 = std::max(column[i].dd + d * (column[i].du2 + d), 0.0f);
        const float z = d_then2 > near * near ? slices_per_log * (0.5f * fast_log(d_then2) - log_near) - 1.0f : -1.0f;
        Vec3f hl, ht;
        sample(previous, x, y, z, hl, ht);
        l[i] += (1.0f - w) * (hl - l[i]);
        t[i] += (1.0f - w) * (ht - t[i]);
      }
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
