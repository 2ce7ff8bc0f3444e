// What the fuzz targets share: each input goes to a file of the reader's kind in a per-process
// temporary folder, and only haze::Error may come out of a reader (anything else escapes to
// libFuzzer, which reports it as a crash, as it does sanitizer findings, hangs and out-of-memory).
#pragma once

#include <haze/core/error.h>

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <new>
#include <string>

// Allocation failure as a plain build has it: std::bad_alloc, which the readers turn into a
// haze::Error. ASan's throwing operator new ends the process instead (allocator_may_return_null
// only reaches the nothrow forms), and a 1 KB VDB header may ask OpenVDB for 100 TB. (Only under
// ASan: libstdc++'s own nothrow form calls the throwing one.) A request past 256 MB fails as it
// would on a small machine: ASan fills the shadow of all it hands out, and an EXR header of a few
// bytes may claim a 2 GB attribute, which took fuzz_exr's time to 5 inputs a second.
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define HAZE_FUZZ_ASAN 1
#endif
#endif
#ifdef HAZE_FUZZ_ASAN
constexpr std::size_t kLargestRequest = std::size_t{256} << 20;
void* operator new(std::size_t n) {
  if (n > kLargestRequest) throw std::bad_alloc();
  if (void* p = ::operator new(n, std::nothrow)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  if (n > kLargestRequest) throw std::bad_alloc();
  if (void* p = ::operator new[](n, std::nothrow)) return p;
  throw std::bad_alloc();
}
#endif

namespace haze::fuzz {

inline const std::filesystem::path& folder() {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("haze-fuzz-" + std::to_string(getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

// The bytes written to `name` in folder(); returns its path.
inline std::filesystem::path write(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const auto path = folder() / name;
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

// Runs f, letting a haze::Error (a clear refusal) end it quietly.
template <class F>
void refused_or_fine(F f) {
  try {
    f();
  } catch (const Error&) {
  }
}

}  // namespace haze::fuzz
