// Homogeneous fog in boxes: the tests' host scene (layers, meshes, froxels) and the unit box
// (the reference's single-scattering test, the extremes tests).
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

// Fog filling [-1, 1]^3 with a point light in it, seen from (0, 0.3, camera_z) through 8 x 8 pixels.
struct UnitFog {
  double camera_z;
  Rgb sigma_t, albedo;
  double g;
  PointLight light;
};
inline Scene unit_fog(const UnitFog& f) {
  Scene scene;
  scene.camera.position = Vec3(0.0, 0.3, f.camera_z);
  scene.camera.width_px = scene.camera.height_px = 8;
  MediumDesc fog;
  fog.bounds = {Vec3(-1.0), Vec3(1.0)};
  fog.sigma_t = f.sigma_t;
  fog.albedo = f.albedo;
  fog.phase = PhaseFunction::henyey_greenstein(f.g);
  scene.medium = fog;
  scene.lights.push_back(f.light);
  return scene;
}

}  // namespace haze::testing
