// Per-target kernel of eye_cells_row (haze/grids/eye_cells.h; Highway: included once per target
// by foreach_target.h).
#if defined(HAZE_GRIDS_EYE_CELLS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_GRIDS_EYE_CELLS_INL_H_
#undef HAZE_GRIDS_EYE_CELLS_INL_H_
#else
#define HAZE_GRIDS_EYE_CELLS_INL_H_
#endif

#include <haze/grids/eye_cells.h>

#include <hwy/highway.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

HWY_BEFORE_NAMESPACE();
namespace haze::grids::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// A row in chunks: each chunk's texel and bilinear weights in vectors over cells, then per cell
// its weights c in vectors over terms (four table rows of `stride` floats, zeros past `terms`)
// dotted with each channel's moments (a cell's vector load reaches into the next cell's moments,
// which the zeros cancel; the row's last cells within a vector of the end dot term by term).
HWY_NOINLINE void EyeCellsRowKernel(const EyeCellsRow& row) {
  constexpr int kChunk = 64, kMaxStride = 64;
  const hn::ScalableTag<float> d;
  const hn::RebindToSigned<decltype(d)> di;
  using V = hn::Vec<decltype(d)>;
  const int lanes = static_cast<int>(hn::Lanes(d)), side = row.side, stride = row.stride, terms = row.terms;
  HWY_ALIGN float w_of[4][kChunk + 16];
  HWY_ALIGN int32_t at_of[kChunk + 16];
  HWY_ALIGN float c[kMaxStride];
  const float half = 0.5f * static_cast<float>(side);
  const V ayz = hn::Set(d, std::abs(row.dy) + std::abs(row.dz)), dy = hn::Set(d, row.dy);
  const V one = hn::Set(d, 1.0f), zero = hn::Zero(d), h = hn::Set(d, half), texel_max = hn::Set(d, static_cast<float>(side - 1));
  const V corner_max = hn::Set(d, static_cast<float>(side - 2));
  const bool lower = row.dz < 0.0f;
  for (int x0 = 0; x0 < row.count; x0 += kChunk) {
    const int n = std::min(kChunk, row.count - x0);
    for (int p = 0; p < n; p += lanes) {
      const V ddx = hn::MulAdd(hn::Iota(d, static_cast<float>(x0 + p)), hn::Set(d, row.dx), hn::Set(d, row.x0));
      const V norm = hn::Add(hn::Abs(ddx), ayz);
      V u = hn::Div(ddx, norm), v = hn::Div(dy, norm);
      if (lower) {  // the lower hemisphere folded out
        const V fu = hn::CopySign(hn::Sub(one, hn::Abs(v)), u), fv = hn::CopySign(hn::Sub(one, hn::Abs(u)), v);
        u = fu, v = fv;
      }
      // Bilinear between texel centres, clamped at the map's edge.
      const V fs = hn::Min(hn::Max(hn::MulSub(hn::Add(u, one), h, hn::Set(d, 0.5f)), zero), texel_max);
      const V ft = hn::Min(hn::Max(hn::MulSub(hn::Add(v, one), h, hn::Set(d, 0.5f)), zero), texel_max);
      const V s0 = hn::Min(hn::Floor(fs), corner_max), t0 = hn::Min(hn::Floor(ft), corner_max);
      const V a = hn::Sub(fs, s0), b = hn::Sub(ft, t0), not_a = hn::Sub(one, a), not_b = hn::Sub(one, b);
      hn::Store(hn::Mul(not_a, not_b), d, w_of[0] + p), hn::Store(hn::Mul(a, not_b), d, w_of[1] + p);
      hn::Store(hn::Mul(not_a, b), d, w_of[2] + p), hn::Store(hn::Mul(a, b), d, w_of[3] + p);
      hn::Store(hn::Mul(hn::ConvertTo(di, hn::MulAdd(t0, hn::Set(d, static_cast<float>(side)), s0)), hn::Set(di, stride)), di, at_of + p);
    }
    for (int p = 0; p < n; ++p) {
      const float* t00 = row.table + at_of[p];
      const float* t01 = t00 + static_cast<size_t>(side) * static_cast<size_t>(stride);
      const V w00 = hn::Set(d, w_of[0][p]), w10 = hn::Set(d, w_of[1][p]), w01 = hn::Set(d, w_of[2][p]), w11 = hn::Set(d, w_of[3][p]);
      for (int k = 0; k < stride; k += lanes)
        hn::Store(hn::MulAdd(w11, hn::LoadU(d, t01 + stride + k),
                             hn::MulAdd(w01, hn::LoadU(d, t01 + k), hn::MulAdd(w10, hn::LoadU(d, t00 + stride + k), hn::Mul(w00, hn::LoadU(d, t00 + k))))),
                  d, c + k);
      const size_t first = static_cast<size_t>(x0 + p) * static_cast<size_t>(terms);
      for (int ch = 0; ch < row.channels; ++ch) {
        const float* m = row.moments[ch] + first;
        float j = 0.0f;
        if (HWY_LIKELY(first + static_cast<size_t>(stride) <= row.readable)) {
          V sum = zero;
          for (int k = 0; k < stride; k += lanes) sum = hn::MulAdd(hn::Load(d, c + k), hn::LoadU(d, m + k), sum);
          j = hn::GetLane(hn::SumOfLanes(d, sum));
        } else {
          for (int k = 0; k < terms; ++k) j += c[k] * m[k];
        }
        row.out[ch][x0 + p] = row.scale[ch] * std::max(0.0f, j);
      }
    }
  }
}

}  // namespace haze::grids::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HAZE_GRIDS_EYE_CELLS_INL_H_
