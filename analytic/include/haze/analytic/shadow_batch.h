// LightShadows' tests (core/surface.h) over rows of rays and batches of points in float64 lanes,
// Highway runtime dispatch: which view stretches a point light lights all along, nowhere or in
// part, and which surface points see it. ISA-free header: per-target code in
// analytic/src/shadow_batch-inl.h; the scalar references are LightShadows' own.
#pragma once

#include <haze/core/surface.h>

#include <cstddef>
#include <utility>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::analytic {

// View stretches [t0, t1] of rays o + t d (structure of arrays, count rounded up to 16 long).
struct ShadowRays {
  const double* o[3];
  const double* d[3];
  const double* t0;
  const double* t1;
  size_t count;
};
// stretch[i] = 0, 1 or 2 where LightShadows::classify says lit, dark or partial (every stretch
// partial where the scene has a mesh).
void classify_stretches(const LightShadows& shadows, const ShadowRays& rays, float* stretch);
// visible[i] = 1 where LightShadows::hidden(x_i, self) is false, else 0 (x: count rounded up to 16 long).
void light_visible(const LightShadows& shadows, const double* const x[3], size_t count, const Surface* self, float* visible);

// lit_stretches (core/surface.h) for scenes of planes and spheres through LightShadows' constants:
// the same edges (the cones past their tangent circles), hidden() deciding between them; appended
// to `out`. A scene with a mesh takes lit_stretches itself.
void lit_pieces(const LightShadows& shadows, const Ray& ray, double t0, double t1, std::vector<std::pair<double, double>>& out);

}  // namespace haze::analytic

#pragma GCC visibility pop
