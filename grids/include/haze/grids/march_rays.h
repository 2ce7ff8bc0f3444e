// The ray marcher of method `propagation` (grids/propagation.h, seed 003 eq. 8-10) over packets of
// camera rays in float32 lanes, Highway runtime dispatch. ISA-free header: per-target code in
// src/march_rays-inl.h. Its reference is the float64 marcher in grids (MarchSettings::scalar).
//
// Per ray, steps s < steps of length dt from t0, at the midpoints x:
//   rho   = trilinear density, depth_l = trilinear optical depth to light l (cell-centred, clamped),
//   L_in  = sum_l p(to_light_l . dir) E_l(x) V_l e^(-sigma_t depth_l)   (V_l trilinear visibility, or 1)
//           + source(x) + folded(x)                                      (trilinear, where given),
//   L    += T albedo (1 - e^(-sigma_t rho dt)) L_in,   T *= e^(-sigma_t rho dt)   (per channel).
// The row's rays themselves from one eye (march_row_packet), and the lights folded in toward it
// per cell (march_toward_eye), are here too.
#pragma once

#include <haze/core/phase.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::grids {

struct MarchLight {
  enum Type { point, spot, directional } type = point;
  float position[3] = {0, 0, 0};  // point, spot
  float to_light[3] = {0, 0, 1};  // directional: unit vector toward the light
  float axis[3] = {0, 0, -1};     // spot: unit direction it shines along
  float intensity[3] = {1, 1, 1};  // I (point), I0 (spot), irradiance (directional)
  float cos_cone = 0.0f, exponent = 1.0f;  // spot: I0 cos^exponent(theta) where cos(theta) >= cos_cone
  int slot = 0;  // its depths and visibility: depths[cell * depth_stride + slot]
  int plane = -1;  // march_toward_eye: its plane of MarchVolume::attenuation, or -1
};

struct MarchVolume {
  int n[3] = {1, 1, 1};
  float lo[3] = {0, 0, 0}, h[3] = {1, 1, 1};
  const float* density = nullptr;  // x fastest
  const float* depths = nullptr;   // depths[cell * depth_stride + lights[l].slot]
  const float* visibility = nullptr;  // the same layout, in [0, 1] (surface shadows); null: 1
  const MarchLight* lights = nullptr;
  int light_count = 0;
  int depth_stride = 0;  // the lights packed per cell (pack_lights: all the scene's)
  float sigma_t[3] = {1, 1, 1}, albedo[3] = {1, 1, 1};
  int channels = 3;  // 1 where sigma_t, albedo and every light are grey: channel 0 only
  // A radiance per cell added to L_in, trilinear like the density (planes of cells,
  // [c * cells + cell], one channel for all or three; null: none): dom's scattered light from the
  // moments, with the lights' depths attenuated by sigma_t times depth_scale (its delta-M scaled
  // steps).
  const float* source = nullptr;
  int source_channels = 1;
  float depth_scale[3] = {1, 1, 1};
  // The depths and the source keep their slope into the outer half cells, clamped at 0 (dom's
  // gather), instead of the edge cells' values.
  bool outer = false;
  // The lights folded in toward an eye (march_toward_eye: cells of channels + 1 float16 values,
  // the channels' L_in and the density, each over its folded_scale, two to a 32-bit word, on the
  // grid with one ghost cell around the volume's), added to L_in where given and read between the
  // centres of the cells and the ghosts beside them in the outer half cells; with no light left in
  // the steps, the density is read from it too. folded_scale: channels 0 to 2, then the density.
  const uint32_t* folded = nullptr;
  float folded_scale[4] = {1, 1, 1, 1};
  // march_toward_eye: planes of cells, [plane * cells + cell], V e^(-sigma_t depth) of a grey
  // medium (PackedLights::attenuation), read for the lights with a plane instead of their depths.
  const float* attenuation = nullptr;
};

struct RayPacket {
  const float *ox, *oy, *oz, *dx, *dy, *dz;  // origin, unit direction
  const float *t0, *dt, *steps;              // first step's start, step length, step count (whole)
  size_t count;
  float* radiance[3];       // out, per channel (channels of the volume)
  float* transmittance[3];  // out, per channel
};

// The lights' part of L_in toward one eye, per cell: what march_rays evaluates at a step, at the
// cell's centre with w the unit vector from `eye` to it,
//   S(cell) = sum_l p(to_light_l . w) E_l V_l e^(-sigma_t depth_scale depth_l),
// for `count` point or directional lights (a spot's cone edge is left to the march; haze::Error),
// on the grid with one ghost cell around the volume's (a ghost's depths and visibility those of
// the cell beside it, as the march's clamped reads have them; MarchVolume::folded),
// prefiltered for trilinear reads: each cell less 1/12 of its second differences along the axes
// (linear interpolation's mean error over a cell, h^2 f'' / 12, taken back), at least 0. Into
// out (MarchVolume::folded's layout over volume.folded_scale: (channels + 1) / 2 words a cell,
// the channels then the cell's density, a ghost's the cell's beside it; (n + 2)^3 cells; float16
// values, 2^-11 relative, 0 below 2^-14 of their scale), on the threads; each worker's scratch
// (three planes) kept, so that a frame allocates nothing once it has grown.
void march_toward_eye(const MarchVolume& volume, const PhaseFunction& phase, const float eye[3], const MarchLight* lights, int count, uint32_t* out,
                      int threads);
// Its float64 reference, one cell at a time (phase.eval, std::exp): out[cell * (channels + 1) + c],
// the values themselves (no scale, no float16).
void march_toward_eye_reference(const MarchVolume& volume, const PhaseFunction& phase, const double eye[3], const MarchLight* lights, int count,
                                std::vector<double>& out);

// One image row of rays from one eye, pixel x's direction normalize(a + b (x + 0.5)) (Camera::
// row_frame), clipped to the box [lo, hi] and to the host's depth (null: none), in steps of
// `step`: into rows[r * stride + x] for pixels x < count, rows r = ox, oy, oz, dx, dy, dz, t0, dt,
// steps (steps 0 where the ray misses the box; rows padded to whole vectors), in float32 lanes.
// With `film`, ray x goes through a + b film[x] instead (any points of the row; `film` padded
// to whole vectors as the rows). The SIMD kernel's own packet rows, without a float64 ray per pixel.
struct RowFrame {
  float eye[3], a[3], b[3];
  float lo[3], hi[3];
  float step;
  const float* depth;  // the row's, or null
  const float* film;   // the rays' film x, or null: x + 0.5
};
void march_row_packet(const RowFrame& row, float* rows, size_t stride, size_t count);

// Three rows of `count` floats into RGB pixels, out[3 x + c] (the kernels' rows into a caller's span).
void march_interleave_rgb(const float* r, const float* g, const float* b, size_t count, float* out);

// False for phase functions the kernel cannot evaluate (tabulated): use the float64 marcher.
bool march_supported(const PhaseFunction& phase);
void march_rays(const MarchVolume& volume, const PhaseFunction& phase, const RayPacket& rays);

}  // namespace haze::grids

#pragma GCC visibility pop
