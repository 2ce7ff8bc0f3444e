// The `haze` subcommands: each adds itself to the CLI11 app and runs when chosen.
#pragma once

#include <haze/core/method.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include <functional>

namespace haze::app {

// A subcommand and what runs when it was chosen (after parsing); run returns the exit status.
struct Command {
  CLI::App* sub;
  std::function<int()> run;
};
Command add_info(CLI::App& app);
Command add_phase(CLI::App& app);
Command add_render(CLI::App& app);
Command add_demo(CLI::App& app);
Command add_compare(CLI::App& app);
Command add_tables(CLI::App& app);
Command add_bench(CLI::App& app);
// `haze bench frame` under `bench` (cmd_bench_frame.cpp).
Command add_bench_frame(CLI::App& bench);
// `haze bench seeds` under `bench` (cmd_bench_seeds.cpp).
Command add_bench_seeds(CLI::App& bench);
// The median of the benchmarks' per-frame times (cmd_bench_frame.cpp).
double median(std::vector<double> v);
Command add_methods(CLI::App& app);
// Every registered method and its settings, for help texts.
std::string methods_help();

// Writes the result's EXR (with its standard-error layer, if any) and a PNG preview beside it;
// returns the JSON summary `haze render --json` prints.
nlohmann::json save_result(const RenderResult& result, const std::string& method, double seconds,
                           const std::filesystem::path& exr, bool png);

// `haze render --display gl`: the method's solution prepared on the CPU and, when it keeps grid
// fields (grids::GridSolution: propagation, dom), shown by haze::gl's ray-march display in a
// headless context, read back. Throws haze::Error for a method without grid fields, or when the
// build has no GL (HAZE_WITH_GL=OFF).
RenderResult render_gl(const Scene& scene, const std::string& method, const RenderOptions& options);

// The .json scene files in a directory, sorted; throws haze::Error naming `option` when it is not
// a directory or holds none.
std::vector<std::filesystem::path> scene_files(const std::string& directory, const std::string& option);

}  // namespace haze::app
