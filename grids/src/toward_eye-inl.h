// Per-target kernel of march_toward_eye (haze/grids/march_rays.h; Highway: included once per
// target by foreach_target.h): the lights' in-scatter toward one eye at each cell's centre, a row
// of cells in SIMD lanes, and the prefilter over three planes.
#if defined(HAZE_GRIDS_TOWARD_EYE_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_GRIDS_TOWARD_EYE_INL_H_
#undef HAZE_GRIDS_TOWARD_EYE_INL_H_
#else
#define HAZE_GRIDS_TOWARD_EYE_INL_H_
#endif

#include <haze/grids/march_rays.h>
#include <haze/simd/phase_params.h>

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include <algorithm>

#include "march_light-inl.h"

HWY_BEFORE_NAMESPACE();
namespace haze::grids::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Cells (x0 .. x0 + lanes, y, z) of the grid with one ghost cell around it (cell i of the volume
// is i + 1 there; x past the last: the last's) into raw[c * row_stride + x], C channels:
// sum_l p(to_light . w) E_l V_l e^(-sigma_t depth_l), w the unit vector from the eye, a ghost
// cell's depth and visibility those of the volume's cell beside it (as the march's clamped reads).
template <int C, class D>
HWY_INLINE void TowardEyeCells(D d, const MarchVolume& v, const simd::PhaseParams& phase, const float* eye, const MarchLight* lights, int count, int y,
                               int z, int x0, float* HWY_RESTRICT raw, size_t row_stride) {
  using V = hn::Vec<D>;
  const hn::RebindToSigned<D> di;
  const V zero = hn::Zero(d);
  const auto xi = hn::Sub(hn::Min(hn::Iota(di, x0), hn::Set(di, v.n[0] + 1)), hn::Set(di, 1));  // the volume's cell, -1 to n
  V p[3];
  p[0] = hn::MulAdd(hn::Add(hn::ConvertTo(d, xi), hn::Set(d, 0.5f)), hn::Set(d, v.h[0]), hn::Set(d, v.lo[0]));
  p[1] = hn::Set(d, v.lo[1] + (static_cast<float>(y - 1) + 0.5f) * v.h[1]);
  p[2] = hn::Set(d, v.lo[2] + (static_cast<float>(z - 1) + 0.5f) * v.h[2]);
  V w[3];
  for (int e = 0; e < 3; ++e) w[e] = hn::Sub(p[e], hn::Set(d, eye[e]));
  const V inv_w = simd::HWY_NAMESPACE::ReciprocalSqrt(hn::MulAdd(w[0], w[0], hn::MulAdd(w[1], w[1], hn::Mul(w[2], w[2]))));
  for (int e = 0; e < 3; ++e) w[e] = hn::Mul(w[e], inv_w);
  const int cy = std::clamp(y - 1, 0, v.n[1] - 1), cz = std::clamp(z - 1, 0, v.n[2] - 1);
  const auto cell = hn::Add(hn::Min(hn::Max(xi, hn::Zero(di)), hn::Set(di, v.n[0] - 1)), hn::Set(di, (cz * v.n[1] + cy) * v.n[0]));
  const int depth_stride = v.depth_stride > 0 ? v.depth_stride : v.light_count;
  const auto at = hn::Mul(cell, hn::Set(di, depth_stride));
  const float depth_0 = v.sigma_t[0] * v.depth_scale[0];
  const bool grey = v.sigma_t[1] * v.depth_scale[1] == depth_0 && v.sigma_t[2] * v.depth_scale[2] == depth_0;
  V in[C];
  for (int c = 0; c < C; ++c) in[c] = zero;
  // The attenuation planes' cells: whole rows of the volume's, but at the ghosts.
  const size_t cells = static_cast<size_t>(v.n[0]) * static_cast<size_t>(v.n[1]) * static_cast<size_t>(v.n[2]);
  const bool whole = x0 >= 1 && x0 + static_cast<int>(hn::Lanes(d)) <= v.n[0] + 1;
  const size_t first = static_cast<size_t>((cz * v.n[1] + cy) * v.n[0] + x0 - 1);
  for (int l = 0; l < count; ++l) {
    const MarchLight& light = lights[l];
    if (v.attenuation && light.plane >= 0) {
      const float* plane = v.attenuation + static_cast<size_t>(light.plane) * cells;
      const V weight = hn::Mul(LightWeight(d, light, phase, p, w, hn::Set(d, 1.0f)), whole ? hn::LoadU(d, plane + first) : hn::GatherIndex(d, plane, cell));
      for (int c = 0; c < C; ++c) in[c] = hn::MulAdd(weight, hn::Set(d, light.intensity[c]), in[c]);
      continue;
    }
    const V visible = v.visibility ? hn::GatherIndex(d, v.visibility + light.slot, at) : hn::Set(d, 1.0f);
    AddLight<C>(d, v, light, phase, p, w, hn::Max(hn::GatherIndex(d, v.depths + light.slot, at), zero), visible, grey, in);
  }
  for (int c = 0; c < C; ++c) hn::StoreU(in[c], d, raw + static_cast<size_t>(c) * row_stride + static_cast<size_t>(x0));
}

// x (at least 0) as float16 bits in the low half of each 32-bit lane: at most 65504, and 0 below
// 2^-14 (no subnormals: the march decodes by moving the bits into a float32's).
template <class D>
HWY_INLINE hn::Vec<hn::RebindToUnsigned<D>> Half(D d, hn::Vec<D> x) {
  const hn::Rebind<hwy::float16_t, D> df16;
  const hn::Rebind<uint16_t, D> du16;
  const hn::Vec<D> kept = hn::IfThenZeroElse(hn::Lt(x, hn::Set(d, 6.103515625e-5f)), hn::Min(x, hn::Set(d, 65504.0f)));
  return hn::PromoteTo(hn::RebindToUnsigned<D>(), hn::BitCast(du16, hn::DemoteTo(df16, kept)));
}

// Planes [z0, z1) of the ghosted grid (n + 2 cells a side) into out (cells of C + 1 float16
// values, the channels then the density: MarchVolume::folded), through `window`: three raw planes (C channels of rows of
// `row_stride` floats, the row's first and last cells continued linearly one float to each side,
// so that the second difference across the ends is 0), then a row for the density.
template <int C>
HWY_INLINE void TowardEyeAll(const MarchVolume& v, const simd::PhaseParams& phase, const float* eye, const MarchLight* lights, int count, int z0,
                             int z1, uint32_t* HWY_RESTRICT out, float* HWY_RESTRICT window, size_t row_stride) {
  const hn::ScalableTag<float> d;
  const int nx = v.n[0] + 2, ny = v.n[1] + 2, nz = v.n[2] + 2;
  const size_t lanes = hn::Lanes(d), plane = static_cast<size_t>(ny) * C * row_stride;
  float* density_row = window + 3 * plane;
  const auto raw_plane = [&](int z) { return window + static_cast<size_t>(z % 3) * plane; };
  // raw row (y, channel c) of plane z: [c * row_stride + 1 ...] within row y's block
  const auto row = [&](int z, int y, int c) { return raw_plane(z) + (static_cast<size_t>(y) * C + static_cast<size_t>(c)) * row_stride; };
  const auto fill = [&](int z) {
    for (int y = 0; y < ny; ++y) {
      float* block = raw_plane(z) + static_cast<size_t>(y) * C * row_stride;
      for (int x = 0; x < nx; x += static_cast<int>(lanes)) TowardEyeCells<C>(d, v, phase, eye, lights, count, y, z, x, block + 1, row_stride);
      for (int c = 0; c < C; ++c) {
        float* r = row(z, y, c);
        r[0] = nx >= 2 ? 2.0f * r[1] - r[2] : r[1];
        r[nx + 1] = nx >= 2 ? 2.0f * r[nx] - r[nx - 1] : r[nx];
      }
    }
  };
  const int first = std::max(z0 - 1, 0), last = std::min(z1, nz - 1);
  for (int z = first; z <= last && z < z0 + 1; ++z) fill(z);  // the planes before z0's neighbour above
  const hn::Vec<decltype(d)> twelfth = hn::Set(d, 1.0f / 12.0f), two = hn::Set(d, 2.0f), zero = hn::Zero(d);
  const hn::RebindToUnsigned<decltype(d)> du;
  constexpr int kWords = (C + 1) / 2;  // a cell's: channels 0 and 1 (or channel 0 and the density), channel 2 and the density
  float inv_scale[4];
  for (int k = 0; k < 4; ++k) inv_scale[k] = 1.0f / v.folded_scale[C == 1 && k == 1 ? 3 : k];
  for (int z = z0; z < z1; ++z) {
    if (z + 1 <= last) fill(z + 1);
    for (int y = 0; y < ny; ++y) {
      // The density's row, each ghost the cell's beside it (the march's clamped read).
      const int cy = std::clamp(y - 1, 0, v.n[1] - 1), cz = std::clamp(z - 1, 0, v.n[2] - 1);
      const float* from = v.density + (static_cast<size_t>(cz) * static_cast<size_t>(v.n[1]) + static_cast<size_t>(cy)) * static_cast<size_t>(v.n[0]);
      float* rho = density_row;
      rho[0] = from[0], rho[nx - 1] = from[v.n[0] - 1];
      std::copy(from, from + v.n[0], rho + 1);
      uint32_t* o = out + (static_cast<size_t>(z) * ny + static_cast<size_t>(y)) * nx * kWords;
      for (int x = 0; x < nx; x += static_cast<int>(lanes)) {
        // f - (f_-x + f_+x + ... - 2 f per axis) / 12: the mean error of linear interpolation over a
        // cell, h^2 f'' / 12, taken back (an axis without both neighbours adds no term).
        hn::Vec<decltype(d)> value[C + 1];
        for (int c = 0; c < C; ++c) {
          const float* r = row(z, y, c) + 1;
          const auto f = hn::LoadU(d, r + x), f2 = hn::Mul(two, f);
          auto second = hn::Sub(hn::Add(hn::LoadU(d, r + x - 1), hn::LoadU(d, r + x + 1)), f2);
          if (y > 0 && y + 1 < ny) second = hn::Add(second, hn::Sub(hn::Add(hn::LoadU(d, row(z, y - 1, c) + 1 + x), hn::LoadU(d, row(z, y + 1, c) + 1 + x)), f2));
          if (z > 0 && z + 1 < nz) second = hn::Add(second, hn::Sub(hn::Add(hn::LoadU(d, row(z - 1, y, c) + 1 + x), hn::LoadU(d, row(z + 1, y, c) + 1 + x)), f2));
          value[c] = hn::Max(hn::NegMulAdd(twelfth, second, f), zero);
        }
        value[C] = hn::LoadU(d, rho + x);
        // Cells of C + 1 float16 values over their scales, two to a 32-bit word (the channels, then
        // the density).
        hn::Vec<decltype(du)> word[kWords];
        for (int k = 0; k < kWords; ++k)
          word[k] = hn::Or(Half(d, hn::Mul(value[2 * k], hn::Set(d, inv_scale[2 * k]))),
                           hn::ShiftLeft<16>(Half(d, hn::Mul(value[2 * k + 1], hn::Set(d, inv_scale[2 * k + 1])))));
        const size_t n = std::min(lanes, static_cast<size_t>(nx - x));
        HWY_ALIGN uint32_t tail[kWords * hn::MaxLanes(d)];
        uint32_t* to = n == lanes ? o + static_cast<size_t>(x) * kWords : tail;
        if constexpr (kWords == 1) hn::StoreU(word[0], du, to);
        else hn::StoreInterleaved2(word[0], word[1], du, to);
        if (n < lanes) std::copy(tail, tail + n * kWords, o + static_cast<size_t>(x) * kWords);
      }
    }
  }
}

HWY_NOINLINE void TowardEye(const MarchVolume& v, const simd::PhaseParams& phase, const float* eye, const MarchLight* lights, int count, int z0, int z1,
                            uint32_t* out, float* window, size_t row_stride) {
  if (v.channels == 1) {
    TowardEyeAll<1>(v, phase, eye, lights, count, z0, z1, out, window, row_stride);
  } else {
    TowardEyeAll<3>(v, phase, eye, lights, count, z0, z1, out, window, row_stride);
  }
}

}  // namespace haze::grids::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HAZE_GRIDS_TOWARD_EYE_INL_H_
