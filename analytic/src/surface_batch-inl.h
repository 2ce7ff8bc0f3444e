// Per-target surface shading kernel (Highway: included once per target by foreach_target.h).
#if defined(HAZE_ANALYTIC_SURFACE_BATCH_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_ANALYTIC_SURFACE_BATCH_INL_H_
#undef HAZE_ANALYTIC_SURFACE_BATCH_INL_H_
#else
#define HAZE_ANALYTIC_SURFACE_BATCH_INL_H_
#endif

#include <haze/analytic/surface_batch.h>

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

#include <cmath>

HWY_BEFORE_NAMESPACE();
namespace haze::analytic::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// J(T, angle) of a SurfaceAirlightTable (its eval): bilinear in m = T / (1 + T) and angle / pi
// over (1 + T) J, T fastest.
template <class D, class V>
HWY_INLINE V EvalJ(D d, const float* HWY_RESTRICT j, int nt, int na, V T, V angle) {
  const hn::RebindToSigned<D> di;
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0f);
  const V one_plus = hn::Add(one, T);
  const V fi = hn::Mul(hn::Min(hn::Max(hn::Div(T, one_plus), zero), one), hn::Set(d, static_cast<float>(nt - 1)));
  const V fk = hn::Mul(hn::Min(hn::Max(hn::Mul(angle, hn::Set(d, static_cast<float>(1.0 / kPi))), zero), one), hn::Set(d, static_cast<float>(na - 1)));
  const V i = hn::Min(hn::Floor(fi), hn::Set(d, static_cast<float>(nt - 2))), k = hn::Min(hn::Floor(fk), hn::Set(d, static_cast<float>(na - 2)));
  const V x = hn::Sub(fi, i), y = hn::Sub(fk, k);
  const auto index = hn::ConvertTo(di, hn::MulAdd(k, hn::Set(d, static_cast<float>(nt)), i));
  const V a00 = hn::GatherIndex(d, j, index), a10 = hn::GatherIndex(d, j + 1, index);
  const V a01 = hn::GatherIndex(d, j + nt, index), a11 = hn::GatherIndex(d, j + nt + 1, index);
  const V a0 = hn::MulAdd(x, hn::Sub(a10, a00), a00), a1 = hn::MulAdd(x, hn::Sub(a11, a01), a01);
  return hn::Div(hn::MulAdd(y, hn::Sub(a1, a0), a0), one_plus);
}

// x^n for x >= 0 (0 at 0).
template <class D, class V>
HWY_INLINE V PowPositive(D d, V x, float n) {
  const auto positive = hn::Gt(x, hn::Zero(d));
  return hn::IfThenElseZero(positive, hn::Exp(d, hn::Mul(hn::Set(d, n), hn::Log(d, hn::Max(x, hn::Set(d, 1e-30f))))));
}

HWY_NOINLINE void ShadePoints(const ShadingMedium& medium, const ShadingMaterial& material, const ShadingLight* lights, size_t light_count,
                              const ShadingPoints& pts, float* HWY_RESTRICT radiance) {
  const hn::ScalableTag<float> d;
  using V = hn::Vec<decltype(d)>;
  const size_t lanes = hn::Lanes(d);
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0f);
  const bool grey = medium.sigma_t[0] == medium.sigma_t[1] && medium.sigma_t[1] == medium.sigma_t[2];
  const bool phong = material.ks[0] != 0.0f || material.ks[1] != 0.0f || material.ks[2] != 0.0f;
  const float phong_norm = (material.shininess + 2.0f) / (2.0f * static_cast<float>(kPi));
  const float* const lambert = material.lambert ? material.lambert->values().data() : nullptr;
  const float* const phong_j = material.phong ? material.phong->values().data() : nullptr;
  const int l_nt = material.lambert ? material.lambert->t_samples() : 0, l_na = material.lambert ? material.lambert->angle_samples() : 0;
  const int p_nt = material.phong ? material.phong->t_samples() : 0, p_na = material.phong ? material.phong->angle_samples() : 0;
  bool bounded[3];
  for (int e = 0; e < 3; ++e) bounded[e] = !(std::isinf(medium.lo[e]) && std::isinf(medium.hi[e]));
  HWY_ALIGN float tail[3 * HWY_MAX_BYTES / sizeof(float)];
  for (size_t i = 0; i < pts.count; i += lanes) {
    V p[3], n[3], v[3];
    for (int e = 0; e < 3; ++e) p[e] = hn::LoadU(d, pts.p[e] + i), n[e] = hn::LoadU(d, pts.n[e] + i), v[e] = hn::LoadU(d, pts.v[e] + i);
    const auto in_medium = hn::Gt(hn::LoadU(d, pts.in_medium + i), zero);
    // R, the view mirrored about the normal, and max(0, n . R).
    const V vn = hn::MulAdd(v[0], n[0], hn::MulAdd(v[1], n[1], hn::Mul(v[2], n[2])));
    V r[3];
    for (int e = 0; e < 3; ++e) r[e] = hn::NegMulAdd(hn::Add(vn, vn), n[e], v[e]);
    const V cos_r = hn::Max(zero, hn::MulAdd(n[0], r[0], hn::MulAdd(n[1], r[1], hn::Mul(n[2], r[2]))));
    V out[3] = {zero, zero, zero};
    for (size_t l = 0; l < light_count; ++l) {
      const ShadingLight& light = lights[l];
      V wi[3];
      for (int e = 0; e < 3; ++e) wi[e] = hn::Sub(hn::Set(d, light.position[e]), p[e]);
      const V d2 = hn::MulAdd(wi[0], wi[0], hn::MulAdd(wi[1], wi[1], hn::Mul(wi[2], wi[2])));
      const V dist = hn::Sqrt(d2), inv = hn::Div(one, dist);
      for (int e = 0; e < 3; ++e) wi[e] = hn::Mul(wi[e], inv);
      const V cos_i = hn::MulAdd(n[0], wi[0], hn::MulAdd(n[1], wi[1], hn::Mul(n[2], wi[2])));
      // Direct (eq. 4.10): f I / d^2 cos_i e^(-sigma_t d_in), d_in the path inside the box.
      const auto lit = hn::And(hn::Gt(cos_i, zero), hn::Gt(hn::LoadU(d, light.visible + i), zero));
      if (!hn::AllFalse(d, lit)) {
        V s0 = zero, s1 = dist;  // the light's path p + s wi inside the box
        for (int e = 0; e < 3; ++e) {
          if (!bounded[e]) continue;
          const V inv_w = hn::Div(one, wi[e]);
          const V a = hn::Mul(hn::Sub(hn::Set(d, static_cast<float>(medium.lo[e])), p[e]), inv_w);
          const V b = hn::Mul(hn::Sub(hn::Set(d, static_cast<float>(medium.hi[e])), p[e]), inv_w);
          s0 = hn::Max(s0, hn::Min(a, b)), s1 = hn::Min(s1, hn::Max(a, b));
        }
        const V inside = hn::Max(zero, hn::Sub(s1, s0));
        V specular = zero;
        if (phong) {
          // wo = -v; the light's mirror 2 cos_i n - wi.
          V cos_alpha = zero;
          for (int e = 0; e < 3; ++e) cos_alpha = hn::NegMulAdd(hn::MulSub(hn::Add(cos_i, cos_i), n[e], wi[e]), v[e], cos_alpha);
          specular = hn::Mul(hn::Set(d, phong_norm), PowPositive(d, cos_alpha, material.shininess));
        }
        const V scale = hn::IfThenElseZero(lit, hn::Div(cos_i, d2));
        V t_in = zero;
        for (int c = 0; c < 3; ++c) {
          if (c == 0 || !grey) t_in = hn::Exp(d, hn::Mul(hn::Set(d, -medium.sigma_t[c]), inside));
          const V f = hn::MulAdd(hn::Set(d, material.ks[c]), specular, hn::Set(d, material.kd[c] / static_cast<float>(kPi)));
          out[c] = hn::MulAdd(hn::Mul(f, hn::Set(d, light.intensity[c])), hn::Mul(scale, t_in), out[c]);
        }
      }
      // The airlight onto the point (eq. 4.15), inside the medium.
      if ((lambert || phong_j) && !hn::AllFalse(d, in_medium)) {
        const V theta_s = hn::Acos(d, hn::Min(hn::Max(cos_i, hn::Set(d, -1.0f)), one));
        const V cos_rl = hn::MulAdd(r[0], wi[0], hn::MulAdd(r[1], wi[1], hn::Mul(r[2], wi[2])));
        const V theta_r = phong_j ? hn::Acos(d, hn::Min(hn::Max(cos_rl, hn::Set(d, -1.0f)), one)) : zero;
        V j_d = zero, j_s = zero, at = zero;
        for (int c = 0; c < 3; ++c) {
          if (c == 0 || !grey) {
            const V T = hn::Mul(hn::Set(d, medium.sigma_t[c]), dist);
            if (lambert) j_d = EvalJ(d, lambert, l_nt, l_na, T, theta_s);
            if (phong_j) j_s = hn::Mul(EvalJ(d, phong_j, p_nt, p_na, T, theta_r), cos_r);
            at = hn::IfThenElseZero(in_medium, hn::Mul(hn::Exp(d, hn::Neg(T)), inv));
          }
          const V j = hn::MulAdd(hn::Set(d, material.kd[c]), j_d, hn::Mul(hn::Set(d, material.ks[c]), j_s));
          out[c] = hn::MulAdd(hn::Mul(hn::Set(d, medium.sigma_s[c] * light.intensity[c]), at), j, out[c]);
        }
      }
    }
    if (i + lanes <= pts.count) {
      hn::StoreInterleaved3(out[0], out[1], out[2], d, radiance + 3 * i);
    } else {
      hn::StoreInterleaved3(out[0], out[1], out[2], d, tail);
      std::copy_n(tail, 3 * (pts.count - i), radiance + 3 * i);
    }
  }
}

}  // namespace haze::analytic::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // HAZE_ANALYTIC_SURFACE_BATCH_INL_H_
