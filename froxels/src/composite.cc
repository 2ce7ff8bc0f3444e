// Dispatch and scalar reference of the composite's row kernel (Highway skeleton layout).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "composite.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include "composite-inl.h"

#include <hwy/highway.h>

#if HWY_ONCE
namespace haze::froxels_detail {

HWY_EXPORT(CompositeRowKernel);

void composite_row(const CompositeVolume& volume, const CompositeRow& row) { HWY_DYNAMIC_DISPATCH(CompositeRowKernel)(volume, row); }

// Froxels::sample's lookup in float32, one pixel at a time.
void composite_row_reference(const CompositeVolume& v, const CompositeRow& row) {
  const int nx = v.nx, ny = v.ny, nz = v.nz, w = row.width;
  const size_t plane = static_cast<size_t>(nx) * static_cast<size_t>(ny);
  const float y = std::clamp((static_cast<float>(row.py) + 0.5f) / static_cast<float>(row.height) * static_cast<float>(ny) - 0.5f, 0.0f,
                             static_cast<float>(ny - 1));
  const int j = std::min(static_cast<int>(y), std::max(ny - 2, 0));
  const float b = ny > 1 ? y - static_cast<float>(j) : 0.0f;
  const size_t dx = nx > 1 ? 1 : 0, dy = ny > 1 ? static_cast<size_t>(nx) : 0;
  for (int px = 0; px < w; ++px) {
    const float x = std::clamp((static_cast<float>(px) + 0.5f) / static_cast<float>(w) * static_cast<float>(nx) - 0.5f, 0.0f, static_cast<float>(nx - 1));
    const int i = std::min(static_cast<int>(x), std::max(nx - 2, 0));
    const float a = nx > 1 ? x - static_cast<float>(i) : 0.0f;
    const float d = row.depth[px];
    const float z = d > v.near ? std::min(v.slices_per_log * (std::log(d) - v.log_near) - 1.0f, static_cast<float>(nz - 1)) : -1.0f;
    const int k = static_cast<int>(std::floor(z));
    const float c = z - static_cast<float>(k);
    const size_t at = static_cast<size_t>(j) * static_cast<size_t>(nx) + static_cast<size_t>(i);
    const float w00 = (1.0f - a) * (1.0f - b), w10 = a * (1.0f - b), w01 = (1.0f - a) * b, w11 = a * b;
    float l[3], t[3];
    // Slice kk's bilinear L_in and T (kk < 0: near, nothing in-scattered yet), weighted, added.
    const auto column = [&](int kk, float weight, bool first) {
      for (int ch = 0; ch < 3; ++ch) {
        float lc = 0.0f, tc = 1.0f;
        if (kk >= 0) {
          const size_t o = static_cast<size_t>(kk) * plane + at;
          const auto tap = [&](const float* f) {
            return w00 * f[3 * o + ch] + w10 * f[3 * (o + dx) + ch] + w01 * f[3 * (o + dy) + ch] + w11 * f[3 * (o + dx + dy) + ch];
          };
          lc = tap(v.inscatter), tc = tap(v.transmittance);
        }
        l[ch] = (first ? 0.0f : l[ch]) + weight * lc, t[ch] = (first ? 0.0f : t[ch]) + weight * tc;
      }
    };
    const bool between = c > 0.0f && k + 1 < nz;
    column(k, between ? 1.0f - c : 1.0f, true);
    if (between) column(k + 1, c, false);
    const float* in = row.colour + static_cast<size_t>(px) * static_cast<size_t>(row.colour_channels);
    float* to = row.out + static_cast<size_t>(px) * static_cast<size_t>(row.out_channels);
    for (int ch = 0; ch < 3; ++ch) to[ch] = l[ch] + t[ch] * in[ch];
  }
}

}  // namespace haze::froxels_detail
#endif  // HWY_ONCE
