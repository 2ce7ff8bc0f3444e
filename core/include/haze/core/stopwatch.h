// Wall-clock timing for the figures methods report in their stats.
#pragma once

#include <chrono>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  // Seconds since construction or the last restart().
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  void restart() { start_ = std::chrono::steady_clock::now(); }
  // seconds(), then restart(): the time of one stage of several.
  double lap() {
    const double s = seconds();
    restart();
    return s;
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace haze

#pragma GCC visibility pop
