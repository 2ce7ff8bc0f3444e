#include "deadline.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace haze::app {

Deadline::Deadline(double seconds) : seconds_(seconds) {
  if (!(seconds > 0.0)) return;
  end_ = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
  // The grace period: a quarter of the time, at least 2 s, for the work to reach a progress report.
  const double grace = std::max(2.0, 0.25 * seconds);
  const auto last = end_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(grace));
  watchdog_ = std::thread([this, last] {
    std::unique_lock lock(mutex_);
    if (done_.wait_until(lock, last, [this] { return finished_; })) return;
    std::fprintf(stderr, "haze: error: --timeout: got %g s, expected enough time for the work (it did not stop at a progress report within %g s more)\n",
                 seconds_, std::max(2.0, 0.25 * seconds_));
    std::fflush(stderr);
    std::_Exit(2);
  });
}

Deadline::~Deadline() {
  if (!watchdog_.joinable()) return;
  {
    std::lock_guard lock(mutex_);
    finished_ = true;
  }
  done_.notify_all();
  watchdog_.join();
}

bool Deadline::passed() const { return seconds_ > 0.0 && std::chrono::steady_clock::now() >= end_; }

ProgressCallback Deadline::wrap(ProgressCallback inner) const {
  if (!(seconds_ > 0.0)) return inner;
  return [this, inner = std::move(inner)](double fraction) { return !passed() && (!inner || inner(fraction)); };
}

}  // namespace haze::app
