#include <haze/core/error.h>
#include <haze/particles/methods.h>
#include <haze/particles/network.h>

namespace haze::particles {

void register_methods() {
  register_method(network_info());
  // Every other method renders the particles' continuous density, sampled on a grid of
  // `particle_resolution` cells along the longest side (96 unless the settings say).
  register_particle_medium([](const Scene& scene, nlohmann::json& settings) {
    int resolution = 96;
    if (auto it = settings.find("particle_resolution"); it != settings.end()) {
      if (!it->is_number_integer() || it->get<int>() < 2 || it->get<int>() > 1024)
        throw Error("method.particle_resolution", it->dump(), "an integer in [2, 1024]");
      resolution = it->get<int>();
      settings.erase(it);
    }
    const ParticleSet set = ParticleSet::from_json(scene.particles, scene.directory);
    return ParticleField(set.view()).to_medium(resolution, 0);
  });
}

}  // namespace haze::particles
