// Particle CSV files (x,y,z[,density][,h]): read through a scene's particles block, which also
// builds the particles' neighbourhoods and density field.
#include "fuzz_input.h"

#include <haze/core/scene.h>
#include <haze/all.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool registered = (haze::register_all(), true);
  (void)registered;
  haze::fuzz::write("particles.csv", data, size);
  const auto scene = nlohmann::json::parse(R"({"camera": {"position": [0, 0, 4], "look_at": [0, 0, 0]},
    "particles": {"file": "particles.csv", "sigma_t": 3, "grid_resolution": 8}, "lights": []})");
  haze::fuzz::refused_or_fine([&] {
    const haze::Scene s = haze::Scene::from_json(scene, haze::fuzz::folder());
    haze::check_scene(s);
    const auto medium = haze::make_medium(*s.medium);
    (void)medium->transmittance(haze::Vec3(0.0, 0.0, 4.0), haze::Vec3(0.1, -0.2, -4.0));
  });
  return 0;
}
