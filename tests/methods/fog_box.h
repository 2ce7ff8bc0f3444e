// The tests' host scene: homogeneous coloured fog in a box [-2, 2] x [-1, 2] x [-2, 2], a point
// light, a camera looking down into it from outside (layers, meshes and froxels tests).
#pragma once

#include <haze/core/scene.h>

namespace haze::testing {

inline Scene fog_box(int width, int height, const Vec3& light = Vec3(0.5, 1.2, 0.3)) {
  Scene scene;
  scene.camera.position = Vec3(0.2, 0.6, 5.0), scene.camera.look_at = Vec3(0.0, -0.4, 0.0);
  scene.camera.width_px = width, scene.camera.height_px = height;
  MediumDesc medium;
  medium.bounds = {Vec3(-2.0, -1.0, -2.0), Vec3(2.0, 2.0, 2.0)};
  medium.sigma_t = Rgb(0.4, 0.5, 0.6);
  medium.albedo = Rgb(0.8);
  medium.phase = PhaseFunction::henyey_greenstein(0.3);
  scene.medium = medium;
  scene.lights.push_back(PointLight{light, Rgb(4.0, 3.5, 3.0)});
  return scene;
}

}  // namespace haze::testing
