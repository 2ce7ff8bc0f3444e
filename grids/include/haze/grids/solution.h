// The solutions of the grid methods (propagation, dom): their fields on the extinction volume's
// cells, for the GL display and for callers who shade their own surfaces (solution.h in core).
#pragma once

#include <haze/core/solution.h>
#include <haze/grids/dom.h>
#include <haze/grids/propagation.h>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::grids {

class GridSolution : public MethodSolution {
 public:
  const Scene& scene() const { return scene_; }
  const ExtinctionVolume& volume() const { return volume_; }
  // The density integral from each cell to each point, spot or directional light, in the
  // scene's order of those lights (the sky has none); trilinear between cell centres.
  const std::vector<DenseGrid>& depths() const { return depths_; }
  // The DOM's moments; nullptr for single scattering.
  virtual const DomSolution* dom() const { return nullptr; }
  double step_cells() const { return step_cells_; }

  // exp(-sigma_t_scale * depth) toward the light, through the medium (surfaces not counted): at x
  // inside the grid, trilinear; outside, from where the segment to the light enters the grid (1
  // where it misses it).
  Rgb transmittance(size_t light, const Vec3& x) const override;
  // The unscattered light of every delta light (E e^-tau, 0 where a surface hides the light), plus, for the DOM, the diffuse
  // radiance's integral sum_k c_k m_k with c_k = sum_d w_d Q[d][k] (exact for the kept terms: the
  // constant is an eigenvector of the renormalized phase matrix).
  Rgb fluence(const Vec3& x) const override;
  // sum_lights p(w_light . w) E e^-tau, plus, for the DOM, (1 - f) sum_k c_k(w) m_k with c(w) from
  // inscatter_weights and f the delta-M fraction (the source sigma_s S of the scaled equation).
  Rgb inscattered(const Vec3& x, const Vec3& w) const override;

 protected:
  GridSolution(const Scene& scene, ExtinctionVolume volume, std::vector<DenseGrid> depths, double step_cells)
      : scene_(scene), volume_(std::move(volume)), depths_(std::move(depths)), step_cells_(step_cells) {}

  // The extinction volume of change.medium (`scene`, the changed scene): an RBF over the same
  // bounds with the same cutoff re-injects only the bricks in change.region, anything else is
  // made again (make_extinction_volume). Returns what was redone, for the UpdateReport.
  std::string replace_volume(const Scene& scene, const SceneChange& change, const CellCount& cells, double cutoff, int threads);
  // The depth volume of each point, spot and directional light of `scene`: every one after a new
  // density (`all`), else those that differ from scene_'s. Adds what it redid to the report.
  void update_depths(const Scene& scene, bool all, const DepthOptions& depth, UpdateReport& report);

  Scene scene_;
  ExtinctionVolume volume_;
  std::vector<DenseGrid> depths_;
  double step_cells_;

 private:
  // The index into depths_ of scene_.lights[light]; throws for the sky or an index out of range.
  size_t depth_index(size_t light) const;
  Rgb unscattered(size_t light, const Vec3& x, LightArrival& a) const;
};

}  // namespace haze::grids

#pragma GCC visibility pop
