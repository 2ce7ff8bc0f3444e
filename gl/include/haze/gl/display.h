// Hardware ray-march display: a scene's fields, computed on the CPU, in GL textures, marched by a
// fullscreen-triangle GLSL fragment shader into an offscreen float framebuffer and read back.
// The shader evaluates the CPU marchers' estimator (grids/propagation.h, seed 003 eq. 8-10):
// per step of a camera ray inside the volume,
//   L += T albedo_1 (1 - e^(-sigma_t' rho dt)) sum_l p(wi . wo) E_l e^(-sigma_t depth_l)
//      + T albedo' (1 - e^(-sigma_t' rho dt)) sum_k c_k(wo) m_k        (when a DOM solution is shown)
//      + T L_e (1 - e^(-sigma_t' rho dt)) / (sigma_t' rho)           (an emitting medium)
// then surfaces (lit through the depth volumes inside the grid, a DDA walk through the density
// outside it, shadowed by each other; with a DOM solution that carries surface texels, plus
// (kd + ks) / pi times their irradiance, as render_dom with surface_view "texels") and the
// background through T. Without a DOM solution sigma_t' = sigma_t and
// albedo_1 = albedo; with one, the delta-M scaled values of render_dom (grids/dom.h).
#pragma once

#include <haze/core/image.h>
#include <haze/core/scene.h>
#include <haze/gl/texture.h>
#include <haze/grids/dom.h>
#include <haze/grids/propagation.h>
#include <haze/grids/solution.h>

#include <memory>
#include <span>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::gl {

struct DisplaySettings {
  double step_cells = 0.5;                   // ray-march step, as MarchSettings::step_cells
  TexelFormat format = TexelFormat::float32;  // of the density, depth and moment textures
};

class VolumeDisplay {
 public:
  static constexpr int kMaxLights = 16, kMaxSurfaces = 16;

  // Needs a current HeadlessContext on the calling thread for its lifetime. Uploads the volume's
  // density and the depth volumes (depths[i] for the i-th point, spot or directional light of the
  // scene; a sky light adds its radiance to the background, as render_dom does), four lights to an
  // RGBA texture. Throws haze::Error for mismatched sizes, more than kMaxLights lights or
  // kMaxSurfaces surfaces, or a shader the driver rejects (with its log).
  VolumeDisplay(const Scene& scene, const grids::ExtinctionVolume& volume, const std::vector<grids::DenseGrid>& depths,
                const DisplaySettings& settings = {});
  // A grid method's solution (propagation, dom or any other GridSolution): its scene, volume and
  // depths, its march step, and its DOM moments when it has them (settings.step_cells ignored).
  explicit VolumeDisplay(const grids::GridSolution& solution, DisplaySettings settings = {});
  ~VolumeDisplay();
  VolumeDisplay(const VolumeDisplay&) = delete;
  VolumeDisplay& operator=(const VolumeDisplay&) = delete;

  // Adds the multiple-scattering term of a DOM solution of the same volume (its moments as 3D
  // textures) and switches to its delta-M scaled coefficients; its surface texels (DomSolution::
  // surfaces), when it has them, light the surfaces with the medium's and each other's light.
  void show_dom(const grids::DomSolution& solution);

  // New values computed on the CPU: the whole field, or only the bricks that changed.
  void update_density(const grids::DenseGrid& density, std::span<const Brick> bricks = {});
  void update_depths(const std::vector<grids::DenseGrid>& depths, std::span<const Brick> bricks = {});

  // Draws the camera's view into the framebuffer and waits for GL to finish (no read-back).
  void draw(const Camera& camera);
  // draw() and the framebuffer read back (rows top to bottom, as the CPU renderers write them).
  Image render(const Camera& camera);

  const Texture& density() const;
  std::vector<const Texture*> textures() const;  // every texture the shader reads

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace haze::gl

#pragma GCC visibility pop
