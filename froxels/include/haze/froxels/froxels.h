// Froxels (frustum voxels; Wronski 2014, Hillaire 2015, docs/REFERENCES.md): a camera-aligned
// volume holding, per froxel, the in-scattered radiance L_in and the transmittance T accumulated
// from the camera to the froxel's far slice boundary. A host renders it once per frame and looks up
// every pixel's layers at the pixel's depth (trilinear), instead of Haze rendering every pixel:
// colour = L_in(d) + T(d) * host colour (docs/HOST.md). Built from any solution whose method
// renders layers (docs/HOST.md).
#pragma once

#include <haze/core/camera.h>
#include <haze/core/image.h>
#include <haze/core/method.h>

#include <span>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

// The volume's shape: nx x ny columns over the camera's image, nz slices in distance along each
// column's ray (not view-space z), exponential between near and far: slice k ends at
// near (far / near)^((k + 1) / nz). 160 x 90 x 64 suits a 16:9 1080p frame.
struct FroxelGrid {
  int nx = 160, ny = 90, nz = 64;
  double near = 0.1, far = 100.0;
  // 0: the froxels hold every light whole. Else each point light's glow, its in-scatter along the
  // rays within this many columns' angle of its direction, is left to add_glow per pixel, where
  // the method can (analytic with point lights; others hold it whole): a light in view glows
  // narrower than a column. In [0, 16] (the angle at most 0.5 radians); 4 suits 1080p.
  double glow_columns = 0.0;
  // Slice k's far boundary (k = -1: near).
  double boundary(int k) const;
  // The continuous slice coordinate of distance d: k at boundary(k), -1 at near and before.
  double slice(double d) const;
};

struct Froxels {
  FroxelGrid grid;
  double glow_angle = 0.0;  // grid.glow_columns as an angle from the eye (radians), what add_glow adds
  // [(k * ny + j) * nx + i]: L_in and T along column (i, j)'s ray from the camera to boundary(k)
  // (TemporalFroxels: to the frame's jittered boundary, held as boundary(k)'s). Column (i, j) is
  // the camera's ray through film position ((i + 0.5) W / nx, (j + 0.5) H / ny) of its W x H
  // image, rows top to bottom.
  std::vector<Vec3f> inscatter, transmittance;

  // The layers at film position (u, v) in [0, 1]^2 of the image (u across, v down) and distance d
  // along the ray: bilinear between column centres (clamped at the edges), linear in slice(d)
  // between boundaries; before near L_in = 0, T = 1 are taken at near; past far, far's values.
  PixelLayers sample(double u, double v, double d) const;
};

// Builds the froxels of `camera`'s view from `solution` (any method that renders layers) through
// Solution::render_distances: the method's one-pass path (analytic, propagation, dom), or one
// layered render of the nx x ny columns per slice with its boundary as the depth (the method's
// SIMD and threads do the work; options.progress then sees the slices). A camera of type `rays` is
// sampled at the columns' nearest pixels. Bad grids (a count below 1 or above 4096, near not in
// (0, far)) are a haze::Error naming `froxels.<field>`.
Froxels build_froxels(const Solution& solution, const Camera& camera, const FroxelGrid& grid = {}, const RenderOptions& options = {});
// The same into the caller's `out`, whose memory is reused when its grid's size is unchanged.
void build_froxels(const Solution& solution, const Camera& camera, Froxels& out, const FroxelGrid& grid = {}, const RenderOptions& options = {});

// The CPU form of the GLSL composite pass, what a renderer without a GPU runs each frame: per
// pixel of the host's colour, L_in(d) + T(d) * colour at its depth d (distance along the pixel's
// ray, row-major as the colour's pixels; +inf for the background: far's values then), written
// into `out` (the colour's size; it may be the colour's own memory, an RGBA pixel's fourth float
// left as it is). Float32 throughout, the rows split over `threads` (0: every core oneTBB
// offers); within 1e-5 relative of Froxels::sample's float64 lookup (tests/methods/froxels_test.cpp).
void composite_froxels(const Froxels& froxels, ConstImageSpan colour, std::span<const float> depth, ImageSpan out, int threads = 0);
// The same into a new image.
Image composite_froxels(const Froxels& froxels, const Image& host_colour, std::span<const float> depth, int threads = 0);

// Adds to the composite `out` what the froxels left out for grid.glow_columns: per pixel near
// each point light in view, its glow along the pixel's ray up to its depth, in closed form
// (Solution::add_glow; docs/HOST.md). `camera` and `solution` are the froxels'; nothing where
// glow_columns is 0 or the method holds every light whole. The GL pass does not add it yet.
void add_glow(const Solution& solution, const Camera& camera, const Froxels& froxels, std::span<const float> depth, ImageSpan out, int threads = 0);

}  // namespace haze

#pragma GCC visibility pop
