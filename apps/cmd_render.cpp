// haze render: one scene with one method, to EXR (+ PNG preview), with a JSON summary.
#include "commands.h"
#include "deadline.h"
#include "mpi_world.h"
#include "progress_bar.h"

#include <haze/auto/auto.h>
#include <haze/core/error.h>
#include <haze/core/stopwatch.h>
#include <haze/vdb/vdb.h>

#include <optional>
#include <tuple>
#include <iostream>

namespace haze::app {

nlohmann::json save_result(const RenderResult& result, const std::string& method, double seconds,
                           const std::filesystem::path& exr, bool png) {
  if (exr.has_parent_path()) std::filesystem::create_directories(exr.parent_path());
  std::vector<std::pair<std::string, const Image*>> layers;
  if (result.std_error) layers.emplace_back("stderr", &*result.std_error);
  if (result.inscatter)
    layers.insert(layers.end(), {{"inscatter", &*result.inscatter}, {"transmittance", &*result.transmittance}, {"surface", &*result.surface}});
  write_exr(exr, result.radiance, layers);
  Rgb mean = result.radiance.mean();
  nlohmann::json out = {{"method", method},
                        {"seconds", seconds},
                        {"width", result.radiance.width()},
                        {"height", result.radiance.height()},
                        {"mean", {mean.r, mean.g, mean.b}},
                        {"output", exr.string()},
                        {"stats", result.stats}};
  if (result.std_error) {
    Rgb e = result.std_error->mean();
    out["mean_std_error"] = {e.r, e.g, e.b};
  }
  if (png) {
    auto preview = std::filesystem::path(exr).replace_extension(".png");
    write_png(preview, result.radiance);
    out["preview"] = preview.string();
  }
  return out;
}

namespace {

struct RenderArgs {
  std::string scene, method, out, display = "cpu", depth, fields;
  int threads = 0, fields_resolution = 64;
  double timeout = 0.0, max_memory_mib = 0.0;
  bool json = false, no_png = false, no_cache = false, explain = false, layers = false;
  std::optional<double> tolerance;
  std::vector<std::string> set;
  // Shortcuts for the reference path tracer's settings; unset unless given.
  std::optional<long long> spp, max_scattering, max_bounces, seed;
};

// "--set key=value": the value is JSON when it parses as JSON, else a string.
nlohmann::json parse_settings(const std::vector<std::string>& pairs) {
  nlohmann::json settings = nlohmann::json::object();
  for (const auto& pair : pairs) {
    auto eq = pair.find('=');
    if (eq == std::string::npos || eq == 0) throw Error("--set", pair, "key=value");
    std::string value = pair.substr(eq + 1);
    auto parsed = nlohmann::json::parse(value, nullptr, false);
    settings[pair.substr(0, eq)] = parsed.is_discarded() ? nlohmann::json(value) : parsed;
  }
  return settings;
}

int render_scene(const RenderArgs& a, const Deadline& deadline) {
  Scene scene = Scene::load(a.scene);
  // Where the image goes: an EXR (its PNG preview beside it), neither of them the scene itself.
  const std::filesystem::path out =
      a.out.empty() ? std::filesystem::path(a.scene).stem().string() + "_" + (a.method.empty() ? scene.method_name() : a.method) + ".exr" : a.out;
  if (out.extension() != ".exr") throw Error("--out", out.string(), "an .exr file name (the PNG preview is written beside it)");
  std::error_code ec;
  for (const auto& written : {out, std::filesystem::path(out).replace_extension(".png")})
    if (std::filesystem::equivalent(written, a.scene, ec))
      throw Error("--out", out.string(), "a file other than the scene " + a.scene + " (writing " + written.string() + " would replace it)");
  std::string method = a.method.empty() ? scene.method_name() : a.method;
  if (method.empty()) create_method("");  // the error lists the available methods
  RenderOptions options;
  options.threads = a.threads;
  options.max_memory = static_cast<std::size_t>(a.max_memory_mib * 1024.0 * 1024.0);
  options.settings = parse_settings(a.set);
  if (!a.no_cache) options.cache_dir = default_cache_dir();
  // The reference's shortcuts, each given once: with --set as well, which would win is unclear.
  for (const auto& [flag, key, value] : {std::tuple{"--spp", "spp", a.spp}, {"--max-scattering", "max_scattering", a.max_scattering},
                                         {"--max-bounces", "max_bounces", a.max_bounces}, {"--seed", "seed", a.seed}}) {
    if (!value) continue;
    if (options.settings.contains(key))
      throw Error(std::string("--set ") + key, json_text(options.settings[key]), std::string("not given with ") + flag + " (one of them)");
    options.settings[key] = *value;
  }
  const std::string chooser = method_with_role(MethodInfo::Role::chooser);
  if (a.tolerance) {
    if (method != chooser) throw Error("--tolerance", std::to_string(*a.tolerance), "--method " + chooser + " (the only method that takes a tolerance)");
    options.settings["tolerance"] = *a.tolerance;
  }
  if (a.explain && method != chooser) throw Error("--explain", "method " + method, "--method " + chooser + " (the choice it explains)");
  if (a.explain) {  // before the render, which may be long
    nlohmann::json settings = scene.method_name() == chooser ? scene.method : nlohmann::json::object();
    for (const auto& [key, value] : options.settings.items()) settings[key] = value;
    const AutoChoice choice = choose_method(scene, settings.value("tolerance", 0.05));
    std::cout << chooser << " chose " << choice.method << " " << choice.settings.dump() << ", expected "
              << (choice.expected_seconds > 0.0 ? to_text(choice.expected_seconds) + " s (the trade suite's closest scene)"
                                                : std::string("time unknown (the reference renders until its noise target)"))
              << "\n";
    for (const auto& line : choice.why) std::cout << "  - " << line << "\n";
    std::cout << std::flush;
  }
  const bool split = world_ranks() > 1, quiet = world_rank() != 0;  // under mpirun: rank 0 alone draws, writes and prints
  ProgressBar bar(method);
  options.progress = deadline.wrap(quiet ? ProgressCallback() : bar.callback());
  const Stopwatch watch;
  // A host's depth buffer and the layers it composites (View).
  std::vector<float> depth;
  if (!a.depth.empty()) {
    int w = 0, h = 0;
    depth = read_exr_depth(a.depth, w, h);
    if (w != scene.camera.width_px || h != scene.camera.height_px)
      throw Error("--depth " + a.depth, to_text(w) + " x " + to_text(h),
                  "the camera's size, " + to_text(scene.camera.width_px) + " x " + to_text(scene.camera.height_px));
  }
  if (a.display == "gl" && (a.layers || !depth.empty()))
    throw Error("--display", "gl", "cpu with --layers or --depth (the GL display renders the image only)");
  const View view{scene.camera, depth, a.layers};
  if (a.display == "gl" && !a.fields.empty()) throw Error("--display", "gl", "cpu with --fields");
  if (split && (a.display == "gl" || !a.fields.empty()))
    throw Error(a.display == "gl" ? "--display" : "--fields", a.display == "gl" ? "gl" : a.fields, "neither under mpirun (rank 0 holds the image only)");
  RenderResult result;
  std::vector<std::string> fields;
  options.ranks = world();
  if (split) {
    result = render(scene, method, options, view);
    if (quiet) return 0;
  } else if (!a.fields.empty()) {  // one solution for the image and the fields (prepared for any view)
    const Solution solution = prepare(scene, method, options);
    RenderOptions render_options;
    render_options.threads = options.threads;
    render_options.progress = options.progress;
    result = solution.render(view, render_options);
    fields = vdb::write_fields(a.fields, solution, a.fields_resolution, options.threads);
  } else {
    result = a.display == "gl" ? render_gl(scene, method, options) : render(scene, method, options, view);
  }
  const double seconds = watch.seconds();
  // The method's warnings (method auto's: those of the method it chose).
  for (const nlohmann::json* stats : {&result.stats, result.stats.contains("method_stats") ? &result.stats["method_stats"] : nullptr})
    if (stats && stats->contains("warnings") && (*stats)["warnings"].is_array())
      for (const auto& line : (*stats)["warnings"]) std::cerr << "warning: " << line.get<std::string>() << "\n";
  auto summary = save_result(result, method, seconds, out, !a.no_png);
  summary["scene"] = a.scene;
  if (!a.fields.empty()) summary["fields"] = {{"output", a.fields}, {"grids", fields}, {"resolution", a.fields_resolution}};
  if (a.json) {
    std::cout << summary.dump(2) << "\n";
  } else {
    Rgb m = result.radiance.mean();
    std::cout << method << ": " << result.radiance.width() << "x" << result.radiance.height() << " in " << seconds
              << " s, mean RGB (" << m.r << ", " << m.g << ", " << m.b << ") -> " << out.string() << "\n";
  }
  return 0;
}

int run(const RenderArgs& a) {
  const Deadline deadline(a.timeout);
  try {
    return render_scene(a, deadline);
  } catch (const Cancelled&) {
    if (!deadline.passed()) throw;
    throw Error("--timeout", to_text(a.timeout) + " s", "enough time for the render (it was cancelled at its first progress report past that)");
  }
}

}  // namespace

Command add_render(CLI::App& app) {
  auto* sub = app.add_subcommand("render", "Render a scene file with a method; writes EXR and a PNG preview");
  auto a = std::make_shared<RenderArgs>();
  sub->add_option("scene", a->scene, "Scene JSON file")->required()->check(CLI::ExistingFile);
  sub->add_option("--method", a->method, "Method (overrides the scene's; the scene's settings apply when names match)");
  sub->add_option("--display", a->display, "cpu: the method's own renderer; gl: its fields through the GLSL ray-march display (propagation, dom)")
      ->check(CLI::IsMember({"cpu", "gl"}));
  sub->add_option("--out", a->out, "Output EXR (default: <scene>_<method>.exr)");
  sub->add_option("--threads", a->threads, "Thread cap (0: all cores)")->check(CLI::NonNegativeNumber);
  sub->add_option("--set", a->set, "Method setting key=value (repeatable), e.g. --set steps=256");
  sub->add_option("--spp", a->spp, "Samples per pixel (reference)");
  sub->add_option("--max-scattering", a->max_scattering, "Medium scattering events per path: -1 unlimited, 1 single, 0 none (reference)");
  sub->add_option("--max-bounces", a->max_bounces, "Surface reflections per path: -1 unlimited (reference)");
  sub->add_option("--seed", a->seed, "Random seed (reference); the same seed gives the same image on any thread count");
  sub->add_option("--tolerance", a->tolerance, "With --method auto: the relative error to stay under (default 0.05)")
      ->check(CLI::Range(1e-4, 0.99));
  sub->add_flag("--explain", a->explain, "With --method auto: print the method and settings chosen and why");
  sub->add_option("--depth", a->depth, "A host's depth buffer: an EXR of the camera's size with one float channel Z (or depth), the "
                                       "distance along each pixel's ray to the host's geometry (inf: none); rays end there")
      ->check(CLI::ExistingFile);
  sub->add_flag("--layers", a->layers, "Also write the layers a host composites, inscatter.R/G/B, transmittance.R/G/B and surface.R/G/B "
                                       "(R/G/B = inscatter + transmittance * surface)");
  sub->add_option("--fields", a->fields, "Also write the solution's fields (fluence, transmittance per light) as OpenVDB grids to this .vdb file");
  sub->add_option("--fields-resolution", a->fields_resolution, "Voxels along the medium's longest side for --fields (default 64)")->check(CLI::Range(2, 1024));
  sub->add_option("--timeout", a->timeout, "Give up after this many seconds: a haze::Error at the work's next progress report (exit code 2)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--max-memory", a->max_memory_mib, "MiB the method may allocate for its solution (default: the memory available); "
                                                     "a solution that would need more is refused before it is made")
      ->check(CLI::PositiveNumber);
  sub->add_flag("--json", a->json, "Print a JSON summary");
  sub->add_flag("--no-png", a->no_png, "Do not write the PNG preview");
  sub->add_flag("--no-cache", a->no_cache, "Rebuild precomputed tables instead of reading them from the cache");
  sub->footer(methods_help());
  return {sub, [a] { return run(*a); }};
}

}  // namespace haze::app
