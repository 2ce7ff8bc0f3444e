// The grid tests' RBF cloud scene, shared by the propagation and dom tests and haze_dom_accuracy.
#pragma once

#include <haze/core/scene.h>

#include <cmath>
#include <optional>

namespace haze::grids {

// An RBF cloud of 9 blobs lit by 2 point lights, one inside its bounds and one outside; no
// surfaces, so single scattering is the only light path both methods see.
inline Scene cloud_scene(int width, int height) {
  nlohmann::json blobs = nlohmann::json::array();
  for (int i = 0; i < 9; ++i) {
    double t = 0.7 * i;
    blobs.push_back({{"center", {0.45 * std::cos(t), 0.3 * std::sin(1.7 * t), 0.35 * std::cos(1.3 * t + 0.5)}},
                     {"weight", 0.8 + 0.4 * std::sin(2.0 * t)},
                     {"sharpness", 2.5 + (i % 3)}});
  }
  nlohmann::json j = {
      {"camera", {{"type", "pinhole"}, {"position", {0.3, 0.4, 3.2}}, {"look_at", {0, 0, 0}}, {"fov_y_deg", 40}, {"width_px", width}, {"height_px", height}}},
      {"medium", {{"density", {{"type", "rbf"}, {"blobs", blobs}}}, {"sigma_t", {2.0, 2.4, 2.8}}, {"albedo", 0.9}, {"phase", {{"type", "hg"}, {"g", 0.4}}}}},
      {"lights", {{{"type", "point"}, {"position", {0.9, 0.9, -0.6}}, {"intensity", {2.0, 1.8, 1.5}}},
                  {{"type", "point"}, {"position", {-2.0, -0.5, 1.0}}, {"intensity", {3.0, 3.0, 4.0}}}}},
      {"background", {0, 0, 0}}};
  return Scene::from_json(j);
}

// A point light and a sun on a cloud: `rbf` the propagation tests' 9-blob cloud, else a box of
// constant density. Full multiple scattering, no surfaces.
inline Scene lit_cloud(bool rbf, int width, int height) {
  Scene scene = cloud_scene(width, height);
  scene.lights[1] = DirectionalLight{glm::normalize(Vec3(0.4, -0.8, -0.45)), Rgb(1.0, 1.0, 1.1)};
  if (!rbf) {
    scene.medium->density = ConstantDensity{1.0};
    scene.medium->bounds = {Vec3(-0.6, -0.5, -0.5), Vec3(0.6, 0.5, 0.5)};
  }
  return scene;
}

// Homogeneous fog filling [-1, 1]^3, seen whole from (0, 0, 4) at 32 x 32 pixels; no lights. The
// phase function is Henyey-Greenstein with g, isotropic without it.
inline Scene fog_cube(double sigma_t, double albedo, std::optional<double> g = std::nullopt) {
  Scene scene;
  scene.camera.position = Vec3(0.0, 0.0, 4.0);
  scene.camera.fov_y_deg = 40.0;
  scene.camera.width_px = scene.camera.height_px = 32;
  MediumDesc fog;
  fog.bounds = {Vec3(-1.0), Vec3(1.0)};
  fog.sigma_t = Rgb(sigma_t), fog.albedo = Rgb(albedo);
  if (g) fog.phase = PhaseFunction::henyey_greenstein(*g);
  scene.medium = fog;
  return scene;
}

}  // namespace haze::grids
