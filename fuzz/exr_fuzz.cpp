// OpenEXR files through Haze's three readers: an image (`haze compare`, a demo's reference), a
// host's depth buffer (`haze render --depth`) and a cached table (the analytic method's).
#include "fuzz_input.h"

#include <haze/core/image.h>

#include <ImfHeader.h>

#include <map>
#include <optional>
#include <string>

// A header of a few bytes may claim an image of 2^28 pixels, which the readers then allocate and
// zero-fill (they refuse larger: tests/core/image_test.cpp); capping claims at 1024^2 here keeps
// the fuzzer parsing rather than filling memory. OpenEXR throws past the cap, read as a refusal.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  Imf::Header::setMaxImageSize(1024, 1024);
  Imf::Header::setMaxTileSize(1024, 1024);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = haze::fuzz::write("input.exr", data, size);
  haze::fuzz::refused_or_fine([&] {
    std::optional<haze::Image> std_error;
    (void)haze::read_exr(path, &std_error);
  });
  haze::fuzz::refused_or_fine([&] {
    int width = 0, height = 0;
    (void)haze::read_exr_depth(path, width, height);
  });
  haze::fuzz::refused_or_fine([&] {
    int width = 0, height = 0;
    std::map<std::string, std::string> attributes;
    (void)haze::read_exr_table(path, width, height, attributes);
  });
  return 0;
}
