#include <haze/core/error.h>
#include <haze/particles/methods.h>
#include <haze/particles/network.h>

namespace haze::particles {

void register_methods() {
  register_method(network_info());
  // Every other method renders the particles' continuous density sampled on a grid of
  // `particle_resolution` cells along the longest side (96 unless the settings say), or with
  // `particle_density` "gaussians" the Gaussians themselves (ParticleDensity: exact, and 50x
  // slower in the reference, docs/NETWORKS.md), which the grid methods sample the same way.
  register_particle_medium([](const Scene& scene, nlohmann::json& settings) {
    int resolution = 96;
    if (auto it = settings.find("particle_resolution"); it != settings.end()) {
      if (!it->is_number_integer() || it->get<int>() < 2 || it->get<int>() > 1024)
        throw Error("method.particle_resolution", it->dump(), "an integer in [2, 1024]");
      resolution = it->get<int>();
      settings.erase(it);
    }
    std::string density = "grid";
    if (auto it = settings.find("particle_density"); it != settings.end()) {
      if (!it->is_string() || (*it != "grid" && *it != "gaussians"))
        throw Error("method.particle_density", it->dump(), "\"grid\" or \"gaussians\"");
      density = it->get<std::string>();
      settings.erase(it);
    }
    ParticleSet set = ParticleSet::from_json(scene.particles, scene.directory);
    if (density == "gaussians") return particle_medium(std::move(set), resolution);
    return ParticleField(set.view()).to_medium(resolution, 0);
  });
}

}  // namespace haze::particles
