// Solve once, render many (docs/ARCHITECTURE.md, "The shape for callers"): what a method computes before it sees a camera,
// the views it renders, and the changes it can take without solving again.
#pragma once

#include <haze/core/camera.h>
#include <haze/core/image.h>
#include <haze/core/light.h>
#include <haze/core/medium.h>
#include <haze/core/progress.h>
#include <haze/core/scene.h>
#include <haze/core/surface.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

// The processes one solve is split over (docs/SCALING.md): haze::mpi::ranks wraps an MPI
// communicator as one.
class Ranks {
 public:
  virtual ~Ranks() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
};

struct RenderOptions {
  int threads = 0;  // 0: every core oneTBB offers; otherwise a cap
  // The method's settings ("name" ignored), read when a solution is prepared; a render takes
  // none (the solution keeps what it was prepared with).
  nlohmann::json settings = nlohmann::json::object();
  ProgressCallback progress;  // optional; return false to cancel (the call throws haze::Cancelled)
  // Where methods may keep precomputed tables between runs; empty: build them every time. The
  // `haze` command passes default_cache_dir().
  std::filesystem::path cache_dir;
  // The solution will render the scene's own camera only (haze::render sets this): a
  // single-scattering method may then leave out the lights that camera cannot see, and rendering
  // another camera is an error.
  bool single_view = false;
  // Bytes a method may allocate for its solution, checked before it allocates (a haze::Error
  // naming what would not fit); 0: the memory the system has available.
  std::size_t max_memory = 0;
  // Null: this process alone. Else every rank prepares, renders and updates alike (collective
  // calls, the same arguments) through the method's form split over them (register_split;
  // haze::mpi registers dom's), whose renders return the image on rank 0 and an empty result on
  // the others; max_memory then caps each rank. A method without a split form is refused when
  // there is more than one rank.
  std::shared_ptr<const Ranks> ranks = nullptr;
};

// $HAZE_CACHE_DIR, else $XDG_CACHE_HOME/haze, else $HOME/.cache/haze, else the temporary directory.
std::filesystem::path default_cache_dir();

// What a solution renders: a camera (Haze's own, or a host's matrices or rays, camera.h), and
// optionally the host's depth buffer and a request for the layers a host composites.
struct View {
  Camera camera;
  // Empty, or per pixel (row-major, rows top to bottom: width_px * height_px values) the distance
  // along the pixel's ray to the host's opaque geometry, +inf where there is none. The ray ends
  // there (or at a nearer surface of Haze's own), and no background is added behind it. Viewed,
  // not copied: it must outlive the render.
  std::span<const float> depth = {};
  // Render the layers (RenderResult::inscatter, transmittance, surface) beside the image.
  bool layers = false;

  // The distance the pixel's ray may go: its depth, or +inf.
  double max_distance(int x, int y) const {
    return depth.empty() ? kInfinity : static_cast<double>(depth[static_cast<size_t>(y) * static_cast<size_t>(camera.width_px) + static_cast<size_t>(x)]);
  }
};

// A pixel's light as a host composites it (docs/HOST.md): the radiance scattered toward
// the camera along the ray up to its end (`inscatter`, L_in), the ray's transmittance to its end
// (T), and the radiance leaving its end toward the camera (C: Haze's own surface, shaded, or the
// background; 0 where the host's depth ends it). The image is L_in + T C.
struct PixelLayers {
  Rgb inscatter{0.0}, transmittance{1.0}, surface{0.0};
  Rgb radiance() const { return inscatter + transmittance * surface; }
};

// L_in and T at distances along a view's rays in float32, slice-major as froxels hold them:
// [k * rays + ray] for distance k and ray = y * width_px + x (Solution::render_distances).
struct DistanceLayers {
  std::span<Vec3f> inscatter, transmittance;
  // Where > 0, a method may leave out of these layers each point light's in-scatter near its
  // direction, within this angle (radians) of it, for MethodSolution::add_glow to add per pixel
  // (the glow of a light in view is narrower than a froxel column).
  double glow_angle = 0.0;
};

// Per-pixel layers into the caller's memory (Solution::render_layers): float32 RGB or RGBA rows of
// the view's size, any stride (a GL pixel-buffer upload takes them as they are); `surface` may be
// left empty (no data) when the caller has no use for it.
struct LayerSpans {
  ImageSpan inscatter, transmittance, surface;
};

struct RenderResult {
  Image radiance;
  std::optional<Image> std_error;                   // per-pixel standard error, for Monte Carlo methods
  nlohmann::json stats = nlohmann::json::object();  // method-specific figures for --json
  // With View::layers: L_in, T and C per pixel (PixelLayers), radiance = inscatter + transmittance * surface.
  std::optional<Image> inscatter = std::nullopt, transmittance = std::nullopt, surface = std::nullopt;

  // A result for `view`: the image, and the layers when it asks for them.
  static RenderResult for_view(const View& view);
  // Pixel (x, y): the image's radiance, and the layers when there are any.
  void set(int x, int y, const PixelLayers& pixel);
};

// What a prepared method's renderer needs of `scene` seen from `camera`: its lights, surfaces,
// background and directory, without the medium (which the solution holds in its own form, and
// which a render need not copy).
Scene view_scene(const Scene& scene, const Camera& camera);

// What changed since a solution was prepared (or last updated); unset fields are unchanged.
struct SceneChange {
  std::optional<MediumDesc> medium = std::nullopt;  // the new medium: density, coefficients, phase
  // Where the new medium's density differs from the old one (world space); unset: anywhere. A
  // hint: a method that cannot use it redoes the whole density.
  std::optional<Aabb> region = std::nullopt;
  std::optional<std::vector<Light>> lights = std::nullopt;
  std::optional<std::vector<Surface>> surfaces = std::nullopt;
};

// What an update redid, in words a caller can log ("optical depth of lights[1]", "moments: 2
// sweeps from the previous solution"), with the method's figures.
struct UpdateReport {
  bool rebuilt = false;  // nothing could be reused: the solution was prepared again
  std::vector<std::string> redone;
  double seconds = 0.0;
  nlohmann::json stats = nlohmann::json::object();
};

// What a method prepares: implemented by each method, held by a Solution. Views and options come
// checked; lights are the kept ones (light_culling.h), indexed as in the scene the method saw.
class MethodSolution {
 public:
  virtual ~MethodSolution() = default;
  // The scene's medium, lights and surfaces as prepared, seen from view.camera.
  virtual RenderResult render(const View& view, const RenderOptions& options) const = 0;
  // Whether render honours View::depth and View::layers; a method that does not is refused such
  // views with a haze::Error (every method Haze registers does).
  virtual bool renders_layers() const { return false; }
  // L_in and T along each of the view's rays to each of `distances` (ascending, > 0), into `out`
  // (every entry written; its size checked by the caller), in one pass; false where the method has
  // no such path for this scene (Solution::render_distances then renders once per distance).
  virtual bool render_distances(const View&, std::span<const double>, const RenderOptions&, DistanceLayers /*out*/) const { return false; }
  // The view's layers per pixel into `out` (spans checked by the caller), in one pass that
  // allocates nothing once warm; false where the method has no such path for this scene
  // (Solution::render_layers then renders and copies).
  virtual bool render_layers(const View&, LayerSpans /*out*/, const RenderOptions&) const { return false; }
  // Adds to `out` (the view's pixels) what render_distances left out for `glow_angle`: per pixel,
  // the near share of each point light's in-scatter along the ray up to its end (view.depth or
  // the medium's). A method that leaves nothing out adds nothing, the default.
  virtual void add_glow(const View&, double /*glow_angle*/, ImageSpan /*out*/, const RenderOptions&) const {}
  // Applies `change` in place, given `scene` with the change applied, and reports what it redid;
  // std::nullopt when nothing can be reused (the Solution then prepares again). The default.
  virtual std::optional<UpdateReport> update(const Scene& scene, const SceneChange& change, const RenderOptions& options);

  // Fields for callers who shade their own surfaces, at world points, per RGB channel. A method
  // without them throws haze::Error naming the field. Light indices are the method's own.
  // Transmittance exp(-tau) from x to the light.
  virtual Rgb transmittance(size_t light, const Vec3& x) const;
  // Fluence phi(x) = integral over the sphere of the radiance the method carries at x (W/m^2 for
  // W/(m^2 sr) radiance): the unscattered light of point, spot and directional lights plus, in
  // multiple-scattering methods, the light scattered at least once.
  virtual Rgb fluence(const Vec3& x) const;
  // In-scattered radiance toward the propagation direction w per unit scattering coefficient:
  // S(x, w) = integral p(wi . w) L(x, wi) dwi, so that a host's ray march adds sigma_s(x) S ds.
  virtual Rgb inscattered(const Vec3& x, const Vec3& w) const;

  // The solution whose fields these are: itself, or for a method that delegates (auto) the
  // chosen method's.
  virtual const MethodSolution& fields_owner() const { return *this; }

  // What prepare computed and measured (merged into every render's stats).
  nlohmann::json stats = nlohmann::json::object();
};

}  // namespace haze

#pragma GCC visibility pop
