#include <haze/core/error.h>
#include <haze/core/progress.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <exception>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#if defined(__SANITIZE_THREAD__)  // GCC
#define HAZE_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)  // clang
#define HAZE_TSAN 1
#endif
#endif

namespace haze {

std::size_t memory_budget(std::size_t cap) {
  std::size_t available = SIZE_MAX;
  std::ifstream in("/proc/meminfo");
  std::string key, unit;
  std::size_t kb = 0;
  while (in >> key >> kb >> unit)
    if (key == "MemAvailable:") {
      available = kb * 1024;
      break;
    }
  if (available == SIZE_MAX) {
    const long pages = sysconf(_SC_AVPHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    if (pages > 0 && page > 0) available = static_cast<std::size_t>(pages) * static_cast<std::size_t>(page);
  }
  return cap > 0 ? std::min(cap, available) : available;
}

void check_memory(std::size_t bytes, std::size_t cap, const std::string& field, const std::string& what, const std::string& fewer) {
  const std::size_t budget = memory_budget(cap);
  if (bytes <= budget) return;
  const std::string limit = cap > 0 && cap <= budget ? " of the memory cap (RenderOptions::max_memory, haze --max-memory)" : " available";
  auto mib = [](std::size_t b) { return to_text(std::round(static_cast<double>(b) / (1 << 20) * 10.0) / 10.0) + " MiB"; };
  throw Error(field, mib(bytes) + " for " + what, "work that fits in the " + mib(budget) + limit + " (" + fewer + ")");
}

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

#ifdef HAZE_TSAN
namespace {
// Under ThreadSanitizer the chunks run on std::threads that take them from an atomic counter:
// TSan does not see the synchronisation inside Debian's uninstrumented TBB and would report its
// hand-offs as races, so this lets it check the bodies' own accesses instead.
void run_on_threads(long long chunks, int threads, const std::function<void(long long)>& chunk) {
  const long long workers = std::min<long long>(chunks, threads > 0 ? threads : std::max(2u, std::thread::hardware_concurrency()));
  std::atomic<long long> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto work = [&] {
    for (long long c; (c = next.fetch_add(1)) < chunks;) try {
        chunk(c);
      } catch (...) {
        std::lock_guard lock(failure_mutex);
        if (!failure) failure = std::current_exception();
        next = chunks;
      }
  };
  std::vector<std::thread> pool;
  for (long long i = 1; i < workers; ++i) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}
}  // namespace
#endif

#ifndef HAZE_TSAN
namespace {
// The calling thread's arena for a cap (0: every core), made on its first use and kept for the
// thread's life. An arena made and dropped per call, as before, grew resident memory by about
// 14 KB a call on a loaded machine (oneTBB 2021.8 with its tbbmalloc; tests/python/test_soak.py),
// and a frame should set nothing up. One arena per thread keeps callers in threads of their own
// as independent as arenas of their own did.
tbb::task_arena& arena_for(int threads) {
  thread_local std::map<int, std::unique_ptr<tbb::task_arena>> arenas;
  auto& arena = arenas[threads];
  const int concurrency = threads > 0 ? threads : tbb::task_arena::automatic;
  if (!arena) arena = std::make_unique<tbb::task_arena>(concurrency);
  return *arena;
}
}  // namespace
#endif

void parallel_for(long long count, int threads, long long grain, const std::function<void(long long, long long)>& body) {
  if (threads < 0) throw Error("threads", to_text(threads), "0 (all cores) or a positive cap");
  if (count <= 0) return;
  grain = std::max(1LL, grain);
  long long chunks = (count + grain - 1) / grain;
  if (chunks == 1 || threads == 1) {  // no arena to set up for work one thread does anyway
    for (long long c = 0; c < chunks; ++c) body(c * grain, std::min(count, (c + 1) * grain));
    return;
  }
#ifdef HAZE_TSAN
  run_on_threads(chunks, threads, [&](long long c) { body(c * grain, std::min(count, (c + 1) * grain)); });
#else
  arena_for(threads).execute([&] {
    tbb::parallel_for(tbb::blocked_range<long long>(0, chunks, 1), [&](const tbb::blocked_range<long long>& r) {
      for (long long c = r.begin(); c != r.end(); ++c) body(c * grain, std::min(count, (c + 1) * grain));
    }, tbb::simple_partitioner());
  });
#endif
}

}  // namespace haze
