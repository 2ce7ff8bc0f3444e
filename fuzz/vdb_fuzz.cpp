// OpenVDB and NanoVDB files through the vdb density reader: the file's grids, their values and
// transforms, then density lookups and majorants of what is accepted.
#include "fuzz_input.h"

#include <haze/core/medium.h>
#include <haze/core/scene.h>
#include <haze/all.h>

#include <cstring>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool registered = (haze::register_all(), true);
  (void)registered;
  // NanoVDB files by their magic number ("NanoVDB0"), the rest as OpenVDB files.
  const bool nano = size >= 8 && std::memcmp(data, "NanoVDB0", 8) == 0;
  const std::string name = nano ? "density.nvdb" : "density.vdb";
  haze::fuzz::write(name, data, size);
  auto scene = nlohmann::json::parse(R"({"camera": {"position": [0, 0, 40], "look_at": [0, 0, 0]},
    "medium": {"density": {"type": "vdb"}, "sigma_t": 1}, "lights": []})");
  scene["medium"]["density"]["file"] = name;
  haze::fuzz::refused_or_fine([&] {
    const haze::Scene s = haze::Scene::from_json(scene, haze::fuzz::folder());
    haze::check_scene(s);
    const auto medium = haze::make_medium(*s.medium);
    const haze::Aabb box = medium->bounds();
    (void)medium->density(0.5 * (box.lo + box.hi));
    (void)medium->majorants();
  });
  return 0;
}
