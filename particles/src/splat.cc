// splat_rays (haze/particles/splat.h): dispatch, and its float64 reference.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "splat.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include "splat-inl.h"

#include <hwy/highway.h>

#if HWY_ONCE
#include <haze/particles/field.h>

#include <algorithm>
#include <cmath>

namespace haze::particles {

HWY_EXPORT(SplatRaysKernel);

void splat_rays(const SplatParticles& particles, const float sigma_t[3], int channels, const SplatRays& rays) {
  HWY_DYNAMIC_DISPATCH(SplatRaysKernel)(particles, sigma_t, channels, rays);
}

void splat_rays_reference(const SplatParticles& p, const float sigma_t[3], const SplatRays& r) {
  const auto f64 = [](float v) { return static_cast<double>(v); };
  for (size_t j = 0; j < r.count; ++j) {
    const double o[3] = {f64(r.ox[j]), f64(r.oy[j]), f64(r.oz[j])}, w[3] = {f64(r.dx[j]), f64(r.dy[j]), f64(r.dz[j])};
    const double t_end = r.t_end ? f64(r.t_end[j]) : kInfinity;
    double radiance[3] = {0.0, 0.0, 0.0}, transmittance[3] = {1.0, 1.0, 1.0};
    for (size_t k = 0; k < p.count; ++k) {
      const uint32_t i = p.order[k];
      const double v[3] = {f64(p.x[i]) - o[0], f64(p.y[i]) - o[1], f64(p.z[i]) - o[2]}, h = f64(p.h[i]);
      const double tc = v[0] * w[0] + v[1] * w[1] + v[2] * w[2];
      const double off[3] = {v[0] - tc * w[0], v[1] - tc * w[1], v[2] - tc * w[2]};  // the ray's closest approach less the centre, negated
      const double q = (off[0] * off[0] + off[1] * off[1] + off[2] * off[2]) / (h * h);
      if (!(q < kCut * kCut)) continue;
      double tau = f64(p.amplitude[i]) * std::exp(-q);
      const double lo = tc - kCut * h, hi = tc + kCut * h;
      if (lo < 0.0 || hi > t_end) tau *= std::max(0.0, 0.5 * (std::erf((std::min(hi, t_end) - tc) / h) - std::erf((std::max(lo, 0.0) - tc) / h)));
      const double g[3] = {f64(p.gx[i]), f64(p.gy[i]), f64(p.gz[i])}, m = f64(p.shift[i]);
      double log_direct = 0.0, slope = 0.0;
      for (int a = 0; a < 3; ++a) log_direct += g[a] * (m * w[a] - off[a]), slope += g[a] * w[a];  // g . D
      const double direct = std::exp(std::min(f64(p.max_log[i]), log_direct + f64(p.spread[i]) * slope * slope));
      for (int c = 0; c < 3; ++c) {
        const double e = std::exp(-f64(sigma_t[c]) * tau);
        radiance[c] += transmittance[c] * (1.0 - e) * (f64(p.source[c][i]) + f64(p.direct[c][i]) * direct);
        transmittance[c] *= e;
      }
    }
    for (int c = 0; c < 3; ++c) r.radiance[c][j] = static_cast<float>(radiance[c]), r.transmittance[c][j] = static_cast<float>(transmittance[c]);
  }
}

}  // namespace haze::particles
#endif  // HWY_ONCE
