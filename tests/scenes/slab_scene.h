// The plane-parallel slabs the dom tests and haze_dom_accuracy hold against DISORT's published
// test problems: the scene, the camera that reads one emergent radiance, and the published values.
#pragma once

#include <haze/core/scene.h>

#include <cmath>
#include <vector>

namespace haze::grids {

// An orthographic pixel looking at the slab's top (or bottom) centre against the emergent
// direction of cosine mu, at azimuth 0 (the sun's).
inline Camera slab_camera(double tau, double mu, bool top) {
  const Vec3 emergent(std::sqrt(1 - mu * mu), 0.0, top ? mu : -mu), at(0.0, 0.0, top ? tau : 0.0);
  Camera camera;
  camera.type = Camera::Type::orthographic;
  camera.position = at + 10.0 * emergent;
  camera.look_at = at;
  camera.height = 1e-6;
  camera.width_px = camera.height_px = 1;
  return camera;
}

// A slab of optical thickness tau (sigma_t 1, black bottom) lit by a sun of cosine mu0 with
// DISORT's normalization (E = pi / mu0), as a grid density 9 x 9 x nz, `half` wide in x and y on
// either side: the centre column sees no edge. A thick slab under a grazing sun takes half = 2000:
// its 32-high walls catch nearly as much sunlight as its top at half = 200, and at 400 wide its
// conservative scattering (1e) carries that to the centre's bottom (+150% there). Seen from the
// top at mu = 1.
inline Scene slab_scene(double tau, double omega, double g, double mu0, int nz, double half = 200.0) {
  Scene scene;
  MediumDesc m;
  m.bounds = {Vec3(-half, -half, 0), Vec3(half, half, tau)};
  m.density = GridDensity{{9, 9, nz}, std::vector<float>(static_cast<size_t>(81 * nz), 1.0f)};
  m.sigma_t = Rgb(1.0);
  m.albedo = Rgb(omega);
  m.phase = g == 0.0 ? PhaseFunction::isotropic() : PhaseFunction::henyey_greenstein(g);
  scene.medium = m;
  scene.lights.push_back(DirectionalLight{Vec3(std::sqrt(1 - mu0 * mu0), 0.0, -mu0), Rgb(kPi / mu0)});
  scene.camera = slab_camera(tau, 1.0, true);
  return scene;
}

struct SlabView {
  double mu;
  bool top;
  double uu;  // published
};

// DISORT's thick test problems (published UU; van de Hulst 1980), the top at mu 1, 0.5 and 0.1
// first: 1d and 1e (isotropic, tau 32, sun at mu0 0.1, absorbing omega 0.2 and conservative) and
// 3b (HG g 0.75, tau 8, sun overhead, conservative).
struct ThickSlab {
  const char* label;
  const char* description;
  double tau, omega, g, mu0;
  std::vector<SlabView> views;
};

inline const std::vector<ThickSlab>& thick_slabs() {
  static const std::vector<ThickSlab> slabs = {
      {"1d", "tau 32, omega 0.2, isotropic, mu0 0.1", 32.0, 0.2, 0.0, 0.1, {{1.0, true, 0.0502853}, {0.5, true, 0.0906967}, {0.1, true, 0.262972}}},
      {"1e",
       "tau 32, omega 1, isotropic, mu0 0.1",
       32.0,
       1.0,
       0.0,
       0.1,
       {{1.0, true, 0.797199}, {0.5, true, 1.02732}, {0.1, true, 1.93321}, {1.0, false, 0.0271316}, {0.5, false, 0.0187805}}},
      {"3b",
       "tau 8, omega 1, HG 0.75, mu0 1",
       8.0,
       1.0,
       0.75,
       1.0,
       {{1.0, true, 0.493302}, {0.5, true, 0.519598}, {0.1, true, 0.379740}, {1.0, false, 0.669581}, {0.5, false, 0.422350}, {0.1, false, 0.236362}}}};
  return slabs;
}

}  // namespace haze::grids
