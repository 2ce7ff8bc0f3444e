// Every compiled Highway target against the scalar reference for batched phase evaluation.
#include <haze/simd/phase_batch.h>

#include <gtest/gtest.h>
#include <hwy/tests/hwy_gtest.h>

namespace haze::simd {
namespace {

class PhaseBatch : public hwy::TestWithParamTarget {};
HWY_TARGET_INSTANTIATE_TEST_SUITE_P(PhaseBatch);

TEST_P(PhaseBatch, MatchesScalarReferenceOnEveryTarget) {
  const PhaseFunction phases[] = {PhaseFunction::isotropic(),
                                  PhaseFunction::rayleigh(),
                                  PhaseFunction::henyey_greenstein(0.5),
                                  PhaseFunction::henyey_greenstein(-0.9),
                                  PhaseFunction::henyey_greenstein(0.999),
                                  PhaseFunction::cornette_shanks(0.85),
                                  PhaseFunction::double_hg(0.9, -0.3, 0.6),
                                  PhaseFunction::tabulated({1.0, 2.0, 5.0})};
  // Odd sizes exercise the masked tail; mu includes both ends of [-1, 1].
  for (size_t count : {size_t(1), size_t(7), size_t(33), size_t(1000)}) {
    std::vector<float> mu(count), fast(count), reference(count);
    for (size_t i = 0; i < count; ++i)
      mu[i] = count == 1 ? 1.0f : -1.0f + 2.0f * static_cast<float>(i) / static_cast<float>(count - 1);
    for (const auto& phase : phases) {
      eval_phase(phase, mu.data(), fast.data(), count);
      eval_phase_reference(phase, mu.data(), reference.data(), count);
      for (size_t i = 0; i < count; ++i)
        ASSERT_NEAR(fast[i], reference[i], 8e-7f * reference[i])
            << phase.name() << " g " << phase.mean_cosine() << " mu " << mu[i] << " target " << hwy::TargetName(GetParam());
    }
  }
}

TEST(SimdTargets, SelectedTargetIsAvailable) {
  auto targets = available_targets();
  ASSERT_FALSE(targets.empty());
  EXPECT_EQ(selected_target(), targets.front());
}

}  // namespace
}  // namespace haze::simd
