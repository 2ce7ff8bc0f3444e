// Rendering methods and their registry. Each method (reference, analytic, propagation, dom,
// network, ...) registers itself under its scene-file name; `haze render --method` and the scene's
// "method" block pick one.
#pragma once

#include <haze/core/image.h>
#include <haze/core/progress.h>
#include <haze/core/scene.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace haze {

struct RenderOptions {
  int threads = 0;  // 0: every core oneTBB offers; otherwise a cap
  nlohmann::json settings = nlohmann::json::object();  // the method's settings ("name" ignored)
  ProgressCallback progress;  // optional; return false to cancel (render throws haze::Cancelled)
  // Where methods may keep precomputed tables between runs; empty: build them every time. The
  // `haze` command passes default_cache_dir().
  std::filesystem::path cache_dir;
};

// $HAZE_CACHE_DIR, else $XDG_CACHE_HOME/haze, else $HOME/.cache/haze, else the temporary directory.
std::filesystem::path default_cache_dir();

struct RenderResult {
  Image radiance;
  std::optional<Image> std_error;  // per-pixel standard error, for Monte Carlo methods
  nlohmann::json stats = nlohmann::json::object();  // method-specific figures for --json
};

class Method {
 public:
  virtual ~Method() = default;
  virtual RenderResult render(const Scene& scene, const RenderOptions& options) const = 0;
};

struct MethodInfo {
  std::string name;
  std::string summary;  // one line for `haze render --help` and error messages
  std::function<std::unique_ptr<Method>()> create;
  // The method reads the scene's `particles` block itself; any other method is given the
  // particles' continuous density as the scene's medium (register_particle_medium).
  bool reads_particles = false;
  // The image holds light scattered or reflected once only, at points the camera sees: a light
  // that reaches none of the view is left out too (light_culling.h).
  bool single_scattering = false;
};

// Turns a scene's `particles` block into a medium (the particle module registers one when its
// methods are registered: the particles' continuous density sampled on a grid). `settings` are the
// render's method settings, from which it may read (and must remove) its own keys.
using ParticleMediumFactory = std::function<MediumDesc(const Scene& scene, nlohmann::json& settings)>;
void register_particle_medium(ParticleMediumFactory factory);

// Reads a method's settings with validation: a bad value or a key the method never asked for
// throws haze::Error naming "method.<key>".
class Settings {
 public:
  Settings(const nlohmann::json& settings, std::string method);
  long long integer(const std::string& key, long long fallback, long long min, long long max);
  double number(const std::string& key, double fallback, double min, double max);
  // A string that must be one of `allowed`.
  std::string choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& allowed);
  // Throws for any key not read by integer() or number().
  void reject_unknown() const;

 private:
  const nlohmann::json& settings_;
  std::string method_;
  std::vector<std::string> known_;
};

// Adds a method; a second registration under the same name replaces the first.
void register_method(MethodInfo info);
// All registered methods, sorted by name (core's own are always there).
std::vector<MethodInfo> registered_methods();
// Throws haze::Error listing the available methods when the name is unknown.
std::unique_ptr<Method> create_method(const std::string& name);

// Renders with `method_name`, or the scene's method when empty. The scene's method settings
// apply when its name matches; options.settings override them key by key. A scene with particles
// and no medium renders with a method that does not read particles through the registered
// ParticleMediumFactory. Lights that reach nothing (for a single-scattering method: nothing in
// view) are left out first (light_culling.h); the result's stats list them under "culled_lights".
RenderResult render(const Scene& scene, const std::string& method_name, RenderOptions options = {});

}  // namespace haze
