// A terminal progress bar with an ETA, drawn on stderr only when stderr is a terminal.
#pragma once

#include <haze/core/progress.h>

#include <chrono>
#include <string>

namespace haze::app {

class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  ~ProgressBar();
  // A callback for RenderOptions::progress (never cancels).
  ProgressCallback callback();

 private:
  void draw(double fraction);
  std::string label_;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace haze::app
