#include <haze/core/error.h>
#include <haze/core/progress.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace haze {

ProgressTracker::ProgressTracker(ProgressCallback callback, long long total)
    : callback_(std::move(callback)), total_(std::max(1LL, total)) {}

bool ProgressTracker::advance(long long items) {
  long long done = done_.fetch_add(items, std::memory_order_relaxed) + items;
  if (!callback_ || cancelled()) return !cancelled();
  double fraction = std::min(1.0, static_cast<double>(done) / static_cast<double>(total_));
  std::lock_guard lock(mutex_);
  // Report at most every 0.1% so a callback on a terminal stays cheap.
  if (fraction - last_reported_ < 1e-3 && fraction < 1.0) return true;
  last_reported_ = fraction;
  if (!callback_(fraction)) cancelled_.store(true, std::memory_order_relaxed);
  return !cancelled();
}

void ProgressTracker::throw_if_cancelled() const {
  if (cancelled()) throw Cancelled();
}

void parallel_for(long long count, int threads, long long grain, const std::function<void(long long, long long)>& body) {
  if (threads < 0) throw Error("threads", to_text(threads), "0 (all cores) or a positive cap");
  if (count <= 0) return;
  grain = std::max(1LL, grain);
  long long chunks = (count + grain - 1) / grain;
  if (chunks == 1 || threads == 1) {  // no arena to set up for work one thread does anyway
    for (long long c = 0; c < chunks; ++c) body(c * grain, std::min(count, (c + 1) * grain));
    return;
  }
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<long long>(0, chunks, 1), [&](const tbb::blocked_range<long long>& r) {
      for (long long c = r.begin(); c != r.end(); ++c) body(c * grain, std::min(count, (c + 1) * grain));
    }, tbb::simple_partitioner());
  });
}

}  // namespace haze
