// What froxels.cpp shares with temporal.cpp.
#pragma once

#include <haze/froxels/froxels.h>

namespace haze::froxels_detail {

// The camera whose pixels are the grid's columns: the same frustum at nx x ny.
Camera column_camera(const Camera& camera, int nx, int ny);
// build_froxels with slice k ending at near (far / near)^((k + 1 + jitter) / nz).
void build(const Solution& solution, const Camera& camera, Froxels& out, const FroxelGrid& grid, double jitter, const RenderOptions& options);

}  // namespace haze::froxels_detail
