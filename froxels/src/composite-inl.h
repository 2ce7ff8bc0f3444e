// Per-target composite kernel (Highway: included once per target by foreach_target.h).
#if defined(HAZE_FROXELS_COMPOSITE_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_FROXELS_COMPOSITE_INL_H_
#undef HAZE_FROXELS_COMPOSITE_INL_H_
#else
#define HAZE_FROXELS_COMPOSITE_INL_H_
#endif

#include <haze/froxels/composite_row.h>

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include <algorithm>
#include <cmath>

HWY_BEFORE_NAMESPACE();
namespace haze::froxels_detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// A row in chunks: each chunk's lookups (column i, slice k, weights a and c) in full vectors over
// pixels, then per pixel its eight taps as four-float vectors (L_in or T, RGB and the next
// froxel's R, unused), lerped first between the row's two froxel rows and kept while the pixels
// that follow share its column and slice.
HWY_NOINLINE void CompositeRowKernel(const CompositeVolume& v, const CompositeRow& row) {
#if HWY_TARGET == HWY_SCALAR  // one lane: no four-float vectors
  composite_row_reference(v, row);
#else
  constexpr int kChunk = 64;
  const hn::ScalableTag<float> d;
  const hn::RebindToSigned<decltype(d)> di;
  const hn::FixedTag<float, 4> d4;
  using V4 = hn::Vec<decltype(d4)>;
  const int lanes = static_cast<int>(hn::Lanes(d));
  const int nx = v.nx, ny = v.ny, nz = v.nz, w = row.width;
  const size_t plane = static_cast<size_t>(nx) * static_cast<size_t>(ny), last = plane * static_cast<size_t>(nz) - 1;
  const float y = std::clamp((static_cast<float>(row.py) + 0.5f) / static_cast<float>(row.height) * static_cast<float>(ny) - 0.5f, 0.0f,
                             static_cast<float>(ny - 1));
  const int j = std::min(static_cast<int>(y), std::max(ny - 2, 0));
  const float b = ny > 1 ? y - static_cast<float>(j) : 0.0f;
  const size_t dx = nx > 1 ? 1 : 0, dy = ny > 1 ? static_cast<size_t>(nx) : 0, row_at = static_cast<size_t>(j) * static_cast<size_t>(nx);
  // Per pixel of a chunk: its column i, slice k and the weights of its four lerped taps.
  HWY_ALIGN float w_of[4][kChunk + 16];
  HWY_ALIGN int32_t i_of[kChunk + 16], k_of[kChunk + 16];
  // The chunk's L_in and T, RGB packed (a pixel's four-float store overlaps the next's first float).
  HWY_ALIGN float l_of[3 * kChunk + 16], t_of[3 * kChunk + 16];
  const auto x_scale = hn::Set(d, static_cast<float>(nx) / static_cast<float>(w));
  const auto x_max = hn::Set(d, static_cast<float>(nx - 1)), i_max = hn::Set(d, static_cast<float>(std::max(nx - 2, 0)));
  const auto near = hn::Set(d, v.near), log_near = hn::Set(d, v.log_near), per_log = hn::Set(d, v.slices_per_log);
  const auto last_slice = hn::Set(d, static_cast<float>(nz - 1)), one = hn::Set(d, 1.0f), half = hn::Set(d, 0.5f), zero = hn::Zero(d);
  const auto lane_index = hn::Iota(d, 0.0f);
  // The taps of the last pixel's column and slice pair, lerped between the row's two froxel rows:
  // yl[0], yl[1] at columns i, i + 1 of slice k, yl[2], yl[3] of slice k + 1 (L_in, and yt for T).
  // Neighbouring pixels mostly share them: a pixel then costs eight FMAs.
  V4 yl[4], yt[4];
  int cached_i = -1, cached_k = -2;
  const V4 wy0 = hn::Set(d4, 1.0f - b), wy1 = hn::Set(d4, b);
  const auto load = [&](const float* f, size_t o) {
    if (HWY_LIKELY(o != last)) return hn::LoadU(d4, f + 3 * o);
    HWY_ALIGN const float padded[4] = {f[3 * o], f[3 * o + 1], f[3 * o + 2], 0.0f};  // a four-float load would read past the volume
    return hn::Load(d4, padded);
  };
  const auto fill = [&](int i, int k) {
    for (int s = 0; s < 2; ++s) {
      const int kk = std::min(k + s, nz - 1);
      if (kk < 0) {  // before slice 0: L_in 0 and T 1 at near
        yl[2 * s] = yl[2 * s + 1] = hn::Zero(d4), yt[2 * s] = yt[2 * s + 1] = hn::Set(d4, 1.0f);
        continue;
      }
      const size_t o = static_cast<size_t>(kk) * plane + row_at + static_cast<size_t>(i);
      for (int e = 0; e < 2; ++e) {
        const size_t q = o + (e ? dx : 0);
        yl[2 * s + e] = hn::MulAdd(wy1, load(v.inscatter, q + dy), hn::Mul(wy0, load(v.inscatter, q)));
        yt[2 * s + e] = hn::MulAdd(wy1, load(v.transmittance, q + dy), hn::Mul(wy0, load(v.transmittance, q)));
      }
    }
  };
  for (int x0 = 0; x0 < w; x0 += kChunk) {
    const int n = std::min(kChunk, w - x0);
    // The next row's colour and depth under this chunk, on their way to the cache meanwhile: a
    // row's start otherwise waits for memory (4.6 -> 4.1 ms at 1080p).
    if (row.colour_ahead) {
      const char* colour = reinterpret_cast<const char*>(row.colour_ahead + static_cast<size_t>(x0) * static_cast<size_t>(row.colour_channels));
      const char* depth = reinterpret_cast<const char*>(row.depth_ahead + x0);
      for (int b = 0; b < n * row.colour_channels * 4; b += 64) __builtin_prefetch(colour + b, 1);
      for (int b = 0; b < n * 4; b += 64) __builtin_prefetch(depth + b, 0);
    }
    for (int p = 0; p < n; p += lanes) {
      const auto px = hn::Add(lane_index, hn::Set(d, static_cast<float>(x0 + p)));
      const auto x = hn::Min(hn::Max(hn::MulSub(hn::Add(px, half), x_scale, half), zero), x_max);
      const auto i = hn::Min(hn::Floor(x), i_max);
      const auto a = nx > 1 ? hn::Sub(x, i) : zero;
      hn::Store(hn::ConvertTo(di, i), di, i_of + p);
      // The row's last, partial vector through a copy: its lanes past the end are computed, never used.
      HWY_ALIGN float tail[HWY_MAX_BYTES / sizeof(float)];
      const float* depth = row.depth + x0 + p;
      if (x0 + p + lanes > w) {
        std::fill(std::copy_n(depth, w - x0 - p, tail), tail + lanes, 1.0f);
        depth = tail;
      }
      const auto dist = hn::LoadU(d, depth);
      const auto z = hn::IfThenElse(hn::Gt(dist, near), hn::Min(hn::MulSub(per_log, hn::Sub(hn::Log(d, dist), log_near), one), last_slice),
                                    hn::Set(d, -1.0f));
      const auto k = hn::Floor(z), c = hn::Sub(z, k);
      hn::Store(hn::ConvertTo(di, k), di, k_of + p);
      const auto not_a = hn::Sub(one, a), not_c = hn::Sub(one, c);
      hn::Store(hn::Mul(not_a, not_c), d, w_of[0] + p), hn::Store(hn::Mul(a, not_c), d, w_of[1] + p);
      hn::Store(hn::Mul(not_a, c), d, w_of[2] + p), hn::Store(hn::Mul(a, c), d, w_of[3] + p);
    }
#if HWY_TARGET <= HWY_AVX2  // eight-float vectors: a tap's L_in and T side by side, four FMAs a pixel
    const hn::FixedTag<float, 8> d8;
    hn::Vec<decltype(d8)> ylt[4];
    for (int p = 0; p < n; ++p) {
      const int k = k_of[p], i = i_of[p];
      if (k != cached_k || i != cached_i) {
        fill(i, k), cached_i = i, cached_k = k;
        for (int e = 0; e < 4; ++e) ylt[e] = hn::Combine(d8, yt[e], yl[e]);
      }
      const auto lt = hn::Add(hn::MulAdd(hn::Set(d8, w_of[1][p]), ylt[1], hn::Mul(hn::Set(d8, w_of[0][p]), ylt[0])),
                              hn::MulAdd(hn::Set(d8, w_of[3][p]), ylt[3], hn::Mul(hn::Set(d8, w_of[2][p]), ylt[2])));
      hn::StoreU(hn::LowerHalf(d4, lt), d4, l_of + 3 * p);
      hn::StoreU(hn::UpperHalf(d4, lt), d4, t_of + 3 * p);
    }
#else
    for (int p = 0; p < n; ++p) {
      const int k = k_of[p], i = i_of[p];
      if (k != cached_k || i != cached_i) fill(i, k), cached_i = i, cached_k = k;
      const V4 w00 = hn::Set(d4, w_of[0][p]), w10 = hn::Set(d4, w_of[1][p]), w01 = hn::Set(d4, w_of[2][p]), w11 = hn::Set(d4, w_of[3][p]);
      hn::StoreU(hn::Add(hn::MulAdd(w10, yl[1], hn::Mul(w00, yl[0])), hn::MulAdd(w11, yl[3], hn::Mul(w01, yl[2]))), d4, l_of + 3 * p);
      hn::StoreU(hn::Add(hn::MulAdd(w10, yt[1], hn::Mul(w00, yt[0])), hn::MulAdd(w11, yt[3], hn::Mul(w01, yt[2]))), d4, t_of + 3 * p);
    }
#endif
    // colour = L_in + T colour, over the chunk's floats in full vectors where rows are RGB.
    const float* in = row.colour + static_cast<size_t>(x0) * static_cast<size_t>(row.colour_channels);
    float* to = row.out + static_cast<size_t>(x0) * static_cast<size_t>(row.out_channels);
    int f = 0;
    if (row.colour_channels == 3 && row.out_channels == 3)
      for (; f + lanes <= 3 * n; f += lanes) hn::StoreU(hn::MulAdd(hn::Load(d, t_of + f), hn::LoadU(d, in + f), hn::Load(d, l_of + f)), d, to + f);
    for (; f < 3 * n; ++f) {
      const int px = f / 3, ch = f - 3 * px;
      to[px * row.out_channels + ch] = l_of[f] + t_of[f] * in[px * row.colour_channels + ch];
    }
  }
#endif
}

}  // namespace haze::froxels_detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HAZE_FROXELS_COMPOSITE_INL_H_
