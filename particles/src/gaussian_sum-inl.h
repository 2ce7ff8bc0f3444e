// Per-target sums of truncated Gaussians (Highway: included once per target by foreach_target.h).
#if defined(HAZE_PARTICLES_GAUSSIAN_SUM_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef HAZE_PARTICLES_GAUSSIAN_SUM_INL_H_
#undef HAZE_PARTICLES_GAUSSIAN_SUM_INL_H_
#else
#define HAZE_PARTICLES_GAUSSIAN_SUM_INL_H_
#endif

#include <haze/particles/gaussian_sum.h>

#include <hwy/contrib/math/math-inl.h>
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace haze::particles::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

inline HWY_NOINLINE float GaussianSum(const GaussianList& g, float px, float py, float pz, float cut2) {
  const hn::CappedTag<float, kGaussianPad> d;  // lanes divide the padded count
  using V = hn::Vec<decltype(d)>;
  const V x = hn::Set(d, px), y = hn::Set(d, py), z = hn::Set(d, pz), cut = hn::Set(d, cut2);
  V sum = hn::Zero(d);
  for (size_t i = 0; i < g.count; i += hn::Lanes(d)) {
    const V dx = hn::Sub(hn::LoadU(d, g.x + i), x), dy = hn::Sub(hn::LoadU(d, g.y + i), y), dz = hn::Sub(hn::LoadU(d, g.z + i), z);
    const V r2 = hn::Mul(hn::MulAdd(dx, dx, hn::MulAdd(dy, dy, hn::Mul(dz, dz))), hn::LoadU(d, g.inv_h2 + i));
    const V term = hn::Mul(hn::LoadU(d, g.w + i), hn::Exp(d, hn::Neg(hn::Min(r2, cut))));
    sum = hn::Add(sum, hn::IfThenElseZero(hn::Lt(r2, cut), term));
  }
  return hn::GetLane(hn::SumOfLanes(d, sum));
}

}  // namespace haze::particles::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#endif  // include guard
