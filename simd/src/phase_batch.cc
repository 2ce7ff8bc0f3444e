// Dispatch and scalar reference for batched phase evaluation (Highway skeleton layout).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "phase_batch.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <haze/simd/phase_batch-inl.h>

#include <hwy/highway.h>

#if HWY_ONCE
#include <haze/core/error.h>
#include <haze/simd/phase_batch.h>

namespace haze::simd {

HWY_EXPORT(EvalPhaseBatch);

namespace {

void set_lobe(PhaseParams& p, int l, double g, double weight) {
  p.k[l] = static_cast<float>(weight * (1.0 - g * g) * kInv4Pi);
  p.a[l] = static_cast<float>((1.0 - std::abs(g)) * (1.0 - std::abs(g)));
  p.b[l] = static_cast<float>(2.0 * std::abs(g));
  p.s[l] = g < 0.0 ? -1.0f : 1.0f;
}

}  // namespace

bool params_for(const PhaseFunction& phase, PhaseParams& p) {
  switch (phase.type()) {
    case PhaseType::isotropic:
      p.c0 = static_cast<float>(kInv4Pi);
      return true;
    case PhaseType::rayleigh:
      p.c0 = p.c2 = static_cast<float>(3.0 / (16.0 * kPi));
      return true;
    case PhaseType::henyey_greenstein:
      p.lobes = 1;
      set_lobe(p, 0, phase.parameters<PhaseFunction::HenyeyGreenstein>()->g, 1.0);
      return true;
    case PhaseType::cornette_shanks: {
      // HG(g) times 3/2 (1 + mu^2) / (2 + g^2).
      double g = phase.parameters<PhaseFunction::CornetteShanks>()->g;
      p.lobes = 1;
      set_lobe(p, 0, g, 1.0);
      p.c0 = p.c2 = static_cast<float>(1.5 / (2.0 + g * g));
      return true;
    }
    case PhaseType::double_hg: {
      const auto* m = phase.parameters<PhaseFunction::DoubleHg>();
      p.lobes = 2;
      set_lobe(p, 0, m->g1, m->w);
      set_lobe(p, 1, m->g2, 1.0 - m->w);
      return true;
    }
    case PhaseType::tabulated:
      return false;
  }
  return false;
}

void eval_phase_reference(const PhaseFunction& phase, const float* cos_theta, float* out, size_t count) {
  for (size_t i = 0; i < count; ++i) out[i] = static_cast<float>(phase.eval(static_cast<double>(cos_theta[i])));
}

void eval_phase(const PhaseFunction& phase, const float* cos_theta, float* out, size_t count) {
  PhaseParams p;
  if (!params_for(phase, p)) return eval_phase_reference(phase, cos_theta, out, count);
  HWY_DYNAMIC_DISPATCH(EvalPhaseBatch)(p, cos_theta, out, count);
}

std::vector<std::string> available_targets() {
  std::vector<std::string> names;
  for (int64_t t : hwy::SupportedAndGeneratedTargets()) names.emplace_back(hwy::TargetName(t));
  return names;
}

std::string selected_target() {
  auto targets = hwy::SupportedAndGeneratedTargets();
  return targets.empty() ? "none" : hwy::TargetName(targets.front());
}

}  // namespace haze::simd
#endif  // HWY_ONCE
