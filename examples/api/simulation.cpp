// A simulation's frame loop: a puff of smoke drifts through a 48^3 density grid, and every frame
// the DOM solution is updated (warm: from the previous frame's moments, two sweeps after the
// first-collision one) instead of solved again. Prints each frame's cost warm and cold and the
// fluence at the puff's centre, and writes the frames as EXR files. Usage: simulation [OUT_DIR]
#include <haze/grids/methods.h>
#include <haze/haze.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

namespace {

constexpr int kCells = 48;

// The simulation's state: a Gaussian puff centred at `centre`, on the cells of [-1, 1]^3.
haze::MediumDesc puff(const haze::Vec3& centre) {
  haze::GridDensity grid;
  grid.resolution = {kCells, kCells, kCells};
  grid.values.resize(kCells * kCells * kCells);
  for (int k = 0; k < kCells; ++k)
    for (int j = 0; j < kCells; ++j)
      for (int i = 0; i < kCells; ++i) {
        const haze::Vec3 x = haze::Vec3(i + 0.5, j + 0.5, k + 0.5) / double(kCells) * 2.0 - 1.0;
        const double r2 = glm::dot(x - centre, x - centre);
        grid.values[(k * kCells + j) * kCells + i] = static_cast<float>(std::exp(-r2 / (2 * 0.22 * 0.22)));
      }
  haze::MediumDesc medium;
  medium.bounds = {haze::Vec3(-1.0), haze::Vec3(1.0)};
  medium.density = std::move(grid);
  medium.sigma_t = haze::Rgb(6.0);
  medium.albedo = haze::Rgb(0.95);
  medium.phase = haze::PhaseFunction::henyey_greenstein(0.3);
  return medium;
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path out = argc > 1 ? argv[1] : ".";
  std::filesystem::create_directories(out);
  haze::grids::register_methods();

  haze::Scene scene;
  scene.camera.position = haze::Vec3(0.0, 0.3, 3.5);
  scene.camera.width_px = 128, scene.camera.height_px = 96;
  scene.lights = {haze::DirectionalLight{glm::normalize(haze::Vec3(0.3, -1.0, -0.2)), haze::Rgb(1.0)},
                  haze::PointLight{haze::Vec3(1.2, 0.2, 0.8), haze::Rgb(2.0)}};
  haze::Vec3 centre(-0.45, 0.0, 0.0);
  scene.medium = puff(centre);

  haze::RenderOptions options;
  // Short-characteristics optical depths (0.4% to 1.1% from exact in clouds, docs/PROPAGATION.md)
  // and two warm sweeps a frame; the cold solves take the same settings and run to the tolerance.
  options.settings = {{"directions", 64}, {"terms", 16}, {"optical_depth", "sweep"}, {"warm_iterations", 2}};
  haze::Solution solution = haze::prepare(scene, "dom", options);
  std::printf("frame  warm_s  cold_s  warm/cold  fluence_at_centre (warm, cold)  redone\n");
  double warm_total = 0.0, cold_total = 0.0;
  for (int frame = 0; frame < 10; ++frame) {
    centre.x += 0.09;  // the simulation's step
    scene.medium = puff(centre);
    const haze::UpdateReport report = solution.update({.medium = scene.medium});
    const haze::Stopwatch cold_watch;  // for comparison: everything solved again
    const haze::Solution cold = haze::prepare(scene, "dom", options);
    const double cold_seconds = cold_watch.seconds();
    warm_total += report.seconds, cold_total += cold_seconds;
    const haze::Rgb phi = solution.fluence(centre), phi_cold = cold.fluence(centre);
    std::printf("%5d  %6.3f  %6.3f  %9.2f  %14.5f %14.5f  %s\n", frame, report.seconds, cold_seconds, report.seconds / cold_seconds, phi.r,
                phi_cold.r, report.redone.back().c_str());
    char name[32];
    std::snprintf(name, sizeof name, "frame_%02d.exr", frame);
    haze::write_exr(out / name, solution.render().radiance);
  }
  std::printf("total: warm %.3f s, cold %.3f s, warm/cold %.2f\n", warm_total, cold_total, warm_total / cold_total);
}
