// Dispatch and scalar reference of the temporal froxels' reprojection row kernel (Highway skeleton
// layout).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "reproject.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include "reproject-inl.h"

#include <hwy/highway.h>

#if HWY_ONCE
namespace haze::froxels_detail {

HWY_EXPORT(ReprojectRowKernel);

void reproject_row(const CompositeVolume& previous, const ReprojectRow& row) { HWY_DYNAMIC_DISPATCH(ReprojectRowKernel)(previous, row); }

// Froxels::sample's lookup in float32 where each froxel's point was, one froxel at a time.
void reproject_row_reference(const CompositeVolume& v, const ReprojectRow& row) {
  const int nx = v.nx, ny = v.ny, nz = v.nz;
  const size_t plane = static_cast<size_t>(nx) * static_cast<size_t>(ny), dx = nx > 1 ? 1 : 0, dy = ny > 1 ? static_cast<size_t>(nx) : 0;
  const auto fx = static_cast<float>(nx), fy = static_cast<float>(ny), d = row.distance;
  for (int i = 0; i < row.width; ++i) {
    const float w = row.aw[i] + d * row.bw[i];
    if (!(w > 0.0f)) continue;
    const float inverse_w = 1.0f / w;
    float x = (0.5f * (row.ax[i] + d * row.bx[i]) * inverse_w + 0.5f) * fx - 0.5f, y = (0.5f - 0.5f * (row.ay[i] + d * row.by[i]) * inverse_w) * fy - 0.5f;
    if (!(x >= -0.5f && x <= fx - 0.5f && y >= -0.5f && y <= fy - 0.5f)) continue;
    const float d2 = row.dd[i] + d * (row.du2[i] + d);
    const float z = d2 > v.near * v.near ? std::min(v.slices_per_log * (0.5f * std::log(d2) - v.log_near) - 1.0f, static_cast<float>(nz - 1)) : -1.0f;
    x = std::clamp(x, 0.0f, fx - 1.0f), y = std::clamp(y, 0.0f, fy - 1.0f);
    const int ci = std::min(static_cast<int>(x), std::max(nx - 2, 0)), cj = std::min(static_cast<int>(y), std::max(ny - 2, 0));
    const float a = nx > 1 ? x - static_cast<float>(ci) : 0.0f, b = ny > 1 ? y - static_cast<float>(cj) : 0.0f;
    const int k = static_cast<int>(std::floor(z));
    const float c = z - static_cast<float>(k);
    const size_t at = static_cast<size_t>(cj) * static_cast<size_t>(nx) + static_cast<size_t>(ci);
    const float w00 = (1.0f - a) * (1.0f - b), w10 = a * (1.0f - b), w01 = (1.0f - a) * b, w11 = a * b;
    const bool between = c > 0.0f && k + 1 < nz;
    for (int ch = 0; ch < 3; ++ch) {
      // Slice kk's bilinear L_in and T (kk < 0: near, nothing in-scattered yet).
      const auto slice = [&](int kk, float& l, float& t) {
        l = 0.0f, t = 1.0f;
        if (kk < 0) return;
        const size_t o = static_cast<size_t>(kk) * plane + at;
        const auto tap = [&](const float* f) {
          return w00 * f[3 * o + ch] + w10 * f[3 * (o + dx) + ch] + w01 * f[3 * (o + dy) + ch] + w11 * f[3 * (o + dx + dy) + ch];
        };
        l = tap(v.inscatter), t = tap(v.transmittance);
      };
      float l, t;
      slice(k, l, t);
      if (between) {
        float l1, t1;
        slice(k + 1, l1, t1);
        l = (1.0f - c) * l + c * l1, t = (1.0f - c) * t + c * t1;
      }
      float& to_l = row.inscatter[3 * i + ch];
      float& to_t = row.transmittance[3 * i + ch];
      to_l += row.keep * (l - to_l);
      to_t += row.keep * (t - to_t);
    }
  }
}

}  // namespace haze::froxels_detail
#endif  // HWY_ONCE
