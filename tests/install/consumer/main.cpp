// The API tour in README.md: a phase-function factorization, then a scene rendered with a method.
#include <haze/haze.h>
#include <haze/reference/methods.h>

#include <iostream>

int main() {
  // Henyey-Greenstein g = 0.5 over 128 Fibonacci directions, factorized into 24 separable terms.
  haze::PhaseMatrix matrix(haze::PhaseFunction::henyey_greenstein(0.5), haze::DirectionSet::fibonacci(128));
  haze::SeparablePhase separable(matrix, 24);
  std::cout << "separable phase: relative error " << separable.relative_error() << "\n";

  // The yardstick methods, "quadrature" and "reference" (haze::register_all() in <haze/all.h>
  // registers every module).
  haze::reference::register_methods();

  // A scene in code; haze::Scene::load("scene.json") reads the same from a file.
  haze::Scene scene;
  scene.camera.width_px = scene.camera.height_px = 32;
  haze::MediumDesc fog;
  fog.bounds = {haze::Vec3(-1.0), haze::Vec3(1.0)};
  fog.sigma_t = haze::Rgb(0.5);
  fog.albedo = haze::Rgb(0.9);
  fog.phase = haze::PhaseFunction::henyey_greenstein(0.3);
  scene.medium = fog;
  scene.lights.push_back(haze::PointLight{haze::Vec3(0.0, 1.5, 0.0), haze::Rgb(10.0)});

  haze::RenderOptions options;
  options.threads = 2;                                      // a cap; 0 uses every core
  options.settings = {{"steps", 128}};                      // the method's own settings
  options.progress = [](double) { return true; };           // return false to cancel
  haze::RenderResult result = haze::render(scene, "quadrature", options);
  haze::write_exr("fog.exr", result.radiance);
  std::cout << "quadrature: mean radiance " << result.radiance.mean().r << "\n";

  try {
    haze::render(scene, "no_such_method");
  } catch (const haze::Error& e) {  // bad input is always a haze::Error naming the field
    std::cout << "error: " << e.what() << "\n";
  }
}
