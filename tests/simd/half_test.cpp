// float16 conversion on every compiled Highway target: exact for values float16 holds, within the
// documented error (simd/half.h) for the rest, and Eigen's reference agrees.
#include <haze/core/rng.h>
#include <haze/simd/half.h>

#include <gtest/gtest.h>
#include <hwy/tests/hwy_gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace haze::simd {
namespace {

class HalfConversion : public hwy::TestWithParamTarget {};
HWY_TARGET_INSTANTIATE_TEST_SUITE_P(HalfConversion);

// Every finite float16 bit pattern (both signs, subnormals included) survives
// float16 -> float32 -> float16 with its value (emulated targets turn -0 into +0), and the float32
// value is Eigen's.
TEST_P(HalfConversion, RoundTripsEveryFiniteHalf) {
  std::vector<Half> all;
  for (uint32_t b = 0; b < 0x10000; ++b)
    if ((b & 0x7C00) != 0x7C00) all.push_back(Eigen::numext::bit_cast<Half>(static_cast<uint16_t>(b)));
  std::vector<float> wide(all.size()), expected(all.size());
  to_float(all.data(), wide.data(), all.size());
  to_float_reference(all.data(), expected.data(), all.size());
  std::vector<Half> back(all.size());
  to_half(wide.data(), back.data(), all.size());
  for (size_t i = 0; i < all.size(); ++i) {
    ASSERT_EQ(wide[i], expected[i]) << "bits " << std::hex << all[i].x << " target " << hwy::TargetName(GetParam());
    ASSERT_EQ(static_cast<float>(back[i]), wide[i]) << "value " << wide[i] << " target " << hwy::TargetName(GetParam());
  }
}

// Random float32 values from 1e-9 to 6e4 (odd counts, to cover the tails): relative error below
// 2^-10 where float16 is normal, absolute error below 2^-23 (1.2e-7) where it is subnormal.
TEST_P(HalfConversion, ErrorWithinHalfPrecision) {
  Rng rng(5);
  for (size_t count : {size_t{1}, size_t{7}, size_t{1001}}) {
    std::vector<float> x(count), y(count);
    for (float& e : x) e = static_cast<float>((rng.uniform() < 0.5 ? -1.0 : 1.0) * std::pow(10.0, -9.0 + 13.7 * rng.uniform()));
    std::vector<Half> h(count), r(count);
    to_half(x.data(), h.data(), count);
    to_half_reference(x.data(), r.data(), count);
    to_float(h.data(), y.data(), count);
    for (size_t i = 0; i < count; ++i) {
      const double err = std::abs(static_cast<double>(y[i]) - static_cast<double>(x[i]));
      const double limit = std::abs(x[i]) >= 6.103515625e-5f ? std::ldexp(std::abs(static_cast<double>(x[i])), -10) : std::ldexp(1.0, -23);
      ASSERT_LE(err, limit) << "x " << x[i] << " target " << hwy::TargetName(GetParam());
      ASSERT_LE(std::abs(static_cast<double>(static_cast<float>(r[i])) - static_cast<double>(x[i])), 0.5 * limit + 1e-30) << "reference, x " << x[i];
    }
  }
}

}  // namespace
}  // namespace haze::simd
