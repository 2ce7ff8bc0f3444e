// haze demo: every built-in scene (examples/*.json) with every registered method, EXR + PNG each,
// and a table of method, time and error against the reference.
#include "commands.h"
#include "progress_bar.h"

#include <haze/core/error.h>
#include <haze/core/stopwatch.h>

#include <algorithm>
#include <cstdio>
#include <iostream>

namespace haze::app {

std::vector<std::filesystem::path> scene_files(const std::string& directory, const std::string& option) {
  std::vector<std::filesystem::path> scenes;
  if (!std::filesystem::is_directory(directory)) throw Error(option, directory, "a directory of scene files");
  for (const auto& entry : std::filesystem::directory_iterator(directory))
    if (entry.path().extension() == ".json") scenes.push_back(entry.path());
  std::sort(scenes.begin(), scenes.end());
  if (scenes.empty()) throw Error(option, directory, "at least one .json scene");
  return scenes;
}

namespace {

struct DemoArgs {
  std::string out = "haze-demo";
  std::string examples = HAZE_EXAMPLES_DIR;
  int threads = 0;
};

int run(const DemoArgs& a) {
  const std::vector<std::filesystem::path> scenes = scene_files(a.examples, "--examples");

  auto methods = registered_methods();
  // auto is a chooser, not a method of its own: the demo shows the methods it chooses from.
  std::erase_if(methods, [](const MethodInfo& m) { return m.name == "auto"; });
  bool has_reference = std::any_of(methods.begin(), methods.end(), [](const auto& m) { return m.name == "reference"; });
  // The reference renders first so the others can be compared with it.
  std::stable_partition(methods.begin(), methods.end(), [](const auto& m) { return m.name == "reference"; });

  std::printf("%-22s %-12s %10s %14s  %s\n", "scene", "method", "seconds", "rel. error", "output");
  int rendered = 0;
  for (const auto& path : scenes) {
    Scene scene = Scene::load(path);
    std::optional<Image> reference;
    for (const auto& method : methods) {
      std::string stem = path.stem().string();
      RenderOptions options;
      options.threads = a.threads;
      options.cache_dir = default_cache_dir();
      ProgressBar bar(stem + " " + method.name);
      options.progress = bar.callback();
      try {
        Stopwatch start;
        RenderResult result = render(scene, method.name, options);
        double seconds = start.seconds();
        auto exr = std::filesystem::path(a.out) / (stem + "_" + method.name + ".exr");
        save_result(result, method.name, seconds, exr, true);
        ++rendered;
        std::string error = has_reference ? "-" : "n/a (no ref.)";
        if (method.name == "reference") {
          reference = result.radiance;
          // Its own noise on the same scale: RMS standard error over RMS radiance.
          char buf[32];
          std::snprintf(buf, sizeof buf, "noise %.4f", result.std_error ? rms(*result.std_error) / rms(result.radiance) : 0.0);
          error = buf;
        } else if (reference) {
          char buf[32];
          std::snprintf(buf, sizeof buf, "%.4f", relative_rmse(result.radiance, *reference));
          error = buf;
        }
        std::printf("%-22s %-12s %10.3f %14s  %s\n", stem.c_str(), method.name.c_str(), seconds, error.c_str(),
                    exr.string().c_str());
      } catch (const Cancelled&) {
        throw;
      } catch (const Error& e) {
        std::printf("%-22s %-12s %10s %14s  not applicable: %s\n", stem.c_str(), method.name.c_str(), "-", "-", e.what());
      }
      std::fflush(stdout);
    }
  }
  std::printf("rel. error: RMSE over pixels and channels divided by the reference's RMS; the reference's row\n"
              "gives its own noise (RMS standard error over RMS radiance) on the same scale. The reference\n"
              "solves the full transport: single-scattering methods (analytic, propagation, quadrature) also differ by the\n"
              "multiple scattering and shadows they leave out.\n");
  return rendered > 0 ? 0 : 1;
}

}  // namespace

Command add_demo(CLI::App& app) {
  auto* sub = app.add_subcommand("demo", "Render the built-in scenes with every method; EXR + PNG and a table");
  auto a = std::make_shared<DemoArgs>();
  sub->add_option("--out", a->out, "Output directory")->capture_default_str();
  sub->add_option("--examples", a->examples, "Directory of scene files")->capture_default_str();
  sub->add_option("--threads", a->threads, "Thread cap (0: all cores)")->check(CLI::NonNegativeNumber);
  return {sub, [a] { return run(*a); }};
}

}  // namespace haze::app
