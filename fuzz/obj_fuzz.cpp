// OBJ meshes (tinyobjloader and Haze's checks): an accepted mesh is built in Embree and traced.
#include "fuzz_input.h"

#include <haze/core/mesh.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = haze::fuzz::write("mesh.obj", data, size);
  haze::fuzz::refused_or_fine([&] {
    const auto mesh = haze::TriangleMesh::load_obj(path);
    const haze::Aabb box = mesh->bounds();
    const haze::Vec3 centre = 0.5 * (box.lo + box.hi);
    double t;
    haze::Vec3 normal;
    for (const haze::Vec3& d : {haze::Vec3(1.0, 0.0, 0.0), haze::Vec3(0.0, -1.0, 0.0), glm::normalize(haze::Vec3(0.3, 0.5, -0.8))}) {
      (void)mesh->intersect({centre - 10.0 * (1.0 + glm::length(box.extent())) * d, d}, 0.0, haze::kInfinity, t, normal);
      (void)mesh->occluded({centre, d}, 0.0, haze::kInfinity);
    }
  });
  return 0;
}
