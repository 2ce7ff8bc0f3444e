// A renderer's use: solve the lighting of a smoke cloud once, then render it from two cameras
// without solving again. Prints the cost of each step and writes both views as EXR files.
// Usage: two_cameras [OUT_DIR]
#include <haze/grids/methods.h>
#include <haze/haze.h>

#include <cstdio>
#include <filesystem>

int main(int argc, char** argv) {
  const std::filesystem::path out = argc > 1 ? argv[1] : ".";
  std::filesystem::create_directories(out);
  haze::grids::register_methods();

  haze::Scene scene;
  haze::MediumDesc smoke;
  smoke.bounds = {haze::Vec3(-1.0), haze::Vec3(1.0)};
  smoke.density = haze::RbfDensity{{{haze::Vec3(-0.3, 0.0, 0.0), 1.0, 3.0}, {haze::Vec3(0.3, 0.2, 0.1), 0.8, 3.5}}};
  smoke.sigma_t = haze::Rgb(5.0);
  smoke.albedo = haze::Rgb(0.9);
  scene.medium = smoke;
  scene.lights = {haze::PointLight{haze::Vec3(0.0, 1.5, 0.5), haze::Rgb(6.0)}};
  scene.camera.width_px = 96, scene.camera.height_px = 72;

  haze::RenderOptions options;
  options.settings = {{"resolution", 40}, {"directions", 64}, {"terms", 16}};
  const haze::Stopwatch watch;
  const haze::Solution solution = haze::prepare(scene, "dom", options);
  std::printf("prepare (dom, %s cells): %.3f s\n", solution.stats()["cells"].dump().c_str(), watch.seconds());

  haze::View front{scene.camera}, side{scene.camera};
  front.camera.position = haze::Vec3(0.0, 0.0, 4.0);
  side.camera.position = haze::Vec3(4.0, 0.5, 0.0);
  for (const auto& [name, view] : {std::pair{"front", front}, std::pair{"side", side}}) {
    const haze::Stopwatch render_watch;
    const haze::RenderResult result = solution.render(view);
    std::printf("render %s: %.3f s, mean radiance %.5f\n", name, render_watch.seconds(), result.radiance.mean().r);
    haze::write_exr(out / (std::string(name) + ".exr"), result.radiance);
  }
}
