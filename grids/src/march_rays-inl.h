// Per-target ray-march kernel (Highway: included once per target by foreach_target.h).
#include <haze/simd/phase_params.h>

#if defined(HAZE_GRIDS_MARCH_RAYS_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_GRIDS_MARCH_RAYS_INL_H_
#undef HAZE_GRIDS_MARCH_RAYS_INL_H_
#else
#define HAZE_GRIDS_MARCH_RAYS_INL_H_
#endif

#include <haze/grids/march_rays.h>

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include <algorithm>

#include "march_light-inl.h"

HWY_BEFORE_NAMESPACE();
namespace haze::grids::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

#if HWY_TARGET != HWY_SCALAR
// Lane offsets (in floats) as the two halves' byte offsets of 64-bit gathers.
template <class D>
struct PairOffsets {
  hn::Vec<hn::RebindToSigned<hn::Repartition<double, D>>> lower, upper;
};
template <class D, class VI>
HWY_INLINE PairOffsets<D> PairOffsetsOf(D, VI offset) {
  const hn::RebindToSigned<D> di;
  const hn::Half<decltype(di)> dih;
  const hn::RebindToSigned<hn::Repartition<double, D>> di64;
  const VI bytes = hn::ShiftLeft<2>(offset);
  return {hn::PromoteTo(di64, hn::LowerHalf(dih, bytes)), hn::PromoteTo(di64, hn::UpperHalf(dih, bytes))};
}
// The float pairs (base[o], base[o + 1]) at each lane's offset o into `first` and `second`: one
// 64-bit gather per half vector, half the loads of two float gathers.
template <class D>
HWY_INLINE void GatherPairsAt(D d, const float* HWY_RESTRICT base, const PairOffsets<D>& at, hn::Vec<D>& first, hn::Vec<D>& second) {
  const hn::Repartition<double, D> dd;
  const double* pairs = reinterpret_cast<const double*>(base);  // read as 8-byte lanes, never as doubles
  const hn::Vec<D> a = hn::BitCast(d, hn::GatherOffset(dd, pairs, at.lower));
  const hn::Vec<D> b = hn::BitCast(d, hn::GatherOffset(dd, pairs, at.upper));
  first = hn::ConcatEven(d, b, a), second = hn::ConcatOdd(d, b, a);
}
template <class D, class VI>
HWY_INLINE void GatherPairs(D d, const float* HWY_RESTRICT base, VI offset, hn::Vec<D>& first, hn::Vec<D>& second) {
  GatherPairsAt(d, base, PairOffsetsOf(d, offset), first, second);
}
#endif

// A 32-bit word's low (kHigh 0) or high float16 half, 0 or normal as march_toward_eye writes them,
// as a float32 2^-112 times its value (its bits moved into a float32's exponent and mantissa):
// weights times kHalfUnit make products of normal floats.
constexpr float kHalfUnit = 5.192296858534828e33f;  // 2^112
template <int kHigh, class D>
HWY_INLINE hn::Vec<D> HalfBits(D d, hn::Vec<hn::RebindToUnsigned<D>> word) {
  const hn::RebindToUnsigned<D> du;
  return hn::BitCast(d, kHigh ? hn::And(hn::ShiftRight<3>(word), hn::Set(du, 0x0FFFE000u)) : hn::ShiftLeft<13>(hn::And(word, hn::Set(du, 0x7FFFu))));
}
#if HWY_TARGET != HWY_SCALAR
#endif

// The packet's rays first .. first + lanes into buffer's rows (origin, direction, t0, dt, steps;
// lanes past `last` repeat the last ray).
template <size_t N>
HWY_INLINE void LoadRays(const RayPacket& rays, size_t first, size_t last, size_t lanes, float (&buffer)[9][N]) {
  const float* inputs[9] = {rays.ox, rays.oy, rays.oz, rays.dx, rays.dy, rays.dz, rays.t0, rays.dt, rays.steps};
  for (int a = 0; a < 9; ++a)
    for (size_t m = 0; m < lanes; ++m) buffer[a][m] = inputs[a][std::min(first + m, last)];
}

// One vector of rays starting at ray `first` (lanes past the end repeat the last ray), `C` channels.
template <int C, class D>
HWY_INLINE void MarchVector(D d, const MarchVolume& v, const simd::PhaseParams& phase, const RayPacket& rays, size_t first,
                            size_t last, float* HWY_RESTRICT radiance_out, float* HWY_RESTRICT transmittance_out) {
  using V = hn::Vec<D>;
  const hn::RebindToSigned<D> di;
  using VI = hn::Vec<decltype(di)>;
  const size_t lanes = hn::Lanes(d);
  HWY_ALIGN float buffer[9][hn::MaxLanes(d)];
  LoadRays(rays, first, last, lanes, buffer);
  V o[3], dir[3];
  for (int e = 0; e < 3; ++e) o[e] = hn::Load(d, buffer[e]), dir[e] = hn::Load(d, buffer[3 + e]);
  const V t0 = hn::Load(d, buffer[6]), dt = hn::Load(d, buffer[7]), steps = hn::Load(d, buffer[8]);
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0f), half = hn::Set(d, 0.5f);
  V radiance[C], transmittance[C];
  for (int c = 0; c < C; ++c) radiance[c] = zero, transmittance[c] = one;
  const int stride[3] = {1, v.n[0], v.n[0] * v.n[1]};
  const size_t cells = static_cast<size_t>(v.n[0]) * static_cast<size_t>(v.n[1]) * static_cast<size_t>(v.n[2]);  // a source plane's
  const int depth_stride = v.depth_stride > 0 ? v.depth_stride : v.light_count;
  // Grey extinction: one exponential for all channels.
  const float depth_0 = v.sigma_t[0] * v.depth_scale[0];
  const bool grey_steps = v.sigma_t[1] == v.sigma_t[0] && v.sigma_t[2] == v.sigma_t[0];
  const bool grey_depths = v.sigma_t[1] * v.depth_scale[1] == depth_0 && v.sigma_t[2] * v.depth_scale[2] == depth_0;
  float max_steps = 0.0f;
  for (size_t m = 0; m < lanes; ++m) max_steps = std::max(max_steps, buffer[8][m]);
  for (int s = 0; s < static_cast<int>(max_steps); ++s) {
    auto active = hn::Lt(hn::Set(d, static_cast<float>(s)), steps);
    const V t = hn::MulAdd(hn::Add(hn::Set(d, static_cast<float>(s)), half), dt, t0);
    // Trilinear stencil on the cell-centred grid, clamped to the edge cells.
    V x[3], frac[3];
    VI lo[3], hi[3];
    V u[3];  // the point in cells, 0 at the first cell's centre
    for (int e = 0; e < 3; ++e) {
      x[e] = hn::MulAdd(t, dir[e], o[e]);
      u[e] = hn::Sub(hn::Mul(hn::Sub(x[e], hn::Set(d, v.lo[e])), hn::Set(d, 1.0f / v.h[e])), half);
      const V fl = hn::Floor(u[e]);
      frac[e] = hn::Sub(u[e], fl);
      const VI c = hn::ConvertTo(di, fl), last_cell = hn::Set(di, v.n[e] - 1);
      lo[e] = hn::Mul(hn::Min(hn::Max(c, hn::Zero(di)), last_cell), hn::Set(di, stride[e]));
      hi[e] = hn::Mul(hn::Min(hn::Max(hn::Add(c, hn::Set(di, 1)), hn::Zero(di)), last_cell), hn::Set(di, stride[e]));
    }
    VI offset[8];
    V weight[8];
    for (int m = 0; m < 8; ++m) {
      const bool bx = m & 1, by = (m >> 1) & 1, bz = (m >> 2) & 1;
      offset[m] = hn::Add(bx ? hi[0] : lo[0], hn::Add(by ? hi[1] : lo[1], bz ? hi[2] : lo[2]));
      weight[m] = hn::Mul(bx ? frac[0] : hn::Sub(one, frac[0]),
                          hn::Mul(by ? frac[1] : hn::Sub(one, frac[1]), bz ? frac[2] : hn::Sub(one, frac[2])));
    }
    // The density, trilinear: on vector targets each (y, z) corner's two x neighbours as one pair
    // from p = clamp(i, 0, n - 2) (lo and hi, clamped at the faces, are p or p + 1), else eight
    // gathers.
#if HWY_TARGET != HWY_SCALAR
    const bool pairs = v.n[0] >= 2;
    VI pair_at[4];
    V yz[4], w_first = zero, w_second = zero;
    if (pairs) {
      const VI pair = hn::Min(hn::Max(hn::ConvertTo(di, hn::Floor(u[0])), hn::Zero(di)), hn::Set(di, v.n[0] - 2));
      w_first = hn::Add(hn::IfThenElseZero(hn::RebindMask(d, hn::Eq(lo[0], pair)), hn::Sub(one, frac[0])),
                        hn::IfThenElseZero(hn::RebindMask(d, hn::Eq(hi[0], pair)), frac[0]));
      w_second = hn::Sub(one, w_first);
      for (int m = 0; m < 8; m += 2) {
        pair_at[m / 2] = hn::Add(pair, hn::Sub(offset[m], lo[0]));
        yz[m / 2] = hn::Add(weight[m], weight[m + 1]);  // the corner's y and z weights (its x weights sum to 1)
      }
    }
#endif
    const auto trilinear = [&](const float* HWY_RESTRICT field) {
      V sum = zero;
#if HWY_TARGET != HWY_SCALAR
      if (pairs) {
        for (int e = 0; e < 4; ++e) {
          V a, b;
          GatherPairs(d, field, pair_at[e], a, b);
          sum = hn::MulAdd(yz[e], hn::MulAdd(w_second, b, hn::Mul(w_first, a)), sum);
        }
        return sum;
      }
#endif
      for (int m = 0; m < 8; ++m) sum = hn::MulAdd(weight[m], hn::GatherIndex(d, field, offset[m]), sum);
      return sum;
    };
    const V rho = trilinear(v.density);
    active = hn::And(active, hn::Gt(rho, zero));
    if (hn::AllFalse(d, active)) continue;
    V in[C], step_transmittance_0 = one;
    for (int c = 0; c < C; ++c) in[c] = zero;
    // The lights' depths and the source: the density's stencil, or with v.outer one that keeps the
    // slope into the outer half cells, per axis the cells p = clamp(floor(u), 0,
    // n - 2) and p + 1 weighted by u - p unclamped (an axis of one cell: that cell).
    VI o_offset[8];
    V o_weight[8], o_x = zero;  // the outer stencil's x weight of cell p + 1
    if (v.outer) {
      VI p[3];
      V a[3];
      for (int e = 0; e < 3; ++e) {
        const bool two = v.n[e] >= 2;
        p[e] = two ? hn::Min(hn::Max(hn::ConvertTo(di, hn::Floor(u[e])), hn::Zero(di)), hn::Set(di, v.n[e] - 2)) : hn::Zero(di);
        a[e] = two ? hn::Sub(u[e], hn::ConvertTo(d, p[e])) : zero;
      }
      for (int m = 0; m < 8; ++m) {
        VI at = hn::Zero(di);
        V w = one;
        for (int e = 0; e < 3; ++e) {
          const bool bit = (m >> e) & 1;
          at = hn::Add(at, hn::Mul(bit && v.n[e] >= 2 ? hn::Add(p[e], hn::Set(di, 1)) : p[e], hn::Set(di, stride[e])));
          w = hn::Mul(w, bit ? a[e] : hn::Sub(one, a[e]));
        }
        o_offset[m] = at, o_weight[m] = w;
      }
      o_x = a[0];
    }
    const VI* f_offset = v.outer ? o_offset : offset;
    const V* f_weight = v.outer ? o_weight : weight;
#if HWY_TARGET != HWY_SCALAR
    // The source's stencil in x pairs (pairs: x cells p and p + 1 on two cells or more): pair
    // offsets, y-z weights, x weights.
    VI s_pair_at[4];
    V s_yz[4], s_first = w_first, s_second = w_second;
    if (pairs && v.source && v.outer) {
      for (int e = 0; e < 4; ++e) s_pair_at[e] = o_offset[2 * e], s_yz[e] = hn::Add(o_weight[2 * e], o_weight[2 * e + 1]);
      s_first = hn::Sub(one, o_x), s_second = o_x;
    } else if (pairs && v.source) {
      for (int e = 0; e < 4; ++e) s_pair_at[e] = pair_at[e], s_yz[e] = yz[e];
    }
#endif
    // The corners' offsets into the per-light volumes ([cell * depth_stride + slot]).
    VI light_offset[8];
    for (int m = 0; m < 8 && v.light_count > 0; ++m) light_offset[m] = hn::Mul(f_offset[m], hn::Set(di, depth_stride));
    V next_depth = zero;  // light l + 1's, gathered with light l's
    bool paired = false;  // next_depth holds light l's
    for (int l = 0; l < v.light_count; ++l) {
      const MarchLight& light = v.lights[l];
      V depth = zero;
#if HWY_TARGET != HWY_SCALAR
      if (paired) {
        depth = next_depth, paired = false;
      } else if (l + 1 < v.light_count && v.lights[l + 1].slot == light.slot + 1) {  // lights l and l + 1 side by side in each cell
        next_depth = zero, paired = true;
        for (int m = 0; m < 8; ++m) {
          V a, b;
          GatherPairs(d, v.depths + light.slot, light_offset[m], a, b);
          depth = hn::MulAdd(f_weight[m], a, depth), next_depth = hn::MulAdd(f_weight[m], b, next_depth);
        }
        next_depth = hn::Max(next_depth, zero);  // the outer stencil may extrapolate below 0
      } else
#endif
      for (int m = 0; m < 8; ++m) depth = hn::MulAdd(f_weight[m], hn::GatherIndex(d, v.depths + light.slot, light_offset[m]), depth);
      depth = hn::Max(depth, zero);
      V visible = one;
      if (v.visibility) {
        visible = zero;
        for (int m = 0; m < 8; ++m)
          visible = hn::MulAdd(weight[m], hn::GatherIndex(d, v.visibility + light.slot, light_offset[m]), visible);
      }
      AddLight<C>(d, v, light, phase, x, dir, depth, visible, grey_depths, in);
    }
    // The source, once for all channels where it has one: in x pairs where the stencil's x cells
    // are p and p + 1 (the density's, or the outer one's on two cells or more).
    V source = zero;
    for (int c = 0; v.source && c < C; ++c) {
      if (c == 0 || v.source_channels > 1) {
        const float* plane = v.source + (v.source_channels > 1 ? static_cast<size_t>(c) * cells : 0);
#if HWY_TARGET != HWY_SCALAR
        if (pairs) {
          source = zero;
          for (int e = 0; e < 4; ++e) {
            V a, b;
            GatherPairs(d, plane, s_pair_at[e], a, b);
            source = hn::MulAdd(s_yz[e], hn::MulAdd(s_second, b, hn::Mul(s_first, a)), source);
          }
        } else
#endif
        {
          source = zero;
          for (int m = 0; m < 8; ++m) source = hn::MulAdd(f_weight[m], hn::GatherIndex(d, plane, f_offset[m]), source);
        }
        source = hn::Max(source, zero);
      }
      in[c] = hn::Add(in[c], source);
    }
    // The lights folded in toward the eye: on the ghosted grid, cells floor(u) + 1 and + 2 per axis
    // at the density's weights (clamped only for lanes past their steps: u is in [-0.5, n - 0.5]
    // inside the bounds).
    if (v.folded) {
      const hn::RebindToUnsigned<D> du;
      constexpr int kWords = (C + 1) / 2;
      const int gx = v.n[0] + 2, gxy = gx * (v.n[1] + 2);
      VI g[3];
      for (int e = 0; e < 3; ++e) g[e] = hn::Min(hn::Max(hn::Add(hn::ConvertTo(di, hn::Floor(u[e])), hn::Set(di, 1)), hn::Zero(di)), hn::Set(di, v.n[e]));
      const VI base = hn::Mul(hn::Add(g[0], hn::Add(hn::Mul(g[1], hn::Set(di, gx)), hn::Mul(g[2], hn::Set(di, gxy)))), hn::Set(di, kWords));
      for (int c = 0; c < C; ++c) {
        V folded = zero;
        for (int m = 0; m < 8; ++m) {
          const VI at = hn::Add(base, hn::Set(di, ((m & 1) + ((m >> 1) & 1) * gx + ((m >> 2) & 1) * gxy) * kWords + c / 2));
          const auto word = hn::GatherIndex(du, v.folded, at);
          folded = hn::MulAdd(hn::Mul(weight[m], hn::Set(d, kHalfUnit)), c % 2 ? HalfBits<1>(d, word) : HalfBits<0>(d, word), folded);
        }
        in[c] = hn::Add(in[c], hn::Max(hn::Mul(folded, hn::Set(d, v.folded_scale[c])), zero));
      }
    }
    for (int c = 0; c < C; ++c) {
      const V step_transmittance = c > 0 && grey_steps ? step_transmittance_0 : hn::Exp(d, hn::Mul(hn::Set(d, -v.sigma_t[c]), hn::Mul(rho, dt)));
      if (c == 0) step_transmittance_0 = step_transmittance;
      const V scattered = hn::Mul(hn::Mul(transmittance[c], hn::Set(d, v.albedo[c])), hn::Mul(hn::Sub(one, step_transmittance), in[c]));
      radiance[c] = hn::Add(radiance[c], hn::IfThenElseZero(active, scattered));
      transmittance[c] = hn::IfThenElse(active, hn::Mul(transmittance[c], step_transmittance), transmittance[c]);
    }
  }
  for (int c = 0; c < C; ++c) {
    hn::Store(radiance[c], d, radiance_out + c * lanes);
    hn::Store(transmittance[c], d, transmittance_out + c * lanes);
  }
}

#if HWY_TARGET != HWY_SCALAR
// MarchVector where every light is folded in toward the eye and none stays in the steps: the
// density and L_in from the folded cells alone (MarchVolume::folded: a cell's C + 1 float16
// values in one 64-bit word, or 32 where grey), one stencil on the ghosted grid, each (y, z)
// corner's two x cells read as 64-bit gathers, u stepped from the vector's start; the vector
// ends where every lane's transmittance is below 1e-4.
template <int C, class D>
HWY_INLINE void MarchFoldedVector(D d, const MarchVolume& v, const RayPacket& rays, size_t first, size_t last, float* HWY_RESTRICT radiance_out,
                                  float* HWY_RESTRICT transmittance_out) {
  using V = hn::Vec<D>;
  const hn::RebindToSigned<D> di;
  using VI = hn::Vec<decltype(di)>;
  const size_t lanes = hn::Lanes(d);
  HWY_ALIGN float buffer[9][hn::MaxLanes(d)];
  LoadRays(rays, first, last, lanes, buffer);
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0f), half = hn::Set(d, 0.5f);
  const V t0 = hn::Load(d, buffer[6]), dt = hn::Load(d, buffer[7]), steps = hn::Load(d, buffer[8]);
  // u(s) = u_start + s du: the point in cells (0 at the first cell's centre) at step s's midpoint.
  V u_start[3], du[3];
  for (int e = 0; e < 3; ++e) {
    const V o = hn::Load(d, buffer[e]), dir = hn::Load(d, buffer[3 + e]), inv_h = hn::Set(d, 1.0f / v.h[e]);
    u_start[e] = hn::Sub(hn::Mul(hn::Sub(hn::MulAdd(hn::MulAdd(half, dt, t0), dir, o), hn::Set(d, v.lo[e])), inv_h), half);
    du[e] = hn::Mul(hn::Mul(dt, dir), inv_h);
  }
  constexpr int kWords = (C + 1) / 2;  // a cell's: its C + 1 float16 values, the channels then the density
  constexpr float kSpent = 1e-4f;
  const int gx = v.n[0] + 2, gxy = gx * (v.n[1] + 2);
  const bool grey_steps = v.sigma_t[1] == v.sigma_t[0] && v.sigma_t[2] == v.sigma_t[0];
  V radiance[C], transmittance[C];
  for (int c = 0; c < C; ++c) radiance[c] = zero, transmittance[c] = one;
  float max_steps = 0.0f;
  for (size_t m = 0; m < lanes; ++m) max_steps = std::max(max_steps, buffer[8][m]);
  const VI last_cell[3] = {hn::Set(di, v.n[0]), hn::Set(di, v.n[1]), hn::Set(di, v.n[2])};
  for (int s = 0; s < static_cast<int>(max_steps); ++s) {
    auto active = hn::Lt(hn::Set(d, static_cast<float>(s)), steps);
    // Cells floor(u) + 1 and + 2 of the ghosted grid per axis (clamped only for lanes past their steps).
    V frac[3];
    VI g[3];
    for (int e = 0; e < 3; ++e) {
      const V u = hn::MulAdd(hn::Set(d, static_cast<float>(s)), du[e], u_start[e]), fl = hn::Floor(u);
      frac[e] = hn::Sub(u, fl);
      g[e] = hn::Min(hn::Max(hn::Add(hn::ConvertTo(di, fl), hn::Set(di, 1)), hn::Zero(di)), last_cell[e]);
    }
    const VI base = hn::Mul(hn::Add(g[0], hn::Add(hn::Mul(g[1], hn::Set(di, gx)), hn::Mul(g[2], hn::Set(di, gxy)))), hn::Set(di, kWords));
    const V y0 = hn::Sub(one, frac[1]), z0 = hn::Sub(one, frac[2]), x0 = hn::Sub(one, frac[0]);
    const V yz[4] = {hn::Mul(y0, z0), hn::Mul(frac[1], z0), hn::Mul(y0, frac[2]), hn::Mul(frac[1], frac[2])};
    const hn::RebindToUnsigned<D> du;
    V value[C + 1];  // trilinear, times 2^-112: the channels, then the density
    for (int k = 0; k <= C; ++k) value[k] = zero;
    for (int e = 0; e < 4; ++e) {
      const PairOffsets<D> at = PairOffsetsOf(d, hn::Add(base, hn::Set(di, ((e & 1) * gx + (e >> 1) * gxy) * kWords)));
      const V w0 = hn::Mul(yz[e], hn::Mul(x0, hn::Set(d, kHalfUnit))), w1 = hn::Mul(yz[e], hn::Mul(frac[0], hn::Set(d, kHalfUnit)));
      const float* words = reinterpret_cast<const float*>(v.folded);  // read as 8-byte lanes, bits kept
      V a, b, a1, b1;
      if constexpr (kWords == 1) {  // cells x and x + 1 side by side: [channel 0 | density] each
        GatherPairsAt(d, words, at, a, a1);
        b = a, b1 = a1;
      } else {  // a cell's two words: [channel 0 | channel 1], [channel 2 | density]
        GatherPairsAt(d, words, at, a, b);
        GatherPairsAt(d, words + 2, at, a1, b1);
      }
      const auto wa = hn::BitCast(du, a), wb = hn::BitCast(du, b), wa1 = hn::BitCast(du, a1), wb1 = hn::BitCast(du, b1);
      value[0] = hn::MulAdd(w1, HalfBits<0>(d, wa1), hn::MulAdd(w0, HalfBits<0>(d, wa), value[0]));
      if constexpr (C == 3) {
        value[1] = hn::MulAdd(w1, HalfBits<1>(d, wa1), hn::MulAdd(w0, HalfBits<1>(d, wa), value[1]));
        value[2] = hn::MulAdd(w1, HalfBits<0>(d, wb1), hn::MulAdd(w0, HalfBits<0>(d, wb), value[2]));
      }
      value[C] = hn::MulAdd(w1, HalfBits<1>(d, wb1), hn::MulAdd(w0, HalfBits<1>(d, wb), value[C]));
    }
    for (int k = 0; k < C; ++k) value[k] = hn::Mul(value[k], hn::Set(d, v.folded_scale[k]));
    value[C] = hn::Mul(value[C], hn::Set(d, v.folded_scale[3]));
    const V rho = value[C];
    active = hn::And(active, hn::Gt(rho, zero));
    if (hn::AllFalse(d, active)) continue;
    // Every lane's light spent (T below kSpent in every channel): what the rest would add is at
    // most kSpent of its light unattenuated.
    V most = transmittance[0];
    for (int c = 1; c < C; ++c) most = hn::Max(most, transmittance[c]);
    if (hn::AllTrue(d, hn::Lt(most, hn::Set(d, kSpent)))) break;
    V step_transmittance_0 = one;
    for (int c = 0; c < C; ++c) {
      const V step_transmittance = c > 0 && grey_steps ? step_transmittance_0 : hn::Exp(d, hn::Mul(hn::Set(d, -v.sigma_t[c]), hn::Mul(rho, dt)));
      if (c == 0) step_transmittance_0 = step_transmittance;
      const V scattered = hn::Mul(hn::Mul(transmittance[c], hn::Set(d, v.albedo[c])), hn::Mul(hn::Sub(one, step_transmittance), hn::Max(value[c], zero)));
      radiance[c] = hn::Add(radiance[c], hn::IfThenElseZero(active, scattered));
      transmittance[c] = hn::IfThenElse(active, hn::Mul(transmittance[c], step_transmittance), transmittance[c]);
    }
  }
  for (int c = 0; c < C; ++c) {
    hn::Store(radiance[c], d, radiance_out + c * lanes);
    hn::Store(transmittance[c], d, transmittance_out + c * lanes);
  }
}
#endif

// march_row_packet's lanes: pixels [x0, x0 + lanes) (the caller pads the rows to whole vectors).
HWY_NOINLINE void RowPacket(const RowFrame& r, float* HWY_RESTRICT rows, size_t stride, size_t count) {
  const hn::ScalableTag<float> d;
  using V = hn::Vec<decltype(d)>;
  const size_t lanes = hn::Lanes(d);
  float* HWY_RESTRICT origin[3] = {rows, rows + stride, rows + 2 * stride};
  float* HWY_RESTRICT direction[3] = {rows + 3 * stride, rows + 4 * stride, rows + 5 * stride};
  float* HWY_RESTRICT t0 = rows + 6 * stride;
  float* HWY_RESTRICT dt = rows + 7 * stride;
  float* HWY_RESTRICT steps = rows + 8 * stride;
  const V zero = hn::Zero(d), step = hn::Set(d, r.step), tiny = hn::Set(d, 1e-30f);
  for (size_t x0 = 0; x0 < count; x0 += lanes) {
    const V px = r.film ? hn::LoadU(d, r.film + x0) : hn::Add(hn::ConvertTo(d, hn::Iota(hn::RebindToSigned<decltype(d)>(), static_cast<int>(x0))), hn::Set(d, 0.5f));
    V w[3];
    for (int e = 0; e < 3; ++e) w[e] = hn::MulAdd(hn::Set(d, r.b[e]), px, hn::Set(d, r.a[e]));
    const V inv_length = hn::Div(hn::Set(d, 1.0f), hn::Sqrt(hn::MulAdd(w[0], w[0], hn::MulAdd(w[1], w[1], hn::Mul(w[2], w[2])))));
    // The slabs (a zero component taken as 1e-30 of its sign: its planes at +-inf, never NaN).
    V near = zero, far = hn::Set(d, 3.0e38f);
    for (int e = 0; e < 3; ++e) {
      w[e] = hn::Mul(w[e], inv_length);
      const V safe = hn::IfThenElse(hn::Lt(hn::Abs(w[e]), tiny), hn::CopySign(tiny, w[e]), w[e]);
      const V inv = hn::Div(hn::Set(d, 1.0f), safe);
      const V a = hn::Mul(hn::Sub(hn::Set(d, r.lo[e]), hn::Set(d, r.eye[e])), inv), b = hn::Mul(hn::Sub(hn::Set(d, r.hi[e]), hn::Set(d, r.eye[e])), inv);
      near = hn::Max(near, hn::Min(a, b)), far = hn::Min(far, hn::Max(a, b));
      hn::StoreU(w[e], d, direction[e] + x0);
      hn::StoreU(hn::Set(d, r.eye[e]), d, origin[e] + x0);
    }
    if (r.depth) far = hn::Min(far, hn::LoadU(d, r.depth + x0));
    const auto inside = hn::Gt(far, near);
    const V n = hn::IfThenElseZero(inside, hn::Max(hn::Ceil(hn::Div(hn::Sub(far, near), step)), hn::Set(d, 1.0f)));
    hn::StoreU(hn::IfThenElseZero(inside, near), d, t0 + x0);
    hn::StoreU(hn::IfThenElseZero(inside, hn::Div(hn::Sub(far, near), hn::Max(n, hn::Set(d, 1.0f)))), d, dt + x0);
    hn::StoreU(n, d, steps + x0);
  }
}

HWY_NOINLINE void InterleaveRgb(const float* HWY_RESTRICT r, const float* HWY_RESTRICT g, const float* HWY_RESTRICT b, size_t count,
                                float* HWY_RESTRICT out) {
  const hn::ScalableTag<float> d;
  const size_t lanes = hn::Lanes(d);
  size_t x = 0;
  for (; x + lanes <= count; x += lanes) hn::StoreInterleaved3(hn::LoadU(d, r + x), hn::LoadU(d, g + x), hn::LoadU(d, b + x), d, out + 3 * x);
  for (; x < count; ++x) out[3 * x] = r[x], out[3 * x + 1] = g[x], out[3 * x + 2] = b[x];
}

template <int C>
HWY_INLINE void MarchAll(const MarchVolume& v, const simd::PhaseParams& phase, const RayPacket& rays) {
  const hn::ScalableTag<float> d;
  const size_t lanes = hn::Lanes(d);
  HWY_ALIGN float radiance[3 * hn::MaxLanes(d)], transmittance[3 * hn::MaxLanes(d)];
#if HWY_TARGET != HWY_SCALAR
  const bool folded = v.folded && v.light_count == 0 && !v.source;
#endif
  for (size_t first = 0; first < rays.count; first += lanes) {
#if HWY_TARGET != HWY_SCALAR
    if (folded) MarchFoldedVector<C>(d, v, rays, first, rays.count - 1, radiance, transmittance);
    else
#endif
    MarchVector<C>(d, v, phase, rays, first, rays.count - 1, radiance, transmittance);
    const size_t n = std::min(lanes, rays.count - first);
    for (int c = 0; c < C; ++c) {
      std::copy(radiance + c * lanes, radiance + c * lanes + n, rays.radiance[c] + first);
      std::copy(transmittance + c * lanes, transmittance + c * lanes + n, rays.transmittance[c] + first);
    }
  }
}

HWY_NOINLINE void MarchRays(const MarchVolume& v, const simd::PhaseParams& phase, const RayPacket& rays) {
  if (v.channels == 1) {
    MarchAll<1>(v, phase, rays);
  } else {
    MarchAll<3>(v, phase, rays);
  }
}

}  // namespace haze::grids::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HAZE_GRIDS_MARCH_RAYS_INL_H_
