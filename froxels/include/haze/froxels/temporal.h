// Froxels that are stable from frame to frame, as Frostbite, Unreal and HDRP keep theirs (Hillaire
// 2015, Wronski 2014; docs/HOST.md "Temporal stability"): each frame's slices end at boundaries
// offset by a jitter of up to half a slice, held as the unjittered boundaries', and are blended
// with the previous frame's froxels sampled at the same world points (reprojected), so that the
// history averages the jitter over each slice.
#pragma once

#include <haze/froxels/froxels.h>

#include <array>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

class TemporalFroxels {
 public:
  // The new frame's weight in the blend, in (0, 1]: froxel = blend * this frame's + (1 - blend)
  // * the previous frame's at the same world point. 1 keeps no history; 0.1 (the default)
  // settles in about 20 frames and cuts the jitter's flicker about 10x.
  double blend = 0.1;
  // Whether frame n's slices end at boundary(k + j_n), j_n in [-1/2, 1/2) from the R1 sequence
  // (frac(1/2 + n / golden ratio) - 1/2), held as boundary(k)'s: the lookups see the average over
  // the jitter once the history has settled.
  bool jitter = true;

  // This frame's froxels, built from `solution` for `camera` and blended with the history. The
  // history is the previous frame's where the froxel's centre was in the previous frustum; none
  // after reset(), a change of grid or image size, or a move of a camera that is not a pinhole or
  // a host's perspective matrices (orthographic and ray cameras blend only when still). After
  // the first frame nothing is allocated. Bad grids and blends are a haze::Error naming the field.
  const Froxels& build(const Solution& solution, const Camera& camera, const FroxelGrid& grid = {}, const RenderOptions& options = {});
  // The last frame's froxels.
  const Froxels& froxels() const { return frames_[current_]; }
  // A camera cut: the next frame starts without history.
  void reset() { frames_built_ = 0; }
  // The jitter of frame n, in slices.
  static double jitter_of(long long n);

 private:
  std::array<Froxels, 2> frames_;
  int current_ = 0;
  long long frames_built_ = 0, frame_ = 0;
  Camera camera_;  // the last frame's
  std::vector<float> columns_;  // the reprojection's per column (reproject_row.h)
};

}  // namespace haze

#pragma GCC visibility pop
