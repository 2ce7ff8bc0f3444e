// Internal: dom's froxels through the propagation marcher's SIMD kernel (march_distances with
// MarchScattered): the moments' scattered light toward one eye as a radiance per cell, made each
// frame from a table of the in-scatter weights over directions.
#pragma once

#include <haze/grids/dom.h>

#include <vector>

namespace haze::grids::dom {

class TowardEye {
 public:
  // The in-scatter weights c(-w) (inscatter_weights) over kSide x kSide directions w of an
  // octahedral map, made once per solution's factorization (kept over updates that keep it).
  explicit TowardEye(const DomSolution& solution);
  // Whether the table holds `solution`'s weights: it was made from the same directions and phase.
  bool made_for(const DomSolution& solution) const { return &solution == &solution_ && solution.separable == separable_; }
  // Per cell of the solution's grid (`density`'s resolution and bounds) and channel:
  // scale[c] max(0, c(-w) . m_c), w the unit direction from `eye` to the cell's centre (c(-w)
  // bilinear in the table), into out[c * cells + cell] (kept by the caller), on the threads: rows
  // of cells through eye_cells_row (haze/grids/eye_cells.h).
  void fill(const DenseGrid& density, const Vec3& eye, const Rgb& scale, std::vector<float>& out, int threads) const;
  int channels() const { return solution_.channels; }

  // The map's side: its directions about 0.9 degrees apart, c bilinear between them (the froxels
  // made with it are within 0.4% of the gather's layers at 12^3: tests/methods/froxels_test.cpp).
  static constexpr int kSide = 128;

 private:
  const DomSolution& solution_;
  std::shared_ptr<const SeparablePhase> separable_;  // the factorization the table was made from
  int stride_;  // terms rounded up to 16 (EyeCellsRow::stride)
  std::vector<float> table_;  // [(v * kSide + u) * stride_ + k], zeros past terms
};

}  // namespace haze::grids::dom
