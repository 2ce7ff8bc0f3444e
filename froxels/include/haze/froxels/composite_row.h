// The CPU composite's row kernel (composite_froxels, froxels.h, splits an image's rows over
// threads), in float32 with Highway runtime dispatch, beside its scalar reference. ISA-free
// header: per-target code in src/composite-inl.h. Per pixel: its column and slice in vectors over
// pixels, then its eight taps (two slices' bilinear four) as four-float vectors, one broadcast
// weight and one FMA each for L_in and T.
#pragma once

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::froxels_detail {

// The froxels as floats (L_in and T, three per froxel, slice-major) and the float32 lookup:
// slice(d) = slices_per_log (log d - log_near) - 1 past near.
struct CompositeVolume {
  const float* inscatter;
  const float* transmittance;
  int nx, ny, nz;
  float near, log_near, slices_per_log;
};
// One row of pixels: colour and out pixels `channels` floats apart (3 or 4; a fourth is left as
// it is), depth one float per pixel; row py of an image `height` rows tall.
struct CompositeRow {
  const float* colour;
  int colour_channels;
  const float* depth;
  float* out;
  int out_channels;
  int width, height, py;
  const float* colour_ahead = nullptr;  // the next row's colour and depth, fetched ahead (null: none)
  const float* depth_ahead = nullptr;
};

void composite_row(const CompositeVolume& volume, const CompositeRow& row);
void composite_row_reference(const CompositeVolume& volume, const CompositeRow& row);

}  // namespace haze::froxels_detail

#pragma GCC visibility pop
