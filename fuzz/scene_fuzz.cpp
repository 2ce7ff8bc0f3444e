// Scene files: the JSON reader (depth, duplicate keys, number range), every block's checks, the
// particle and VDB blocks' readers, and check_scene on what is accepted.
#include "fuzz_input.h"

#include <haze/core/scene.h>
#include <haze/all.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool registered = (haze::register_all(), true);
  (void)registered;
  const auto path = haze::fuzz::write("scene.json", data, size);
  haze::fuzz::refused_or_fine([&] { haze::check_scene(haze::Scene::load(path)); });
  return 0;
}
