// --timeout for long commands: the work is cancelled at its first progress report past the
// deadline (haze::Cancelled, which the command reports as a --timeout error); work that reports
// no progress by then is stopped a grace period later by ending the process with exit code 2.
#pragma once

#include <haze/core/progress.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace haze::app {

class Deadline {
 public:
  // seconds <= 0: none.
  explicit Deadline(double seconds);
  ~Deadline();
  Deadline(const Deadline&) = delete;
  Deadline& operator=(const Deadline&) = delete;

  bool passed() const;
  double seconds() const { return seconds_; }
  // `inner` (may be empty) that also returns false once the deadline has passed.
  ProgressCallback wrap(ProgressCallback inner) const;

 private:
  double seconds_;
  std::chrono::steady_clock::time_point end_;
  std::mutex mutex_;
  std::condition_variable done_;
  bool finished_ = false;
  std::thread watchdog_;
};

}  // namespace haze::app
