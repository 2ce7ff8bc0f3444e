// The binary grid file of a scene's grid density (docs/SCENES.md, "grid"): float32 little-endian,
// x fastest, its size checked against the resolution before it is read.
#pragma once

#include "json_object.h"

#include <haze/core/medium.h>

namespace haze::internal {

// The density object `o` ({"type": "grid", "resolution": [nx, ny, nz], "file": ...}) read, its
// file resolved against base_dir. Its samples' ranges are check_medium's.
GridDensity read_grid(const Object& o, const fs::path& base_dir);

}  // namespace haze::internal
