// The discrete-ordinate solver (method "dom") against published slab values, the reference path
// tracer, its own schemes, and bad input.
#include <haze/core/error.h>
#include <haze/core/method.h>
#include <haze/grids/dom.h>
#include <haze/grids/methods.h>
#include <haze/grids/optical_depth.h>

#include <gtest/gtest.h>

#include <cstdio>

namespace haze::grids {
namespace {

// The reference test's slab (tau 1, sigma_t 1, black bottom, sun with DISORT's normalization
// E = pi / mu0), as a grid density 9 x 9 x nz wide in x and y: the centre column sees no edge.
Scene slab(double omega, double g, double mu0, double mu, int nz) {
  Scene scene;
  MediumDesc m;
  m.bounds = {Vec3(-200, -200, 0), Vec3(200, 200, 1)};
  m.density = GridDensity{{9, 9, nz}, std::vector<float>(static_cast<size_t>(81 * nz), 1.0f)};
  m.sigma_t = Rgb(1.0);
  m.albedo = Rgb(omega);
  m.phase = PhaseFunction::henyey_greenstein(g);
  scene.medium = m;
  scene.lights.push_back(DirectionalLight{Vec3(std::sqrt(1 - mu0 * mu0), 0.0, -mu0), Rgb(kPi / mu0)});
  const Vec3 emergent(std::sqrt(1 - mu * mu), 0.0, mu), top(0.0, 0.0, 1.0);
  scene.camera.type = Camera::Type::orthographic;
  scene.camera.position = top + 10.0 * emergent;
  scene.camera.look_at = top;
  scene.camera.height = 1e-6;
  scene.camera.width_px = scene.camera.height_px = 1;
  return scene;
}

TEST(DomSlab, Explore) {
  register_methods();
  for (int nz : {32, 64, 128}) {
    for (double mu : {1.0, 0.5, 0.1}) {
      RenderOptions options;
      options.settings = {{"directions", 256}, {"terms", 0}, {"step", 0.25}, {"tolerance", 1e-5}};
      auto r = render(slab(1.0, 0.75, 1.0, mu, nz), "dom", options);
      std::printf("nz %d mu %.1f: %.6f  iterations %d\n", nz, mu, r.radiance.at(0, 0).r, r.stats["iterations"].get<int>());
    }
  }
}

}  // namespace
}  // namespace haze::grids
