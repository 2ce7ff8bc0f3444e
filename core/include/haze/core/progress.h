// Progress reporting and cancellation for long work, the thread-count cap and the memory budget.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <mutex>
#include <string>

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

// The bytes one computation may allocate: the system's available memory (MemAvailable), or `cap`
// (RenderOptions::max_memory) when that is set and smaller.
std::size_t memory_budget(std::size_t cap = 0);
// Before allocating memory in proportion to the input: throws haze::Error naming `field` when
// `bytes` exceed memory_budget(cap); `what` says what they hold, `fewer` what would need less.
void check_memory(std::size_t bytes, std::size_t cap, const std::string& field, const std::string& what, const std::string& fewer);

}  // namespace haze

#pragma GCC visibility pop
