// Grid density files (float32, little-endian): the first 3 bytes choose the resolution (1 to 8 a
// side), the rest is the file; an accepted grid is sampled and integrated along a few rays.
#include "fuzz_input.h"

#include <haze/core/medium.h>
#include <haze/core/scene.h>

#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 3) return 0;
  const int nx = 1 + data[0] % 8, ny = 1 + data[1] % 8, nz = 1 + data[2] % 8;
  haze::fuzz::write("grid.raw", data + 3, size - 3);
  const std::string scene = R"({"camera": {"position": [0, 0, 4], "look_at": [0, 0, 0]}, "medium": {"bounds": [[-1, -1, -1], [1, 1, 1]],
    "density": {"type": "grid", "resolution": [)" + std::to_string(nx) + ", " + std::to_string(ny) + ", " + std::to_string(nz) +
                            R"(], "file": "grid.raw"}, "sigma_t": 2}, "lights": []})";
  haze::fuzz::refused_or_fine([&] {
    const haze::Scene s = haze::Scene::from_json(nlohmann::json::parse(scene), haze::fuzz::folder());
    haze::check_scene(s);
    const auto medium = haze::make_medium(*s.medium);
    for (double x : {-0.9, -0.1, 0.37, 0.99}) {
      (void)medium->density(haze::Vec3(x, 0.5 * x, -x));
      (void)medium->transmittance(haze::Vec3(-2.0, x, 0.1), haze::Vec3(2.0, -x, 0.3));
    }
  });
  return 0;
}
