#include "progress_bar.h"

#include <cstdio>
#include <unistd.h>

namespace haze::app {

ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)), enabled_(isatty(STDERR_FILENO) != 0), start_(std::chrono::steady_clock::now()) {}

ProgressBar::~ProgressBar() {
  if (drawn_) std::fprintf(stderr, "\r\033[K");
}

ProgressCallback ProgressBar::callback() {
  if (!enabled_) return {};
  return [this](double fraction) {
    draw(fraction);
    return true;
  };
}

void ProgressBar::draw(double fraction) {
  double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (elapsed < 0.5 && !drawn_) return;  // short work draws nothing
  if (fraction >= 1.0) {                    // done: leave the line to the caller's summary
    std::fprintf(stderr, "\r\033[K");
    drawn_ = false;
    return;
  }
  const int width = 30;
  int filled = static_cast<int>(fraction * width);
  std::string bar(static_cast<size_t>(filled), '#');
  bar.resize(width, ' ');
  double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  std::fprintf(stderr, "\r\033[K%s [%s] %3.0f%%  %.1fs elapsed, ETA %.1fs", label_.c_str(), bar.c_str(), 100.0 * fraction,
               elapsed, eta);
  std::fflush(stderr);
  drawn_ = true;
}

}  // namespace haze::app
