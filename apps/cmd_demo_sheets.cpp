// haze demo --sheets: every built-in scene (examples/*.json) with every registered method against a
// reference that resolves their errors (rendered once, then cached), EXR + PNG each, a contact
// sheet per scene with error maps, and a table of time and error. The time it will take is said
// before anything renders.
#include "commands.h"
#include "demo.h"
#include "progress_bar.h"

#include <haze/core/error.h>
#include <haze/core/math.h>
#include <haze/core/stopwatch.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>

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


constexpr long long kPilotSpp = 64;
// Part of each cached reference's key: raise it when the reference's image of a scene changes
// (2: particle scenes render the Gaussians themselves, not a 96^3 resample).
constexpr int kReferenceRevision = 2;
constexpr double kCheapSeconds = 0.5;  // a method this quick at the reference's size is shown at twice it

// What the demo renders a scene at, and the reference it compares with: the finest of 1%
// noise and what reference_seconds buys, at twice the scene's size where that still reaches 2%.
struct Plan {
  std::filesystem::path scene_file;
  int scale = 1;
  long long spp = 0;
  double expected_seconds = 0.0;  // of the reference; 0 when cached
  std::filesystem::path reference;  // its EXR in the cache (with the standard-error layer)
};

Scene scaled(Scene scene, int scale) {
  scene.camera.width_px *= scale, scene.camera.height_px *= scale;
  return scene;
}

RenderResult reference_render(const Scene& scene, long long spp, int threads, const std::string& label) {
  RenderOptions options;
  options.threads = threads;
  options.settings = {{"spp", spp}, {"seed", 1}};
  ProgressBar bar(label);
  options.progress = bar.callback();
  return render(scene, method_with_role(MethodInfo::Role::reference), options);
}

Plan plan(const std::filesystem::path& file, const DemoArgs& a) {
  std::ifstream in(file);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto dir = default_cache_dir() / "demo";
  const std::string key = file.stem().string() + "_" + to_text(std::hash<std::string>{}(text)) + "_" + to_text(a.reference_seconds) + "s_r" +
                          to_text(kReferenceRevision);
  Plan p{file, 1, 0, 0.0, dir / (key + ".exr")};
  if (std::ifstream cached(dir / (key + ".json")); cached && std::filesystem::exists(p.reference)) {
    const nlohmann::json j = nlohmann::json::parse(cached);
    p.scale = j.at("scale"), p.spp = j.at("spp");
    return p;
  }
  const Scene scene = Scene::load(file);
  Stopwatch watch;
  const RenderResult pilot = reference_render(scene, kPilotSpp, a.threads, file.stem().string() + " pilot");
  const double seconds = watch.seconds();
  const double noise = std::max(lit_pixel_error(pilot.radiance, pilot.radiance, &*pilot.std_error).noise_rms, 1e-6);
  // Noise falls as 1 / sqrt(spp); time grows with spp and pixels.
  auto spp_for = [&](double target) { return kPilotSpp * (noise / target) * (noise / target); };
  auto affordable = [&](int scale) { return kPilotSpp * a.reference_seconds / (seconds * scale * scale); };
  p.scale = std::min(spp_for(0.01), affordable(2)) >= spp_for(0.02) ? 2 : 1;
  const double spp = std::clamp(std::min(spp_for(0.01), affordable(p.scale)), 256.0, 1e9);
  p.spp = static_cast<long long>(std::ceil(spp / 64.0)) * 64;
  p.expected_seconds = seconds * p.scale * p.scale * static_cast<double>(p.spp) / kPilotSpp;
  return p;
}

// Display colours written through write_png's tone map (exposure 1, Reinhard, sRGB) unchanged.
Rgb untonemap(const Rgb& display) {
  Rgb out;
  for (int c = 0; c < 3; ++c) {
    const double s = std::clamp(display[c], 0.0, 0.998);
    const double linear = s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
    out[c] = linear / (1.0 - linear);
  }
  return out;
}

// Relative error -> black (0), red (5%), yellow (10%), white (20% and more).
Rgb error_colour(double e) {
  const double t = std::clamp(e / 0.2, 0.0, 1.0);
  if (t < 0.25) return {t / 0.25, 0.0, 0.0};
  if (t < 0.5) return {1.0, (t - 0.25) / 0.25, 0.0};
  return {1.0, 1.0, (t - 0.5) / 0.5};
}

// A 2x image averaged over 2 x 2 pixels: what it shows at the reference's size.
Image downsample2(const Image& image) {
  Image out(image.width() / 2, image.height() / 2);
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x)
      out.set(x, y, 0.25 * (image.at(2 * x, 2 * y) + image.at(2 * x + 1, 2 * y) + image.at(2 * x, 2 * y + 1) + image.at(2 * x + 1, 2 * y + 1)));
  return out;
}

// Top row: the reference, then each method (`shown`, at the reference's size or twice it; the
// cells take the largest, smaller images enlarged); bottom row: the reference's own noise, then
// each method's error against it (`compared`, at the reference's size), per pixel: |image -
// reference| over the reference's luminance, at least 1% of its peak.
void write_sheet(const std::filesystem::path& path, const Image& reference, const Image& noise, const std::vector<Image>& shown,
                 const std::vector<Image>& compared) {
  const int w = reference.width(), h = reference.height(), n = static_cast<int>(shown.size()) + 1;
  int f = 1;  // the cells' scale over the reference's pixels
  for (const Image& image : shown) f = std::max(f, image.width() / w);
  std::vector<double> lum;
  double peak = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) lum.push_back(luminance(reference.at(x, y))), peak = std::max(peak, lum.back());
  std::vector<double> sorted = lum;
  std::sort(sorted.begin(), sorted.end());
  const double exposure = 1.0 / std::max(sorted[sorted.size() * 95 / 100], 1e-12);
  Image sheet(n * f * w, 2 * f * h);
  for (int i = 0; i < n; ++i) {
    const Image& top = i == 0 ? reference : shown[static_cast<size_t>(i - 1)];
    const int g = top.width() / w;  // this image's scale
    for (int y = 0; y < f * h; ++y)
      for (int x = 0; x < f * w; ++x) {
        const int rx = x / f, ry = y / f;
        const double scale = std::max(lum[static_cast<size_t>(ry * w + rx)], 0.01 * peak);
        const double e = i == 0 ? luminance(noise.at(rx, ry)) / scale
                                : luminance(glm::abs(compared[static_cast<size_t>(i - 1)].at(rx, ry) - reference.at(rx, ry))) / scale;
        sheet.set(i * f * w + x, y, top.at(x * g / f, y * g / f) * exposure);
        sheet.set(i * f * w + x, f * h + y, untonemap(error_colour(e)));
      }
  }
  write_png(path, sheet);
}

std::string percent(double v) {
  char s[32];
  std::snprintf(s, sizeof s, "%.1f%%", 100.0 * v);
  return s;
}

}  // namespace

int run_sheets(const DemoArgs& a) {
  const std::vector<std::filesystem::path> scenes = scene_files(a.examples, "--examples");
  auto methods = registered_methods();
  // auto is a chooser and the reference the yardstick: the rows are the methods auto chooses from.
  std::erase_if(methods, [](const MethodInfo& m) { return m.role != MethodInfo::Role::solver; });
  const std::string reference_name = method_with_role(MethodInfo::Role::reference);

  std::vector<Plan> plans;
  for (const auto& file : scenes) plans.push_back(plan(file, a));
  double reference_seconds = 0.0;
  int to_render = 0;
  for (const Plan& p : plans) reference_seconds += p.expected_seconds, to_render += p.expected_seconds > 0.0;
  std::printf("haze demo: %zu scenes x %zu methods against path-traced references (%d cached, %d to render: about %.0f s,\n"
              "from 64-spp pilots); each method takes from milliseconds to a few seconds.\n\n",
              plans.size(), methods.size(), static_cast<int>(plans.size()) - to_render, to_render, reference_seconds);
  std::fflush(stdout);

  std::printf("%-16s %-12s %9s %10s %9s  %s\n", "scene", "method", "size", "seconds", "error", "output");
  int rendered = 0;
  for (const Plan& p : plans) {
    const std::string stem = p.scene_file.stem().string();
    const Scene scene = scaled(Scene::load(p.scene_file), p.scale);
    const std::string size = to_text(scene.camera.width_px) + "x" + to_text(scene.camera.height_px);
    Image reference, noise;
    double seconds = 0.0;
    if (std::filesystem::exists(p.reference)) {
      std::optional<Image> se;
      reference = read_exr(p.reference, &se);
      noise = *se;
    } else {
      Stopwatch watch;
      RenderResult r = reference_render(scene, p.spp, a.threads, stem + " reference " + to_text(p.spp) + " spp");
      seconds = watch.seconds();
      std::filesystem::create_directories(p.reference.parent_path());
      write_exr(p.reference, r.radiance, &*r.std_error);
      std::ofstream(std::filesystem::path(p.reference).replace_extension(".json")) << nlohmann::json{{"scale", p.scale}, {"spp", p.spp}}.dump();
      reference = std::move(r.radiance), noise = std::move(*r.std_error);
    }
    const double reference_noise = lit_pixel_error(reference, reference, &noise).noise_rms;
    const auto ref_exr = std::filesystem::path(a.out) / (stem + "_reference.exr");
    save_result({reference, noise, {}}, reference_name, seconds, ref_exr, true);
    char took[32];
    std::snprintf(took, sizeof took, "%.3f", seconds);
    std::printf("%-16s %-12s %9s %10s %9s  %s (%lld spp%s)\n", stem.c_str(), reference_name.c_str(), size.c_str(), seconds > 0 ? took : "cached",
                ("noise " + percent(reference_noise)).c_str(), ref_exr.string().c_str(), p.spp, seconds > 0 ? "" : ", from the cache");
    if (reference_noise > 0.05)
      std::printf("%-16s %-12s   errors under %s are not resolved; --reference-seconds %.0f would bring the noise to about 5%%\n", "", "",
                  percent(1.5 * reference_noise).c_str(),
                  a.reference_seconds * (reference_noise / 0.05) * (reference_noise / 0.05));
    std::vector<Image> shown, compared;
    std::string order = reference_name;
    for (const auto& method : methods) {
      auto timed = [&](const Scene& at, const std::string& label) {
        RenderOptions options;
        options.threads = a.threads;
        options.cache_dir = default_cache_dir();
        ProgressBar bar(label);
        options.progress = bar.callback();
        const Stopwatch watch;
        RenderResult r = render(at, method.name, options);
        seconds = watch.seconds();
        return r;
      };
      try {
        RenderResult result = timed(scene, stem + " " + method.name);
        Image at_reference = result.radiance;
        std::string shown_size = size;
        // Where the method is cheap and the reference small, show it at twice the size (compared
        // with the reference averaged back over 2 x 2 pixels).
        if (p.scale == 1 && seconds < kCheapSeconds) {
          const Scene large = scaled(scene, 2);
          result = timed(large, stem + " " + method.name + " 2x");
          at_reference = downsample2(result.radiance);
          shown_size = to_text(large.camera.width_px) + "x" + to_text(large.camera.height_px);
        }
        auto exr = std::filesystem::path(a.out) / (stem + "_" + method.name + ".exr");
        save_result(result, method.name, seconds, exr, true);
        ++rendered;
        const double error = lit_pixel_error(at_reference, reference, &noise).mean_abs;
        // Within 1.5x the reference's noise the error is not resolved: say so.
        const std::string error_text = error < 1.5 * reference_noise ? "~noise" : percent(error);
        std::printf("%-16s %-12s %9s %10.3f %9s  %s\n", stem.c_str(), method.name.c_str(), shown_size.c_str(), seconds, error_text.c_str(),
                    exr.string().c_str());
        shown.push_back(std::move(result.radiance));
        compared.push_back(std::move(at_reference));
        order += " | " + method.name;
      } catch (const Cancelled&) {
        throw;
      } catch (const Error& e) {
        std::printf("%-16s %-12s %9s %10s %9s  not applicable: %s\n", stem.c_str(), method.name.c_str(), size.c_str(), "-", "-", e.what());
      }
      std::fflush(stdout);
    }
    const auto sheet = std::filesystem::path(a.out) / (stem + "_sheet.png");
    write_sheet(sheet, reference, noise, shown, compared);
    std::printf("%-16s %-12s %9s %10s %9s  %s: %s\n\n", stem.c_str(), "sheet", "", "", "", sheet.string().c_str(), order.c_str());
  }
  std::printf("error: mean relative error over the lit pixels (those above 1%% of the reference's peak) against the\n"
              "reference, whose own noise is its row's figure; \"~noise\" marks errors within 1.5x that noise. Methods\n"
              "quick at the reference's size are rendered at twice it and compared averaged over 2 x 2 pixels. The\n"
              "reference solves the full transport: single-scattering methods also differ by the multiple scattering\n"
              "and shadows they leave out (docs/METHODS.md). Sheets: images on top (the order printed), error maps\n"
              "below (the reference's noise first; black 0, red 5%%, yellow 10%%, white 20%% and more).\n");
  return rendered > 0 ? 0 : 1;
}

}  // namespace haze::app
