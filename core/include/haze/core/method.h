// Rendering methods and their registry. Each method (reference, analytic, propagation, dom,
// network, ...) registers itself under its scene-file name; `haze render --method` and the scene's
// "method" block pick one.
#pragma once

#include <haze/core/features.h>
#include <haze/core/image.h>
#include <haze/core/progress.h>
#include <haze/core/scene.h>
#include <haze/core/solution.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

// A method turns a scene into a solution (docs/ARCHITECTURE.md, "The shape for callers"); the
// solution renders views.
class Method {
 public:
  virtual ~Method() = default;
  // Everything that does not depend on the camera, from the scene and options.settings (checked:
  // unknown keys are an error). options.progress follows the work.
  virtual std::unique_ptr<MethodSolution> prepare(const Scene& scene, const RenderOptions& options) const = 0;
};

// One setting of a method, as validation, `haze render --help` and docs/METHODS.md read it.
struct SettingInfo {
  enum class Type { integer, number, choice, cells };  // cells: an integer, or three (per axis)
  std::string name;
  Type type = Type::integer;
  nlohmann::json fallback;  // the default; null when it follows from other settings (the doc says how)
  double min = 0.0, max = 0.0;       // integer and number: the accepted range
  std::vector<std::string> choices;  // choice: the accepted names
  std::string doc;                   // one line

  static SettingInfo integer(std::string name, nlohmann::json fallback, long long min, long long max, std::string doc);
  static SettingInfo number(std::string name, nlohmann::json fallback, double min, double max, std::string doc);
  static SettingInfo choice(std::string name, std::string fallback, std::vector<std::string> choices, std::string doc);
  static SettingInfo cells(std::string name, nlohmann::json fallback, long long min, long long max, std::string doc);
  // "integer in [2, 1024], default 64" and the like.
  std::string describe() const;
};

// What a method handles, for help, docs and callers choosing one.
struct MethodHandles {
  std::string media;     // e.g. "constant, RBF and grid densities (bounded)"
  std::string lights;    // e.g. "point, spot, directional"
  std::string surfaces;  // e.g. "planes and spheres lit by unscattered light, no shadows"
  bool multiple_scattering = false;
};

// What a method offers method "auto" for a scene: settings expected to meet the tolerance and
// their expected time (measured on the trade suite's closest scene), or why it declines.
struct AutoOffer {
  bool offered = false;
  nlohmann::json settings = nlohmann::json::object();
  double expected_seconds = 0.0;
  std::string why;  // one line: the measurement the offer rests on, or why not
};
using AutoRule = std::function<AutoOffer(const SceneFeatures& features, double tolerance)>;

// A measured point of a method's trade curve that an offer rests on: offered where the tolerance
// asked is at least `tolerance` (the error measured, with a margin).
struct MeasuredOffer {
  double tolerance = 0.0;
  nlohmann::json settings;
  double seconds = 0.0;  // measured, 2 threads
  std::string measured;  // the scene, the error, the settings and the date: "cloud_sun 3.3% at 16^3 (2026-12-02)"
};
// The first of `table` (cheapest first) that `tolerance` meets, its why "<what>: <measured>"; else
// declined, with `otherwise` as the why.
AutoOffer offer_from(std::span<const MeasuredOffer> table, double tolerance, const std::string& what, const std::string& otherwise);

struct MethodInfo {
  // What a method is to the tools that pick among methods (method auto, `haze demo`, `haze bench
  // trade`): one that solves, the unbiased reference every other is measured against, or one that
  // chooses another and delegates to it.
  enum class Role { solver, reference, chooser };

  std::string name;
  std::string summary;  // one line for `haze render --help` and error messages
  std::function<std::unique_ptr<Method>()> create;
  MethodHandles handles;
  std::vector<SettingInfo> settings;
  // The settings `haze bench trade` sweeps: those that trade time for error.
  std::vector<nlohmann::json> trade_sweep;
  // How the method bids for a scene in method "auto" (none: never chosen; the reference is the
  // fallback when nothing offers).
  AutoRule offer;
  // The image holds light scattered or reflected once only, at points the camera sees: a light
  // that reaches none of the view is left out too (light_culling.h).
  bool single_scattering = false;
  // Renders a medium's emission (MediumDesc::emission); haze::prepare refuses an emitting medium
  // to a method without it.
  bool emission = false;
  Role role = Role::solver;

  const SettingInfo* setting(const std::string& key) const;
};

// The method's settings for `haze render --help` (one line each) and as a markdown table.
std::string settings_help(const MethodInfo& info);
std::string settings_markdown(const MethodInfo& info);

// Reads a method's settings against its registered schema (MethodInfo::settings): a bad value, or
// a key the method never asked for, throws haze::Error naming "method.<key>", the value and the
// schema's range. A fallback given here replaces the schema's (a default that follows from
// other settings).
class Settings {
 public:
  Settings(const nlohmann::json& settings, const std::string& method);
  long long integer(const std::string& key);
  long long integer(const std::string& key, long long fallback);
  double number(const std::string& key);
  double number(const std::string& key, double fallback);
  std::string choice(const std::string& key);
  std::string choice(const std::string& key, const std::string& fallback);
  // A cells setting: {n} for an integer n, {nx, ny, nz} for an array of three, each in the range.
  std::vector<int> cells(const std::string& key);
  // Throws for any key not read.
  void reject_unknown() const;

 private:
  const SettingInfo& info(const std::string& key, SettingInfo::Type type);
  const nlohmann::json& settings_;
  MethodInfo method_;
  std::vector<std::string> known_;
};

// Adds a method; a second registration under the same name replaces the first.
void register_method(MethodInfo info);
// All registered methods, sorted by name (core's own are always there).
std::vector<MethodInfo> registered_methods();
// Throws haze::Error listing the available methods when the name is unknown.
std::unique_ptr<Method> create_method(const std::string& name);
// A module's form of `method` split over RenderOptions::ranks (haze::mpi: dom's), which
// haze::prepare makes in place of the method's own when the options give ranks; a second
// registration replaces the first.
void register_split(const std::string& method, std::function<std::unique_ptr<Method>()> create);
// The name of the registered method with this role (the first by name); haze::Error when none is.
std::string method_with_role(MethodInfo::Role role);

// A prepared method: render any camera without solving again, update it when the scene changes,
// read its fields. Made by haze::prepare; movable, not copyable.
class Solution {
 public:
  Solution(Solution&&) noexcept;
  Solution& operator=(Solution&&) noexcept;
  ~Solution();

  const std::string& method() const;
  // The scene as prepared, with every update applied (all of its lights, culled ones included).
  const Scene& scene() const;
  // What prepare (or the last update that rebuilt) computed and measured.
  const nlohmann::json& stats() const;

  // options: threads, progress (settings were fixed by prepare; giving any is an error).
  RenderResult render(const View& view, const RenderOptions& options = {}) const;
  // The view's layers (L_in, T and C, as render with view.layers gives them) written into the
  // caller's memory, reused frame after frame: the method's own path where it has one (analytic
  // with point lights and no surfaces of Haze's own; propagation's march; dom's gather without
  // surfaces or emission: no allocation once warm), else a render copied into it. Spans of
  // another size than the view's are a haze::Error naming them.
  void render_layers(const View& view, LayerSpans out, const RenderOptions& options = {}) const;
  RenderResult render(const RenderOptions& options = {}) const { return render(View{scene().camera}, options); }
  // L_in and T along each of the view's rays (its depth ignored; Haze's own surfaces still end
  // them) to each of `distances` (ascending, > 0), into the caller's `out` (width_px x height_px x
  // distances.size() entries each, slice-major), which a frame loop reuses. The method's one-pass
  // path where it has one (analytic with point lights and no surfaces; propagation; dom without
  // surfaces or emission; the marching ones step a stretch at distance d no finer than the
  // view's pixel_angle() d, the rays' spacing there), else one layered render per distance. What
  // build_froxels (froxels.h) calls.
  void render_distances(const View& view, std::span<const double> distances, DistanceLayers out, const RenderOptions& options = {}) const;
  // Adds to `out` (float32 RGB or RGBA rows of the view's size) what render_distances left out
  // when asked to for `glow_angle` (DistanceLayers::glow_angle): the glow of the point lights in
  // view, per pixel, along each ray up to view.depth (froxels.h's add_glow calls it).
  void add_glow(const View& view, double glow_angle, ImageSpan out, const RenderOptions& options = {}) const;
  // Redoes only what the change reaches (the method says what in the report); a change nothing
  // can be reused for prepares again (report.rebuilt). The scene's camera may change freely: it
  // is not part of a solution. A change that throws haze::Error (checked before anything is
  // redone: the medium, the lights a method cannot take) leaves the solution as it was.
  UpdateReport update(const SceneChange& change, const RenderOptions& options = {});

  // What the method prepared (MethodSolution::fields_owner: the chosen method's for auto), e.g.
  // for a display that reads a grid method's fields (grids::GridSolution). Its lights are the
  // kept ones.
  const MethodSolution& method_solution() const;

  // The method's fields (solution.h: MethodSolution), lights indexed as in scene().lights.
  Rgb transmittance(size_t light, const Vec3& x) const;
  Rgb fluence(const Vec3& x) const;
  Rgb inscattered(const Vec3& x, const Vec3& w) const;

  struct State;

 private:
  explicit Solution(std::unique_ptr<State> state);
  friend Solution prepare(const Scene&, const std::string&, RenderOptions);
  std::unique_ptr<State> state_;
};

// Prepares `method_name`, or the scene's method when empty. The scene's method settings apply
// when its name matches; options.settings override them key by key. A scene's particles block is
// its medium (density type "particles", which the particles module registers), so every method
// that takes its density renders particles. Lights that reach nothing (with options.single_view and a
// single-scattering method: nothing in view) are left out first (light_culling.h); the stats
// list them under "culled_lights".
Solution prepare(const Scene& scene, const std::string& method_name = "", RenderOptions options = {});
// The settings method `method_name` takes: the scene's method block when it names that method,
// then `given`'s keys over it ("name" dropped); haze::Error unless `given` is null or an object.
nlohmann::json method_settings(const Scene& scene, const std::string& method_name, const nlohmann::json& given);

// prepare() (with options.single_view) and render() of the scene's camera in a row; the stats hold
// both steps' figures.
RenderResult render(const Scene& scene, const std::string& method_name, RenderOptions options = {});
// The same for a view of the scene's camera with a host's depth buffer or layers (View).
RenderResult render(const Scene& scene, const std::string& method_name, RenderOptions options, const View& view);

}  // namespace haze

#pragma GCC visibility pop
