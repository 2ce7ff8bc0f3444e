// haze tables: precompute every table the analytic method needs for the given scenes (default: the
// built-in ones with a homogeneous medium), write them as EXRs, and say what was made and how long
// each took.
#include "commands.h"

#include <haze/analytic/airlight.h>
#include <haze/core/stopwatch.h>
#include <haze/core/error.h>

#include <cstdio>
#include <set>

namespace haze::app {

using analytic::AirlightTable;
using analytic::SurfaceAirlightTable;

namespace {

struct TablesArgs {
  std::string out;
  std::vector<std::string> scenes;
  std::string examples = HAZE_EXAMPLES_DIR;
  int threads = 0;
};

int run(const TablesArgs& a) {
  std::filesystem::path out = a.out.empty() ? default_cache_dir() : std::filesystem::path(a.out);
  std::vector<std::filesystem::path> scenes(a.scenes.begin(), a.scenes.end());
  if (scenes.empty() && std::filesystem::is_directory(a.examples))
    for (const auto& entry : std::filesystem::directory_iterator(a.examples))
      if (entry.path().extension() == ".json") scenes.push_back(entry.path());
  std::sort(scenes.begin(), scenes.end());

  Stopwatch total_start;
  std::set<std::string> done;
  std::printf("%-16s %-44s %10s %9s\n", "table", "for", "size", "seconds");
  for (const auto& path : scenes) {
    Scene scene = Scene::load(path);
    if (!scene.medium || !std::holds_alternative<ConstantDensity>(scene.medium->density)) continue;
    const PhaseFunction& phase = scene.medium->phase;
    Stopwatch start;
    bool hit = false;
    AirlightTable airlight = AirlightTable::cached(phase, out, 256, 512, a.threads, &hit);
    if (done.insert(airlight.key()).second)
      std::printf("%-16s %-44s %10s %9.3f%s\n", "airlight", phase.key().c_str(), "256x512", start.seconds(),
                  hit ? " (cached)" : "");
    std::set<double> exponents;
    for (const auto& s : scene.surfaces) {
      if (s.kd != Rgb(0.0)) exponents.insert(0.0);
      if (s.ks != Rgb(0.0)) exponents.insert(s.shininess);
    }
    for (double n : exponents) {
      start.restart();
      SurfaceAirlightTable j = SurfaceAirlightTable::cached(airlight, n, out, 64, 64, a.threads, &hit);
      char label[32];
      std::snprintf(label, sizeof label, n == 0.0 ? "surface J1" : "surface J%g", n);
      if (done.insert(airlight.key() + label).second)
        std::printf("%-16s %-44s %10s %9.3f%s\n", label, phase.key().c_str(), "64x64", start.seconds(), hit ? " (cached)" : "");
    }
  }
  std::printf("%zu tables in %s, %.3f s in all\n", done.size(), out.string().c_str(), total_start.seconds());
  return 0;
}

}  // namespace

Command add_tables(CLI::App& app) {
  auto* sub = app.add_subcommand("tables", "Precompute the analytic method's tables (EXR) for scenes");
  auto a = std::make_shared<TablesArgs>();
  sub->add_option("scenes", a->scenes, "Scene files (default: the built-in scenes)")->check(CLI::ExistingFile);
  sub->add_option("--out", a->out, "Directory for the tables (default: the cache, $HAZE_CACHE_DIR, else $XDG_CACHE_HOME/haze, else ~/.cache/haze)");
  sub->add_option("--examples", a->examples, "Directory of the built-in scenes")->capture_default_str();
  sub->add_option("--threads", a->threads, "Thread cap (0: all cores)")->check(CLI::NonNegativeNumber);
  return {sub, [a] { return run(*a); }};
}

}  // namespace haze::app
