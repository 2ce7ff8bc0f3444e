// Dispatch and scalar reference for the discrete-ordinate row sweep (Highway skeleton layout).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "dom_sweep.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include "dom_sweep-inl.h"

#include <hwy/highway.h>

#include <algorithm>
#include <cmath>

#if HWY_ONCE
namespace haze::grids {

HWY_EXPORT(DomSweepRow);

namespace {

// 1 / alpha_e of the diamond scheme on one axis (dom_sweep.h) for a cell of extinction sigma,
// a = |w_e| / h_e and sum = a_x + a_y + a_z, without dividing by a (tau = sigma / a):
//   1 / alpha(tau) = (sigma^2 + 3 sigma a + 6 a^2) / (sigma^2 + 2 sigma a + 3 a^2),
//   1 / (1 - a / (sigma + 2 (sum - a))) = (sigma + 2 sum - 2 a) / (sigma + 2 sum - 3 a) where that
//   bound is positive (else it does not bind), the smaller of the two.
float diamond_g(float sigma, float a, float sum, bool bound) {
  const float g = (a * (6.0f * a + 3.0f * sigma) + sigma * sigma) / std::max(a * (3.0f * a + 2.0f * sigma) + sigma * sigma, kDiamondTiny);
  const float q = sigma + 2.0f * sum - 3.0f * a;
  return bound && q > 0.0f ? std::min(g, (sigma + 2.0f * sum - 2.0f * a) / q) : g;
}

}  // namespace

void dom_sweep_row_reference(const DomOctant& o, const DomRow& r) {
  const auto p = static_cast<size_t>(o.directions), n = static_cast<size_t>(o.terms), np = static_cast<size_t>(o.terms_padded);
  float* light = r.scratch;
  for (int m = 0; m < r.count; ++m) {
    const size_t c = r.cell0 + static_cast<size_t>(static_cast<long>(m) * r.step);
    const auto x = static_cast<size_t>(r.x0 + m * r.step);
    const float sigma_t = r.sigma_t_scale * r.density[c], sigma_s = r.albedo * sigma_t;
    float* y = r.y_row + x * p;
    float* z = r.z_row + x * p;
    const bool empty = sigma_t == 0.0f;  // scatters nothing: no source needed
    float t[3] = {0.0f, 0.0f, 0.0f};     // the first-collision source's change along travel, over it
    if (r.first_slope && !empty)
      for (size_t e = 0; e < 3; ++e) t[e] = r.first_slope[c * 3 + e] * o.sign[e];
    // Every direction of the cell; true where a leaving value came out below 0 (kFixUpSlack).
    auto directions = [&](bool bound) {
      bool negative = false;
      for (size_t d = 0; d < p; ++d) {
        float first = empty ? 0.0f
                      : r.first ? r.first[c * r.first_stride + d]
                      : r.first_half ? r.first_scale[c] * static_cast<float>(r.first_half[c * r.first_stride + d]) : 0.0f;
        if (r.first_rows && !empty)
          for (size_t l = 0; l < static_cast<size_t>(r.first_lights); ++l)
            first += r.first_factor[c * static_cast<size_t>(r.first_lights) + l] * r.first_rows[l * r.first_stride + d];
        float s = first;
        if (r.m_in && !empty)
          for (size_t k = 0; k < n; ++k) s += o.lq[k * p + d] * r.m_in[c * n + k];
        if (!o.diamond) {
          const float l = (sigma_s * s + o.a[d] * r.x_run[d] + o.a[p + d] * y[d] + o.a[2 * p + d] * z[d]) / (sigma_t + o.a[3 * p + d]);
          r.x_run[d] = y[d] = z[d] = light[d] = l;
          continue;
        }
        float* face[3] = {r.x_run + d, y + d, z + d};
        const float sum = o.a[d] + o.a[p + d] + o.a[2 * p + d];
        float g[3], shift[3], num = sigma_s * s, den = sigma_t + o.a[4 * p + d];
        for (size_t e = 0; e < 3; ++e) {
          const float a = o.a[e * p + d];
          g[e] = diamond_g(sigma_t, a, sum, bound);
          shift[e] = sigma_s * first * t[e] / (12.0f * sum + 2.0f * sigma_t + kDiamondTiny);
          num += a * g[e] * (*face[e] - shift[e]), den += a * g[e];
        }
        const float l = num / std::max(den, kDiamondTiny), slack = kFixUpSlack * (std::abs(*face[0]) + std::abs(*face[1]) + std::abs(*face[2]) + std::abs(l));
        for (size_t e = 0; e < 3; ++e) {
          *face[e] = g[e] * (l + shift[e]) - (g[e] - 1.0f) * *face[e];
          negative = negative || *face[e] + slack < 0.0f;
        }
        light[d] = l;
      }
      return negative;
    };
    // A cell that may still take the bound (r.mark) goes first with alpha(tau) alone, from a copy
    // of its entering faces; if a leaving value comes out below 0, it is marked and goes again.
    if (o.diamond && r.mark && r.bounded && r.bounded[c * 8] == 0) {
      float* saved = light + p + np;
      std::copy(r.x_run, r.x_run + p, saved);
      std::copy(y, y + p, saved + p);
      std::copy(z, z + p, saved + 2 * p);
      if (directions(false)) {
        std::copy(saved, saved + p, r.x_run);
        std::copy(saved + p, saved + 2 * p, y);
        std::copy(saved + 2 * p, saved + 3 * p, z);
        r.bounded[c * 8] = 1;
        directions(true);
      }
    } else {
      directions(!r.bounded || r.bounded[c * 8] != 0);
    }
    float* out = r.m_out + c * n;
    for (size_t k = 0; k < n; ++k) {
      float sum = 0.0f;
      for (size_t d = 0; d < p; ++d) sum += o.q[d * np + k] * light[d];
      out[k] += sum;
    }
  }
}

void dom_sweep_row(const DomOctant& octant, const DomRow& row) { HWY_DYNAMIC_DISPATCH(DomSweepRow)(octant, row); }

}  // namespace haze::grids
#endif  // HWY_ONCE
