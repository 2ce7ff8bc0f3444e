#include <haze/core/error.h>
#include <haze/particles/methods.h>
#include <haze/particles/network.h>

namespace haze::particles {

void register_methods() {
  register_method(network_info());
  // A scene's `particles` block: the Gaussians' own density (ParticleDensity), which the
  // reference and quadrature render as it is and the grid methods sample on `grid_resolution`
  // cells along the longest side (docs/NETWORKS.md).
  register_density("particles", [](const nlohmann::json& block, const std::string& path, const std::filesystem::path& directory) {
    int resolution = 96;
    if (block.is_object())
      if (auto it = block.find("grid_resolution"); it != block.end()) {
        if (!it->is_number_integer() || it->get<long long>() < 2 || it->get<long long>() > 1024)
          throw Error(path + ".grid_resolution", it->dump(), "an integer in [2, 1024]");
        resolution = it->get<int>();
      }
    return particle_medium(ParticleSet::from_json(block, directory), resolution);
  });
}

}  // namespace haze::particles
