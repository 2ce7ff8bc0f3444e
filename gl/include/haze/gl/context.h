// Headless OpenGL contexts: EGL surfaceless first (GPU or Mesa llvmpipe), OSMesa as the fallback.
#pragma once

#include <memory>
#include <string>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::gl {

struct GlInfo {
  bool available = false;
  std::string backend;   // "egl-surfaceless" or "osmesa"
  std::string vendor, renderer, version;
  std::string error;     // why neither backend worked, when unavailable
};

// An OpenGL context current on the calling thread for its lifetime; no window, no display server.
class HeadlessContext {
 public:
  // Throws haze::Error naming both backends' failures when neither can make a context.
  HeadlessContext();
  ~HeadlessContext();
  HeadlessContext(const HeadlessContext&) = delete;
  HeadlessContext& operator=(const HeadlessContext&) = delete;
  const GlInfo& info() const { return info_; }
  // Waits until GL has executed every command issued so far (benchmarks time uploads with it).
  void finish() const;
  // A GL entry point of this context's driver ("glDrawArrays"), or nullptr: for a host that draws
  // through Haze's headless context (examples/host). Link to neither libGL nor OSMesa yourself:
  // both export gl* symbols, and the wrong one would be called.
  using ProcAddress = void (*)();
  ProcAddress proc_address(const char* name) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  GlInfo info_;
};

// Tries to make a context and reports what it got (never throws).
GlInfo probe();

}  // namespace haze::gl

#pragma GCC visibility pop
