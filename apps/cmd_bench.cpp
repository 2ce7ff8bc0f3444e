// haze bench trade: the speed/accuracy trade of every method on a fixed suite of scenes, measured
// against the reference path tracer; CSV, per-method plot data and docs/TRADEOFFS.md.
#include "commands.h"
#include "progress_bar.h"

#include <haze/core/error.h>
#include <haze/core/stopwatch.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>

namespace haze::app {

namespace {

// The yardstick and the chooser (method auto) as the registry names them (MethodInfo::Role).
const std::string& reference_method() {
  static const std::string name = method_with_role(MethodInfo::Role::reference);
  return name;
}
const std::string& chooser_method() {
  static const std::string name = method_with_role(MethodInfo::Role::chooser);
  return name;
}

struct TradeArgs {
  std::string suite = HAZE_TRADE_SUITE_DIR, out = "build/trade", method;
  long long spp = 16384;
  int threads = 0;
  std::vector<double> tolerances{0.05, 0.02, 0.01};
  bool report_only = false;
  std::vector<std::string> only;  // --scene: these scenes only
};

constexpr long long kDeepestSpp = 1 << 19;  // the reference rows stop here (about 16 minutes per scene)

struct Config {
  std::string method;
  nlohmann::json settings;
};

// What each method's sweep varies: the settings that trade time for error.
// (MethodInfo::trade_sweep; auto's tolerances run apart, after the references are known.)
std::vector<Config> sweep() {
  std::vector<Config> c;
  for (const MethodInfo& m : registered_methods())
    if (m.name != chooser_method())
      for (const nlohmann::json& settings : m.trade_sweep) c.push_back({m.name, settings});
  return c;
}

struct Row {
  std::string scene, method;
  nlohmann::json settings;
  double seconds = 0.0;
  LitPixelError error;
  bool pareto = false;
  std::string chosen;  // auto: the method and settings it chose
  double worst = -1.0;  // a reference row re-rendered on kRecheckSeeds: the largest error of all its seeds
  double measure() const { return error.rms_noise_removed; }
  // What "meets T" is judged by: every seed measured.
  double robust() const { return std::max(measure(), worst); }
};

constexpr int kRecheckSeeds[] = {8, 9};
constexpr double kRecheckSeconds = 60.0;  // reference rows that take longer are judged on one seed

std::string compact(const nlohmann::json& settings) {
  std::string s;
  for (const auto& [key, value] : settings.items()) {
    if (key == "seed" || key == "sky_directions") continue;
    s += (s.empty() ? "" : " ") + key + "=" + value.dump();
  }
  return s;
}

// One render and its wall time.
RenderResult timed_once(const Scene& scene, const std::string& method, const RenderOptions& options, double& seconds) {
  Stopwatch start;
  RenderResult result = render(scene, method, options);
  seconds = start.seconds();
  return result;
}

// Times a render: once, and when that took under a second, three more (tables cached, caches
// warm), their median.
RenderResult timed(const Scene& scene, const std::string& method, const RenderOptions& options, double& seconds) {
  RenderResult result = timed_once(scene, method, options, seconds);
  if (seconds < 1.0) {
    double t[3];
    for (double& v : t) result = timed_once(scene, method, options, v);
    std::sort(t, t + 3);
    seconds = t[1];
  }
  return result;
}

std::string percent(double e) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f%%", 100.0 * e);
  return b;
}

std::string secs(double s) {
  char b[32];
  std::snprintf(b, sizeof b, s < 0.1 ? "%.4f s" : "%.3g s", s);
  return b;
}

// A measured row on stdout, as it comes.
void print_row(const Row& r) {
  std::printf("%-15s %-12s %-40s %10s %8s%s\n", r.scene.c_str(), r.method.c_str(), compact(r.settings).c_str(), secs(r.seconds).c_str(),
              percent(r.measure()).c_str(), r.chosen.empty() ? "" : ("  chose " + r.chosen).c_str());
  std::fflush(stdout);
}


// "k=v k=v" (compact()) back to settings.
nlohmann::json parse_compact(const std::string& text) {
  nlohmann::json settings = nlohmann::json::object();
  size_t at = 0;
  while (at < text.size()) {
    size_t end = text.find(' ', at);
    if (end == std::string::npos) end = text.size();
    const std::string pair = text.substr(at, end - at);
    const size_t eq = pair.find('=');
    if (eq != std::string::npos) settings[pair.substr(0, eq)] = nlohmann::json::parse(pair.substr(eq + 1));
    at = end + 1;
  }
  return settings;
}

// A CSV field in quotes, its quotes doubled (a string setting's value is quoted: storage="float16").
std::string csv_quoted(const std::string& text) {
  std::string out = "\"";
  for (char ch : text) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

// The rows of an earlier trade.csv (so that --method reruns one method and keeps the others).
std::vector<Row> read_rows(const std::filesystem::path& file) {
  std::vector<Row> rows;
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::string cell;
    bool quoted = false;
    for (size_t i = 0; i < line.size(); ++i) {
      const char ch = line[i];
      if (ch == '"' && quoted && i + 1 < line.size() && line[i + 1] == '"') cell += '"', ++i;  // "" in a quoted field
      else if (ch == '"') quoted = !quoted;
      else if (ch == ',' && !quoted) f.push_back(cell), cell.clear();
      else cell += ch;
    }
    f.push_back(cell);
    if (f.size() < 11) continue;
    Row r{f[0], f[1], parse_compact(f[2]), std::stod(f[3]), {}, f[9] == "1", f[10]};
    r.error.rms_noise_removed = std::stod(f[4]), r.error.mean_abs = std::stod(f[5]), r.error.signed_mean = std::stod(f[6]);
    r.error.noise_rms = std::stod(f[7]), r.error.pixels = std::stoi(f[8]);
    if (f.size() > 11 && !f[11].empty()) r.worst = std::stod(f[11]);
    rows.push_back(r);
  }
  return rows;
}

struct Reference {
  long long spp = 0;
  Image image;
  Image se;  // per-pixel standard error
  double seconds = 0.0;
  LitPixelError noise() const { return lit_pixel_error(image, image, &se); }
};

// The scene's reference at `spp` (seed 1), kept between runs in --out/reference: its spp is in the
// file name, its render time beside it.
Reference cached_reference(const Scene& scene, const std::string& name, long long spp, const std::filesystem::path& out,
                           const TradeArgs& a) {
  const auto path = out / reference_method() / (name + "_" + std::to_string(spp) + "spp.exr");
  const auto meta = std::filesystem::path(path).replace_extension(".json");
  Reference ref{spp, {}, {}, 0.0};
  if (std::filesystem::exists(path)) {
    std::optional<Image> se;
    ref.image = read_exr(path, &se);
    if (!se) throw Error("--out", path.string(), "a reference EXR with its standard error channels");
    ref.se = *se;
    std::ifstream in(meta);
    ref.seconds = nlohmann::json::parse(in).value("seconds", 0.0);
    return ref;
  }
  RenderOptions options;
  options.threads = a.threads;
  options.settings = {{"spp", spp}, {"seed", 1}};
  ProgressBar bar(name + " reference " + std::to_string(spp) + " spp");
  options.progress = bar.callback();
  RenderResult r = timed_once(scene, reference_method(), options, ref.seconds);
  write_exr(path, r.radiance, &*r.std_error);
  std::ofstream(meta) << nlohmann::json{{"seconds", ref.seconds}}.dump();
  ref.image = std::move(r.radiance), ref.se = std::move(*r.std_error);
  return ref;
}

// Past the sweep's 4096 spp, the reference doubles its spp until it meets the smallest tolerance,
// unless another row already meets it faster than the next doubling would take (time grows with
// spp). These are the rows that method auto's reference choices are compared with.
void deepen_reference(const Scene& scene, const std::string& name, const Image& reference, const Image& se, const TradeArgs& a,
                      const std::vector<Row>& kept, std::vector<Row>& rows) {
  const double smallest = *std::min_element(a.tolerances.begin(), a.tolerances.end());
  auto last = std::find_if(rows.rbegin(), rows.rend(), [](const Row& r) { return r.method == reference_method(); });
  if (last == rows.rend()) return;
  long long spp = last->settings["spp"].get<long long>();
  double seconds = last->seconds;
  bool met = last->measure() < smallest;
  while (!met && spp < kDeepestSpp) {
    spp *= 2, seconds *= 2;
    auto faster = [&](const Row& r) { return r.scene == name && r.method != chooser_method() && r.measure() < smallest && r.seconds < seconds; };
    if (std::any_of(rows.begin(), rows.end(), faster) || std::any_of(kept.begin(), kept.end(), faster)) return;
    RenderOptions options;
    options.threads = a.threads;
    options.settings = {{"spp", spp}, {"seed", 7}};
    ProgressBar bar(name + " reference " + std::to_string(spp) + " spp");
    options.progress = bar.callback();
    Row row{name, reference_method(), options.settings, 0.0, {}, false, {}};
    row.error = lit_pixel_error(timed_once(scene, reference_method(), options, row.seconds).radiance, reference, &se);
    seconds = row.seconds;
    print_row(row);
    met = row.measure() < smallest;
    rows.push_back(row);
  }
}

const Row* fastest_within(const std::vector<Row>& rows, const std::string& scene, double tolerance) {
  const Row* best = nullptr;
  for (const Row& r : rows)
    if (r.scene == scene && r.method != chooser_method() && r.robust() < tolerance && (!best || r.seconds < best->seconds)) best = &r;
  return best;
}

// The path tracer's error at a given spp varies from seed to seed by more than its standard error
// says (heavy tails), so a reference row that would be the fastest under a tolerance is rendered on
// kRecheckSeeds too (when a render takes under kRecheckSeconds) and counts only if every seed meets
// the tolerance; otherwise the next fastest is checked.
void recheck_seeds(const Scene& scene, const std::string& name, const Image& reference, const Image& se, const TradeArgs& a,
                   std::vector<Row>& all) {
  for (double tolerance : a.tolerances) {
    for (;;) {
      Row* best = const_cast<Row*>(fastest_within(all, name, tolerance));
      if (!best || best->method != reference_method() || best->worst >= 0.0 || best->seconds > kRecheckSeconds) break;
      best->worst = best->measure();
      for (int seed : kRecheckSeeds) {
        RenderOptions options;
        options.threads = a.threads;
        options.settings = {{"spp", best->settings["spp"]}, {"seed", seed}};
        const double error = lit_pixel_error(render(scene, reference_method(), options).radiance, reference, &se).rms_noise_removed;
        best->worst = std::max(best->worst, error);
        std::printf("%-15s %-12s %-40s seed %d: %8s\n", name.c_str(), reference_method().c_str(), compact(best->settings).c_str(), seed, percent(error).c_str());
        std::fflush(stdout);
      }
    }
  }
}

// docs/TRADEOFFS.md, from the rows: what was measured and how, the plots, the recommended settings
// per error level and how method auto did.
void write_tradeoffs(const std::filesystem::path& file, const std::vector<std::string>& suite, const std::vector<Row>& rows,
                     const nlohmann::json& references, const TradeArgs& a) {
  // The scenes measured so far (a --scene run into a fresh --out has only its own).
  std::vector<std::string> scenes;
  std::copy_if(suite.begin(), suite.end(), std::back_inserter(scenes), [&](const std::string& s) { return references.contains(s); });
  std::ofstream md(file);
  md << "# Speed against accuracy: the trade suite\n\n"
        "<!-- Generated by scripts/trade (haze bench trade); edit apps/cmd_bench.cpp, not this file. -->\n\n"
        "Every method renders five scenes (bench/trade/README.md) with the settings that trade time for\n"
        "error, and each image is compared with the reference path tracer's. Use this page to pick a\n"
        "method and settings for an error budget, or let `haze render --method auto --tolerance T` pick.\n\n"
        "**Error** is the RMS relative error over the lit pixels (luminance above 1% of the reference's\n"
        "peak) with the reference's own noise removed: `sqrt(max(0, mean(d^2 - se^2)))`, d the per-pixel\n"
        "relative difference and se the reference's relative standard error (`lit_pixel_error`,\n"
        "`rms_noise_removed`). A noisy method (the path tracer at few samples) counts its own noise as error.\n"
        "**Time** is the whole render (setup, tables, solve, image) on this 2-core machine, every core: the median\n"
        "of three runs after a first one when that first took under a second, else the first run; method\n"
        "auto is timed once, its choice included.\n\n"
        "**The reference is swept too**, at 16 to 4096 spp (another seed than the reference's), then doubling\n"
        "until it meets the smallest tolerance (at most 2^19 spp) unless another measurement already meets it\n"
        "faster than the next doubling would take: those rows are what auto's reference choices are compared with.\n"
        "Where their error stops falling as spp doubles, it has met the floor of the reference's own noise, whose\n"
        "tail is heavier than its standard error says: errors near that floor are not resolved by this reference.\n"
        "For the same reason a reference row counts as meeting a tolerance (in the recommendations and auto's\n"
        "comparison) only if two more seeds (8 and 9) meet it too, when a render takes under a minute; the error\n"
        "shown in the recommendations is then the largest of the three.\n\n"
        "## The references\n\nThe reference's noise limits the smallest error the comparison resolves: about\n"
        "noise (2 / pixels)^(1/4), the spread of the noise-removed estimate, for Gaussian noise; heavy tails\n"
        "make it larger. So a scene whose reference at --spp has more noise than 1% (or the smallest tolerance)\n"
        "is rendered again at the power of two of spp that its noise, falling as 1 / sqrt(spp), predicts\n"
        "brings it under; a heavy tail can leave it a little over (the table shows the noise reached).\n\n"
        "| scene | spp | seconds | reference noise (RMS relative, lit pixels) | lit pixels | smallest error resolved |\n|---|---|---|---|---|---|\n";
  for (const auto& scene : scenes) {
    const auto& r = references[scene];
    md << "| " << scene << " | " << r["spp"].get<long long>() << " | " << secs(r["seconds"].get<double>()) << " | "
       << percent(r["noise_rms"].get<double>()) << " | " << r["pixels"].get<int>() << " | "
       << percent(r["noise_rms"].get<double>() * std::pow(2.0 / std::max(1, r["pixels"].get<int>()), 0.25)) << " |\n";
  }
  md << "\n## At a glance\n\n";
  for (const auto& scene : scenes) {
    const Row* fast = nullptr;  // the most accurate measurement of a method other than the reference
    for (const Row& r : rows)
      if (r.scene == scene && r.method != chooser_method() && r.method != reference_method() && (!fast || r.measure() < fast->measure())) fast = &r;
    const Row* five = fastest_within(rows, scene, 0.05);
    md << "- **" << scene << "**: the most accurate fast method is "
       << (fast ? fast->method + " (" + compact(fast->settings) + ") at " + percent(fast->measure()) + " in " + secs(fast->seconds) : std::string("none"))
       << "; under 5% the fastest is " << (five ? five->method + " at " + secs(five->seconds) : std::string("nothing the sweep measured")) << ".\n";
  }
  std::string single;
  for (const MethodInfo& m : registered_methods())
    if (m.single_scattering) single += (single.empty() ? "" : ", ") + m.name;
  md << "\nThe single-scattering methods (" << single << ") miss the light scattered more than once. How each\n"
        "method lights surfaces, and whether it sends the light they reflect back into the medium, is in\n"
        "docs/METHODS.md (`haze methods`). On scenes where either matters, the path tracer itself is the\n"
        "fastest way under a tight tolerance.\n";
  md << "\n## Recommended settings per error level\n\nThe fastest measured method and settings under each error level, per scene (- : none of\n"
        "the sweep reached it).\n\n| scene | under 10% | under 5% | under 2% | under 1% |\n|---|---|---|---|---|\n";
  for (const auto& scene : scenes) {
    md << "| " << scene;
    for (double t : {0.10, 0.05, 0.02, 0.01}) {
      const Row* best = fastest_within(rows, scene, t);
      md << " | " << (best ? best->method + " " + compact(best->settings) + ", " + secs(best->seconds) + " (" + percent(best->robust()) + ")" : "-");
    }
    md << " |\n";
  }
  md << "\n## Method auto\n\n`--method auto --tolerance T` chooses from the scene alone (core/src/auto.cpp says which\n"
        "measurement each rule rests on; `--explain` prints the choice and why). Here it is checked against the\n"
        "reference, and its time against the fastest swept method and settings under the same T. When the sweep\n"
        "measured the same choice, its error is shown too. A reference choice adds samples until its own noise\n"
        "is 0.75 T (`target_noise`); the spp it reached follows its settings.\n\n"
        "| scene | T | auto chose | seconds | error | the same, swept | under T | fastest under T | auto / fastest |\n"
        "|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    if (r.method != chooser_method()) continue;
    const double t = r.settings["tolerance"].get<double>();
    const Row* best = fastest_within(rows, r.scene, t);
    const auto same = std::find_if(rows.begin(), rows.end(), [&](const Row& o) {
      return o.scene == r.scene && o.method != chooser_method() && o.method + " " + compact(o.settings) == r.chosen;
    });
    char ratio[32] = "-";
    if (best) std::snprintf(ratio, sizeof ratio, "%.2fx", r.seconds / best->seconds);
    md << "| " << r.scene << " | " << percent(t) << " | " << r.chosen << " | " << secs(r.seconds) << " | " << percent(r.measure()) << " | "
       << (same != rows.end() ? percent(same->measure()) : std::string("-")) << " | " << (r.measure() < t ? "yes" : "**no**") << " | "
       << (best ? best->method + " " + compact(best->settings) + ", " + secs(best->seconds) : std::string("none in the sweep")) << " | " << ratio
       << " |\n";
  }
  md << "\n## Each scene\n\nError against time, log-log, one curve per method; the black line joins the Pareto front (no other\n"
        "measurement is both faster and more accurate). The tables list every measurement, the front's in bold.\n";
  for (const auto& scene : scenes) {
    md << "\n### " << scene << "\n\n![" << scene << "](trade_" << scene << ".png)\n\n| method | settings | seconds | error | signed mean |\n|---|---|---|---|---|\n";
    for (const Row& r : rows) {
      if (r.scene != scene || r.method == chooser_method()) continue;
      const std::string b = r.pareto ? "**" : "";
      md << "| " << b << r.method << b << " | " << compact(r.settings) << " | " << secs(r.seconds) << " | " << b << percent(r.measure()) << b
         << " | " << percent(r.error.signed_mean) << " |\n";
    }
  }
  md << "\nRegenerate everything (references are kept in build/trade/reference and reused):\n\n```sh\nscripts/trade\n```\n\n"
        "It builds `haze`, runs `haze bench trade --out build/trade --spp " << a.spp << "` and plots with gnuplot into docs/.\n";
}

int run(const TradeArgs& a) {
  const std::vector<std::filesystem::path> scenes = scene_files(a.suite, "--suite");
  std::vector<std::string> names;
  for (const auto& path : scenes) names.push_back(path.stem().string());
  const std::filesystem::path out = a.out;
  std::filesystem::create_directories(out / "plot");
  std::filesystem::create_directories(out / reference_method());

  std::vector<Row> all;
  if (a.report_only) {
    // Rewrite the outputs from an earlier run's rows and references, rendering nothing.
    if (!std::filesystem::exists(out / "trade.csv")) throw Error("--report-only", (out / "trade.csv").string() + " missing", "an earlier run's output in --out");
    all = read_rows(out / "trade.csv");
    std::ifstream summary(out / "trade.json");
    const nlohmann::json references = nlohmann::json::parse(summary)["references"];
    write_tradeoffs(out / "TRADEOFFS.md", names, all, references, a);
    return 0;
  }
  // With --method or --scene, the other rows of an earlier run stay.
  auto selected = [&](const std::string& scene) { return a.only.empty() || std::find(a.only.begin(), a.only.end(), scene) != a.only.end(); };
  if ((!a.method.empty() || !a.only.empty()) && std::filesystem::exists(out / "trade.csv"))
    for (Row& r : read_rows(out / "trade.csv"))
      if (!((a.method.empty() || r.method == a.method) && selected(r.scene))) all.push_back(std::move(r));
  nlohmann::json references = nlohmann::json::object();
  if (!a.only.empty() && std::filesystem::exists(out / "trade.json")) {
    std::ifstream previous(out / "trade.json");
    references = nlohmann::json::parse(previous)["references"];
  }
  for (const auto& path : scenes) {
    const std::string name = path.stem().string();
    if (!selected(name)) continue;
    const Scene scene = Scene::load(path);
    // The reference's own noise is brought to 1% (or the smallest tolerance, if smaller; the same
    // reference whatever --tolerances a run takes): a scene whose --spp reference is noisier is
    // rendered again at the power of two of spp predicted to bring it there (1 / sqrt(spp)).
    Reference ref = cached_reference(scene, name, a.spp, out, a);
    const double smallest = std::min(0.01, *std::min_element(a.tolerances.begin(), a.tolerances.end()));
    if (const double noise = ref.noise().noise_rms; noise > smallest) {
      long long spp = a.spp;
      while (static_cast<double>(spp) < static_cast<double>(a.spp) * (noise / smallest) * (noise / smallest)) spp *= 2;
      ref = cached_reference(scene, name, spp, out, a);
    }
    const Image& reference = ref.image;
    const Image& se = ref.se;
    const LitPixelError self = ref.noise();
    references[name] = {{"spp", ref.spp}, {"seconds", ref.seconds}, {"noise_rms", self.noise_rms}, {"pixels", self.pixels}};

    std::vector<Row> rows;
    for (const Config& c : sweep()) {
      if (!a.method.empty() && c.method != a.method) continue;
      RenderOptions options;
      options.threads = a.threads;
      options.cache_dir = default_cache_dir();
      options.settings = c.settings;
      Row row{name, c.method, c.settings, 0.0, {}, false, {}};
      try {
        const RenderResult r = timed(scene, c.method, options, row.seconds);
        row.error = lit_pixel_error(r.radiance, reference, &se);
      } catch (const Cancelled&) {
        throw;
      } catch (const Error& e) {
        std::fprintf(stderr, "%-15s %-12s %-40s not applicable: %s\n", name.c_str(), c.method.c_str(), compact(c.settings).c_str(), e.what());
        continue;
      }
      print_row(row);
      rows.push_back(row);
    }
    if (a.method.empty() || a.method == reference_method()) deepen_reference(scene, name, reference, se, a, all, rows);
    all.insert(all.end(), rows.begin(), rows.end());
    recheck_seeds(scene, name, reference, se, a, all);
    if (!a.method.empty() && a.method != chooser_method()) continue;
    for (double tolerance : a.tolerances) {
      RenderOptions options;
      options.threads = a.threads;
      options.cache_dir = default_cache_dir();
      options.settings = {{"tolerance", tolerance}};
      Row row{name, chooser_method(), options.settings, 0.0, {}, false, {}};
      const RenderResult r = timed_once(scene, chooser_method(), options, row.seconds);  // once: its choice may be a long reference render
      row.error = lit_pixel_error(r.radiance, reference, &se);
      row.chosen = r.stats[chooser_method()]["method"].get<std::string>() + " " + compact(r.stats[chooser_method()]["settings"]);
      if (r.stats[chooser_method()]["settings"].contains("target_noise"))  // the reference's rounds: the samples they took
        row.chosen += ": spp=" + std::to_string(r.stats["method_stats"]["spp"].get<long long>());
      print_row(row);
      all.push_back(row);
    }
  }

  // The Pareto front per scene, over every method but auto (a chooser, not a point of the trade).
  std::stable_sort(all.begin(), all.end(), [](const Row& x, const Row& y) { return x.scene < y.scene; });
  for (const std::string& name : names) {
    std::vector<Row*> scene_rows;
    for (Row& r : all)
      if (r.scene == name && r.method != chooser_method()) scene_rows.push_back(&r);
    for (Row* r : scene_rows)
      r->pareto = std::none_of(scene_rows.begin(), scene_rows.end(), [&](const Row* o) {
        return o != r && o->seconds <= r->seconds && o->measure() <= r->measure() && (o->seconds < r->seconds || o->measure() < r->measure());
      });
  }
  std::ofstream csv(out / "trade.csv");
  csv << "scene,method,settings,seconds,error_rms_noise_removed,mean_abs,signed_mean,reference_noise_rms,lit_pixels,pareto,auto_chose,"
         "worst_of_seeds\n";
  for (const Row& r : all) {
    csv << r.scene << "," << r.method << "," << csv_quoted(compact(r.settings)) << "," << r.seconds << "," << r.measure() << ","
        << r.error.mean_abs << "," << r.error.signed_mean << "," << r.error.noise_rms << "," << r.error.pixels << "," << r.pareto << ","
        << csv_quoted(r.chosen) << ",";
    if (r.worst >= 0.0) csv << r.worst;
    csv << "\n";
  }
  // Plot data: one file per scene and method (seconds, error), and the scene's Pareto front.
  std::map<std::string, std::ofstream> files;
  for (const Row& r : all) {
    if (r.method == chooser_method()) continue;
    auto& f = files[r.scene + "__" + r.method];
    if (!f.is_open()) f.open(out / "plot" / (r.scene + "__" + r.method + ".dat"));
    f << r.seconds << " " << std::max(r.measure(), 1e-4) << "\n";
  }
  for (const std::string& name : names) {
    std::vector<Row> front;
    for (const Row& r : all)
      if (r.scene == name && r.pareto) front.push_back(r);
    std::sort(front.begin(), front.end(), [](const Row& x, const Row& y) { return x.seconds < y.seconds; });
    std::ofstream f(out / "plot" / (name + "__pareto.dat"));
    for (const Row& r : front) f << r.seconds << " " << std::max(r.measure(), 1e-4) << "\n";
  }
  write_tradeoffs(out / "TRADEOFFS.md", names, all, references, a);
  nlohmann::json summary = {{"references", references}, {"rows", all.size()}};
  std::ofstream(out / "trade.json") << summary.dump(2) << "\n";
  std::printf("wrote %s (%zu rows)\n", (out / "trade.csv").string().c_str(), all.size());
  return 0;
}

}  // namespace

Command add_bench(CLI::App& app) {
  auto* bench = app.add_subcommand("bench", "Measurements: the speed/accuracy trade of every method, a host's frame");
  bench->require_subcommand(1);
  auto* sub = bench->add_subcommand("trade", "Time and error against the reference for every method and setting on the trade suite");
  auto a = std::make_shared<TradeArgs>();
  sub->add_option("--method", a->method, "Only this method's sweep");
  sub->add_option("--out", a->out, "Output directory (CSV, plot data, cached references)")->capture_default_str();
  sub->add_option("--suite", a->suite, "Directory of the suite's scene files")->capture_default_str();
  sub->add_option("--spp", a->spp, "The reference's samples per pixel")->capture_default_str()->check(CLI::PositiveNumber);
  sub->add_option("--threads", a->threads, "Thread cap (0: all cores)")->check(CLI::NonNegativeNumber);
  sub->add_option("--tolerances", a->tolerances, "The tolerances method auto is run at")->capture_default_str();
  sub->add_option("--scene", a->only, "Only these scenes of the suite (by file stem); the others' rows stay");
  sub->add_flag("--report-only", a->report_only, "Rewrite TRADEOFFS.md from the rows in --out, rendering nothing");
  const Command frame = add_bench_frame(*bench), seeds = add_bench_seeds(*bench);
  return {bench, [a, frame, seeds] { return frame.sub->parsed() ? frame.run() : seeds.sub->parsed() ? seeds.run() : run(*a); }};
}

}  // namespace haze::app
