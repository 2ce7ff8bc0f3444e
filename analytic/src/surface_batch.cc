// Dispatch and scalar reference for the batched surface shading (Highway skeleton layout).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "surface_batch.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include "surface_batch-inl.h"

#include <hwy/highway.h>

#if HWY_ONCE
#include <haze/analytic/surface_batch.h>

#include <algorithm>
#include <cmath>

namespace haze::analytic {

HWY_EXPORT(ShadePoints);

void shade_points(const ShadingMedium& medium, const ShadingMaterial& material, const ShadingLight* lights, size_t light_count,
                  const ShadingPoints& points, float* radiance) {
  HWY_DYNAMIC_DISPATCH(ShadePoints)(medium, material, lights, light_count, points, radiance);
}

namespace {

// SurfaceAirlightTable::eval in float32, the kernel's EvalJ.
float eval_j(const SurfaceAirlightTable& table, float T, float angle) {
  const int nt = table.t_samples(), na = table.angle_samples();
  const float fi = std::clamp(T / (1.0f + T), 0.0f, 1.0f) * static_cast<float>(nt - 1);
  const float fk = std::clamp(angle * static_cast<float>(1.0 / kPi), 0.0f, 1.0f) * static_cast<float>(na - 1);
  const float i = std::min(std::floor(fi), static_cast<float>(nt - 2)), k = std::min(std::floor(fk), static_cast<float>(na - 2));
  const float x = fi - i, y = fk - k;
  const float* j = table.values().data() + static_cast<size_t>(k * static_cast<float>(nt) + i);
  const float a0 = j[0] + x * (j[1] - j[0]), a1 = j[nt] + x * (j[nt + 1] - j[nt]);
  return (a0 + y * (a1 - a0)) / (1.0f + T);
}

}  // namespace

void shade_points_reference(const ShadingMedium& medium, const ShadingMaterial& m, const ShadingLight* lights, size_t light_count,
                            const ShadingPoints& pts, float* radiance) {
  const bool phong = m.ks[0] != 0.0f || m.ks[1] != 0.0f || m.ks[2] != 0.0f;
  const float pi = static_cast<float>(kPi);
  for (size_t i = 0; i < pts.count; ++i) {
    const float p[3] = {pts.p[0][i], pts.p[1][i], pts.p[2][i]}, n[3] = {pts.n[0][i], pts.n[1][i], pts.n[2][i]};
    const float v[3] = {pts.v[0][i], pts.v[1][i], pts.v[2][i]};
    const float vn = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
    float r[3];
    for (int e = 0; e < 3; ++e) r[e] = v[e] - 2.0f * vn * n[e];
    const float cos_r = std::max(0.0f, n[0] * r[0] + n[1] * r[1] + n[2] * r[2]);
    float out[3] = {0.0f, 0.0f, 0.0f};
    for (size_t l = 0; l < light_count; ++l) {
      const ShadingLight& light = lights[l];
      float wi[3];
      for (int e = 0; e < 3; ++e) wi[e] = light.position[e] - p[e];
      const float d2 = wi[0] * wi[0] + wi[1] * wi[1] + wi[2] * wi[2], dist = std::sqrt(d2);
      for (float& w : wi) w /= dist;
      const float cos_i = n[0] * wi[0] + n[1] * wi[1] + n[2] * wi[2];
      if (cos_i > 0.0f && light.visible[i] > 0.0f) {
        float s0 = 0.0f, s1 = dist;
        for (int e = 0; e < 3; ++e) {
          if (std::isinf(medium.lo[e]) && std::isinf(medium.hi[e])) continue;
          const float a = (static_cast<float>(medium.lo[e]) - p[e]) / wi[e], b = (static_cast<float>(medium.hi[e]) - p[e]) / wi[e];
          s0 = std::max(s0, std::min(a, b)), s1 = std::min(s1, std::max(a, b));
        }
        const float inside = std::max(0.0f, s1 - s0);
        float specular = 0.0f;
        if (phong) {
          float cos_alpha = 0.0f;
          for (int e = 0; e < 3; ++e) cos_alpha -= (2.0f * cos_i * n[e] - wi[e]) * v[e];
          specular = (m.shininess + 2.0f) / (2.0f * pi) * (cos_alpha > 0.0f ? std::pow(cos_alpha, m.shininess) : 0.0f);
        }
        for (int c = 0; c < 3; ++c)
          out[c] += (m.kd[c] / pi + m.ks[c] * specular) * light.intensity[c] * cos_i / d2 * std::exp(-medium.sigma_t[c] * inside);
      }
      if (pts.in_medium[i] > 0.0f) {
        const float theta_s = std::acos(std::clamp(cos_i, -1.0f, 1.0f));
        const float theta_r = std::acos(std::clamp(r[0] * wi[0] + r[1] * wi[1] + r[2] * wi[2], -1.0f, 1.0f));
        for (int c = 0; c < 3; ++c) {
          const float T = medium.sigma_t[c] * dist;
          const float j = (m.lambert ? m.kd[c] * eval_j(*m.lambert, T, theta_s) : 0.0f) +
                          (m.phong ? m.ks[c] * eval_j(*m.phong, T, theta_r) * cos_r : 0.0f);
          out[c] += medium.sigma_s[c] * light.intensity[c] * std::exp(-T) / dist * j;
        }
      }
    }
    std::copy_n(out, 3, radiance + 3 * i);
  }
}

}  // namespace haze::analytic
#endif  // HWY_ONCE
