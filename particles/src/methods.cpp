#include <haze/core/scene.h>
#include <haze/particles/methods.h>
#include <haze/particles/network.h>

namespace haze::particles {

void register_methods() {
  register_method(network_info());
  // A scene's `particles` block: the Gaussians' own density (ParticleDensity), which the
  // reference and quadrature render as it is and the grid methods sample on `grid_resolution`
  // cells along the longest side (docs/NETWORKS.md).
  register_density("particles", [](const nlohmann::json& block, const std::string& path, const std::filesystem::path& directory) {
    ParticleSet set = ParticleSet::from_json(block, directory);
    MediumDesc medium = particle_medium(std::move(set), scene_fields::integer(block, path, "grid_resolution", 96, 2, 1024));
    medium.emission = read_emission(block, path, medium.density);
    return medium;
  });
}

}  // namespace haze::particles
