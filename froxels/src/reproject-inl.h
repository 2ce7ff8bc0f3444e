// Per-target reprojection kernel (Highway: included once per target by foreach_target.h).
#if defined(HAZE_FROXELS_REPROJECT_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_FROXELS_REPROJECT_INL_H_
#undef HAZE_FROXELS_REPROJECT_INL_H_
#else
#define HAZE_FROXELS_REPROJECT_INL_H_
#endif

#include <haze/froxels/reproject_row.h>

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include <algorithm>
#include <cmath>

HWY_BEFORE_NAMESPACE();
namespace haze::froxels_detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// A row in chunks: each chunk's lookups (the previous grid's column, row and slice, and their
// weights) in full vectors over froxels, then per froxel its eight taps as four-float vectors
// (L_in or T, RGB and the next froxel's R, unused), blended into the froxel's three floats.
HWY_NOINLINE void ReprojectRowKernel(const CompositeVolume& v, const ReprojectRow& row) {
#if HWY_TARGET == HWY_SCALAR  // one lane: no four-float vectors
  reproject_row_reference(v, row);
#else
  constexpr int kChunk = 64;
  const hn::ScalableTag<float> d;
  const hn::RebindToSigned<decltype(d)> di;
  const hn::FixedTag<float, 4> d4;
  using V4 = hn::Vec<decltype(d4)>;
  const int lanes = static_cast<int>(hn::Lanes(d));
  const int nx = v.nx, ny = v.ny, nz = v.nz;
  const size_t plane = static_cast<size_t>(nx) * static_cast<size_t>(ny), last = plane * static_cast<size_t>(nz) - 1;
  const size_t dx = nx > 1 ? 1 : 0, dy = ny > 1 ? static_cast<size_t>(nx) : 0;
  HWY_ALIGN float a_of[kChunk], b_of[kChunk], c_of[kChunk], valid_of[kChunk];
  HWY_ALIGN int32_t i_of[kChunk], j_of[kChunk], k_of[kChunk];
  const auto fx = hn::Set(d, static_cast<float>(nx)), fy = hn::Set(d, static_cast<float>(ny)), half = hn::Set(d, 0.5f), zero = hn::Zero(d);
  const auto x_max = hn::Set(d, static_cast<float>(nx - 1)), y_max = hn::Set(d, static_cast<float>(ny - 1));
  const auto i_max = hn::Set(d, static_cast<float>(std::max(nx - 2, 0))), j_max = hn::Set(d, static_cast<float>(std::max(ny - 2, 0)));
  const auto near2 = hn::Set(d, v.near * v.near), log_near = hn::Set(d, v.log_near), per_log = hn::Set(d, v.slices_per_log);
  const auto last_slice = hn::Set(d, static_cast<float>(nz - 1)), one = hn::Set(d, 1.0f), distance = hn::Set(d, row.distance);
  const auto load = [&](const float* f, size_t o) {
    if (HWY_LIKELY(o != last)) return hn::LoadU(d4, f + 3 * o);
    HWY_ALIGN const float padded[4] = {f[3 * o], f[3 * o + 1], f[3 * o + 2], 0.0f};  // a four-float load would read past the volume
    return hn::Load(d4, padded);
  };
  const V4 keep = hn::Set(d4, row.keep);
  const auto rgb = hn::FirstN(d4, 3);
  for (int x0 = 0; x0 < row.width; x0 += kChunk) {
    const int n = std::min(kChunk, row.width - x0);
    for (int p = 0; p < n; p += lanes) {
      // The row's last, partial vector through copies: its lanes past the end are computed, never used.
      const int at = x0 + p, count = std::min(lanes, row.width - at);
      const auto in = [&](const float* f) {
        if (count == lanes) return hn::LoadU(d, f + at);
        HWY_ALIGN float tail[HWY_MAX_BYTES / sizeof(float)] = {};
        std::copy_n(f + at, count, tail);
        return hn::Load(d, tail);
      };
      const auto w = hn::MulAdd(distance, in(row.bw), in(row.aw));
      const auto inverse_w = hn::Div(one, w);
      const auto x = hn::Sub(hn::Mul(hn::MulAdd(hn::Mul(half, hn::MulAdd(distance, in(row.bx), in(row.ax))), inverse_w, half), fx), half);
      const auto y = hn::Sub(hn::Mul(hn::NegMulAdd(hn::Mul(half, hn::MulAdd(distance, in(row.by), in(row.ay))), inverse_w, half), fy), half);
      auto valid = hn::And(hn::Gt(w, zero), hn::And(hn::And(hn::Ge(x, hn::Neg(half)), hn::Le(x, hn::Sub(fx, half))),
                                                     hn::And(hn::Ge(y, hn::Neg(half)), hn::Le(y, hn::Sub(fy, half)))));
      const auto d2 = hn::MulAdd(distance, hn::Add(in(row.du2), distance), in(row.dd));
      const auto z = hn::IfThenElse(hn::Gt(d2, near2),
                                    hn::Min(hn::MulSub(per_log, hn::MulSub(half, hn::Log(d, hn::Max(d2, near2)), log_near), one), last_slice),
                                    hn::Set(d, -1.0f));
      const auto xc = hn::Min(hn::Max(x, zero), x_max), yc = hn::Min(hn::Max(y, zero), y_max);
      const auto i = hn::Min(hn::Floor(xc), i_max), j = hn::Min(hn::Floor(yc), j_max), k = hn::Floor(z);
      hn::Store(nx > 1 ? hn::Sub(xc, i) : zero, d, a_of + p), hn::Store(ny > 1 ? hn::Sub(yc, j) : zero, d, b_of + p);
      hn::Store(hn::Sub(z, k), d, c_of + p), hn::Store(hn::IfThenElseZero(valid, one), d, valid_of + p);
      hn::Store(hn::ConvertTo(di, i), di, i_of + p), hn::Store(hn::ConvertTo(di, j), di, j_of + p), hn::Store(hn::ConvertTo(di, k), di, k_of + p);
    }
    for (int p = 0; p < n; ++p) {
      if (valid_of[p] == 0.0f) continue;
      const float a = a_of[p], b = b_of[p], c = c_of[p];
      const int k = k_of[p];
      const size_t column = static_cast<size_t>(j_of[p]) * static_cast<size_t>(nx) + static_cast<size_t>(i_of[p]);
      const V4 w00 = hn::Set(d4, (1.0f - a) * (1.0f - b)), w10 = hn::Set(d4, a * (1.0f - b)), w01 = hn::Set(d4, (1.0f - a) * b), w11 = hn::Set(d4, a * b);
      // Slice kk's bilinear L_in and T (kk < 0: near, nothing in-scattered yet).
      const auto slice = [&](int kk, V4& l, V4& t) {
        if (kk < 0) {
          l = hn::Zero(d4), t = hn::Set(d4, 1.0f);
          return;
        }
        const size_t o = static_cast<size_t>(kk) * plane + column;
        const auto tap = [&](const float* f) {
          return hn::Add(hn::MulAdd(w10, load(f, o + dx), hn::Mul(w00, load(f, o))), hn::MulAdd(w11, load(f, o + dx + dy), hn::Mul(w01, load(f, o + dy))));
        };
        l = tap(v.inscatter), t = tap(v.transmittance);
      };
      V4 l, t;
      slice(k, l, t);
      if (c > 0.0f && k + 1 < nz) {
        V4 l1, t1;
        slice(k + 1, l1, t1);
        const V4 vc = hn::Set(d4, c);
        l = hn::MulAdd(vc, hn::Sub(l1, l), l), t = hn::MulAdd(vc, hn::Sub(t1, t), t);
      }
      float* const to_l = row.inscatter + 3 * (x0 + p);
      float* const to_t = row.transmittance + 3 * (x0 + p);
      if (x0 + p + 1 < row.width) {  // the fourth float is the next froxel's: written back as it is
        const V4 now_l = hn::LoadU(d4, to_l), now_t = hn::LoadU(d4, to_t);
        hn::StoreU(hn::IfThenElse(rgb, hn::MulAdd(keep, hn::Sub(l, now_l), now_l), now_l), d4, to_l);
        hn::StoreU(hn::IfThenElse(rgb, hn::MulAdd(keep, hn::Sub(t, now_t), now_t), now_t), d4, to_t);
      } else {  // the row's last froxel: its three floats alone
        HWY_ALIGN float hl[4], ht[4];
        hn::Store(l, d4, hl), hn::Store(t, d4, ht);
        for (int ch = 0; ch < 3; ++ch) to_l[ch] += row.keep * (hl[ch] - to_l[ch]), to_t[ch] += row.keep * (ht[ch] - to_t[ch]);
      }
    }
  }
#endif
}

}  // namespace haze::froxels_detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HAZE_FROXELS_REPROJECT_INL_H_
