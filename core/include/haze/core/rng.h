// A small deterministic random number generator (PCG32, O'Neill 2014). Each pixel or path gets its
// own stream from (seed, index), so results do not depend on the thread count or schedule.
#pragma once

#include <cstdint>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

class Rng {
 public:
  explicit Rng(std::uint64_t seed = 1, std::uint64_t stream = 0) {
    inc_ = (stream << 1u) | 1u;
    state_ = 0;
    next_u32();
    state_ += seed;
    next_u32();
  }
  std::uint32_t next_u32() {
    std::uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
    auto rot = static_cast<std::uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }
  // Uniform in [0, 1) on a grid of 2^-32: one generator step per number, plenty for Monte Carlo.
  double uniform() { return static_cast<double>(next_u32()) * 0x1.0p-32; }

 private:
  std::uint64_t state_ = 0, inc_ = 1;
};

}  // namespace haze

#pragma GCC visibility pop
