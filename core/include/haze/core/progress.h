// Progress reporting and cancellation for long work, and the thread-count cap.
#pragma once

#include <atomic>
#include <functional>
#include <mutex>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

// Called with the finished fraction in [0, 1]; return false to cancel. Calls are serialized but
// may come from any worker thread.
using ProgressCallback = std::function<bool(double fraction)>;

// Counts finished work items from many threads and forwards the fraction to a callback.
class ProgressTracker {
 public:
  ProgressTracker(ProgressCallback callback, long long total);
  // Adds finished items; returns false once cancelled (workers should stop early).
  bool advance(long long items = 1);
  bool cancelled() const { return cancelled_.load(std::memory_order_relaxed); }
  // Throws haze::Cancelled if the callback asked to stop.
  void throw_if_cancelled() const;

 private:
  ProgressCallback callback_;
  long long total_;
  std::atomic<long long> done_{0};
  std::atomic<bool> cancelled_{false};
  std::mutex mutex_;
  double last_reported_ = -1.0;
};

// Runs body(begin, end) over [0, count) in chunks of `grain` on oneTBB, capped at `threads`
// (0: no cap). Chunk boundaries do not depend on the thread count, so neither do results.
void parallel_for(long long count, int threads, long long grain, const std::function<void(long long, long long)>& body);

}  // namespace haze

#pragma GCC visibility pop
