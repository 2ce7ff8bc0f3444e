// Dispatch, fallback and scalar reference for the batched airlight (Highway skeleton layout).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "airlight_batch.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include "airlight_batch-inl.h"

#include <hwy/highway.h>

#if HWY_ONCE
#include <haze/analytic/airlight_batch.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace haze::analytic {

HWY_EXPORT(AirlightBatch);
HWY_EXPORT(TailSums);
HWY_EXPORT(AirlightSlices);
HWY_EXPORT(RowGeometryKernel);
HWY_EXPORT(LayersFromTails);

namespace {

// log T and scale = 2 / ((1 + w)(1 + a)), the kernel's LogTail.
float log_tail_scalar(const AirlightTable& table, float u, float eta, float w, float& scale) {
  const int na = table.a_samples(), ne = table.fine_eta_samples();
  const float eta_max = static_cast<float>(AirlightTable::kEtaMax);
  float a = std::min(u * (1.0f + w), 1e30f);
  float m = std::sqrt(a / (1.0f + a));
  float fa = m * static_cast<float>(na - 1);
  float fe = (std::clamp(eta, -eta_max, eta_max) + eta_max) * (static_cast<float>(ne - 1) / (2.0f * eta_max));
  float fi = std::min(std::floor(fa), static_cast<float>(na - 2)), fj = std::min(std::floor(fe), static_cast<float>(ne - 2));
  float x = fa - fi, y = fe - fj;
  const float* t = table.log_fine_pairs().data() + 2 * static_cast<size_t>(fi * static_cast<float>(ne) + fj);  // t00 t10 t01 t11
  float t0 = t[0] + x * (t[1] - t[0]), t1 = t[2] + x * (t[3] - t[2]);
  scale = 2.0f / ((1.0f + w) * (1.0f + a));
  return t0 + y * (t1 - t0);
}

// One segment in float32, the formulas of the SIMD kernel; false where float64 must redo it.
bool airlight_scalar(const AirlightTable& table, const AirlightChannel& l, const SegmentBatch& b, size_t i, float& value) {
  float tx = l.x - b.ox[i], ty = l.y - b.oy[i], tz = l.z - b.oz[i];
  float d2 = tx * tx + ty * ty + tz * tz, d_sv = std::sqrt(d2);
  float t = tx * b.dx[i] + ty * b.dy[i] + tz * b.dz[i];
  float floor_h = 1e-6f * d_sv;
  float h2 = std::max(d2 - t * t, floor_h * floor_h), h = std::sqrt(h2);
  float u = l.sigma_t * h;
  float w0 = t <= 0.0f ? (d_sv - t) / h : h / (d_sv + t);
  float scale_near, scale_far;
  float near = std::exp(log_tail_scalar(table, u, std::log(w0), w0, scale_near) - l.sigma_t * d_sv) * scale_near;
  float far = 0.0f;
  if (b.length[i] < 3e38f) {
    float xi = b.length[i] - t, d_sp = std::sqrt(xi * xi + h2);
    float wd = xi >= 0.0f ? (xi + d_sp) / h : h / (d_sp - xi);
    far = std::exp(log_tail_scalar(table, u, std::log(wd), wd, scale_far) - l.sigma_t * (b.length[i] + d_sp)) * scale_far;
  }
  value = l.sigma_s * l.intensity * (near - far) / h;
  return !(far >= 0.5f * near || h < 1e-3f * d_sv);
}

// The float64 path for one segment.
float airlight_double(const AirlightTable& table, const AirlightChannel& l, const SegmentBatch& b, size_t i) {
  float value = 0.0f;
  add_airlight_float64(table, l, {b.ox + i, b.oy + i, b.oz + i, b.dx + i, b.dy + i, b.dz + i, b.length + i, 1}, &value);
  return value;
}

// The kernel's UnitTail for one ray.
float unit_tail_scalar(const AirlightTable& table, float t_c, float h_c, float sigma, float at) {
  const float t = t_c - at, d_sv = std::sqrt(t * t + h_c * h_c);
  const float h = std::max({h_c, 1e-6f * d_sv, 1e-20f});
  const float w0 = std::max(t <= 0.0f ? (d_sv - t) / h : h / (d_sv + t), 1e-30f);
  float scale;
  const float log_tail = log_tail_scalar(table, sigma * h, std::log(w0), w0, scale);
  return std::exp(log_tail - sigma * d_sv) * scale / h;
}

void sum_tails_scalar(const AirlightTable& table, const TailRow& row, size_t i, float at, float s[3]) {
  s[0] = s[1] = s[2] = 0.0f;
  for (size_t l = 0; l < row.light_count; ++l) {
    const TailLight& light = row.lights[l];
    const float g = unit_tail_scalar(table, light.t[i], light.h[i], light.sigma_t, at) * (light.share ? light.share[i] : 1.0f);
    for (int c = 0; c < 3; ++c) s[c] += light.weight[c] * g;
  }
}

}  // namespace

void tail_sums(const AirlightTable& table, const TailRow& row, const float* d, float* const sums[3]) {
  HWY_DYNAMIC_DISPATCH(TailSums)(table.log_fine_pairs().data(), table.a_samples(), table.fine_eta_samples(),
                                 static_cast<float>(AirlightTable::kEtaMax), row, d, sums);
}

void airlight_slices(const AirlightTable& table, const TailRow& row, std::span<const float> distances, float* inscatter, float* transmittance,
                     size_t slice_stride) {
  HWY_DYNAMIC_DISPATCH(AirlightSlices)(table.log_fine_pairs().data(), table.a_samples(), table.fine_eta_samples(),
                                       static_cast<float>(AirlightTable::kEtaMax), row, distances.data(), distances.size(), inscatter,
                                       transmittance, slice_stride);
}

void airlight_slice(const AirlightTable& table, const TailRow& row, float distance, float* inscatter, float* transmittance) {
  airlight_slices(table, row, std::span<const float>(&distance, 1), inscatter, transmittance, 0);
}

void layers_from_tails(const TailRow& row, const float* ends, const float* const sums[3], float* inscatter, float* transmittance, float* redo) {
  HWY_DYNAMIC_DISPATCH(LayersFromTails)(row, ends, sums, inscatter, transmittance, redo);
}

void layers_from_tails_reference(const TailRow& row, const float* ends, const float* const sums[3], float* inscatter, float* transmittance,
                                 float* redo) {
  const bool grey = row.sigma_t[0] == row.sigma_t[1] && row.sigma_t[1] == row.sigma_t[2];
  for (size_t i = 0; i < row.count; ++i) {
    const float t0 = row.t0[i], end = ends[i];
    float* l = inscatter + 3 * i;
    float* t = transmittance + 3 * i;
    bool cancels = false;
    for (int c = 0; c < 3; ++c) {
      if (!(end > t0)) {
        l[c] = 0.0f, t[c] = 1.0f;
        continue;
      }
      t[c] = c > 0 && grey ? t[0] : std::isfinite(end) ? std::exp(-row.sigma_t[c] * (end - t0)) : 0.0f;
      const float far = t[c] * sums[c][i];
      cancels = cancels || far > kTailsCancel * row.whole[c][i];
      l[c] = std::max(0.0f, row.whole[c][i] - far);
    }
    redo[i] = cancels ? 1.0f : 0.0f;
  }
}

void row_geometry(const RowGeometry& g, const double origin[3], const double a[3], const double b[3], double px0, size_t count) {
  HWY_DYNAMIC_DISPATCH(RowGeometryKernel)(g, origin, a, b, px0, count);
}

void row_geometry_rays(const RowGeometry& g, const Ray* rays, size_t count) {
  const Aabb box{Vec3(g.lo[0], g.lo[1], g.lo[2]), Vec3(g.hi[0], g.hi[1], g.hi[2])};
  for (size_t x = 0; x < count; ++x) {
    const Ray& ray = rays[x];
    double a = 0.0, b = kInfinity;
    if (!box.clip(ray, a, b) || !(b > a)) a = b = 0.0;  // no medium: L_in 0, T 1 everywhere (a miss may leave a at +inf)
    g.t0[x] = static_cast<float>(a), g.t1[x] = std::isfinite(b) ? static_cast<float>(b) : INFINITY;
    for (size_t l = 0; l < g.light_count; ++l) {
      const Vec3 to_light = Vec3(g.lights[3 * l], g.lights[3 * l + 1], g.lights[3 * l + 2]) - ray.origin;
      const double t = glm::dot(to_light, ray.direction);
      g.t(l)[x] = static_cast<float>(t), g.h(l)[x] = static_cast<float>(glm::length(to_light - t * ray.direction));
    }
  }
}

void tail_sums_reference(const AirlightTable& table, const TailRow& row, const float* d, float* const sums[3]) {
  for (size_t i = 0; i < row.count; ++i) {
    float s[3];
    sum_tails_scalar(table, row, i, d[i], s);
    for (int c = 0; c < 3; ++c) sums[c][i] = s[c];
  }
}

void airlight_slice_reference(const AirlightTable& table, const TailRow& row, float distance, float* inscatter, float* transmittance) {
  for (size_t i = 0; i < row.count; ++i) {
    const float t0 = row.t0[i], t1 = row.t1[i];
    float* l = inscatter + 3 * i;
    float* T = transmittance + 3 * i;
    if (distance <= t0 || t1 <= t0) {
      l[0] = l[1] = l[2] = 0.0f, T[0] = T[1] = T[2] = 1.0f;
      continue;
    }
    const float at = std::min(distance, t1);
    float s[3];
    sum_tails_scalar(table, row, i, at, s);
    for (int c = 0; c < 3; ++c) {
      T[c] = std::exp(-row.sigma_t[c] * (at - t0));
      l[c] = std::max(0.0f, row.whole[c][i] - T[c] * s[c]);
    }
  }
}

void add_airlight_reference(const AirlightTable& table, const AirlightChannel& light, const SegmentBatch& batch, float* out) {
  for (size_t i = 0; i < batch.count; ++i) {
    float value;
    out[i] += airlight_scalar(table, light, batch, i, value) ? value : airlight_double(table, light, batch, i);
  }
}

void add_airlight(const AirlightTable& table, const AirlightChannel& light, const SegmentBatch& batch, float* out) {
  std::vector<float> result(batch.count), fallback(batch.count);
  const float params[6] = {light.x, light.y, light.z, light.sigma_t, light.sigma_s, light.intensity};
  size_t done = HWY_DYNAMIC_DISPATCH(AirlightBatch)(table.log_fine_pairs().data(), table.a_samples(), table.fine_eta_samples(),
                                                    static_cast<float>(AirlightTable::kEtaMax), params, batch.ox, batch.oy,
                                                    batch.oz, batch.dx, batch.dy, batch.dz, batch.length, batch.count,
                                                    result.data(), fallback.data());
  for (size_t i = 0; i < done; ++i) out[i] += fallback[i] != 0.0f ? airlight_double(table, light, batch, i) : result[i];
  // The last partial vector through the scalar reference (same formulas).
  for (size_t i = done; i < batch.count; ++i) {
    float value;
    out[i] += airlight_scalar(table, light, batch, i, value) ? value : airlight_double(table, light, batch, i);
  }
}

}  // namespace haze::analytic
#endif  // HWY_ONCE
