// Dispatch and scalar reference of eye_cells_row (haze/grids/eye_cells.h; Highway skeleton layout).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "eye_cells.cc"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include "eye_cells-inl.h"

#include <hwy/highway.h>

#if HWY_ONCE
#include <algorithm>
#include <cmath>

namespace haze::grids {

HWY_EXPORT(EyeCellsRowKernel);

void eye_cells_row(const EyeCellsRow& row) { HWY_DYNAMIC_DISPATCH(EyeCellsRowKernel)(row); }

// One cell at a time, the kernel's float32 formulas.
void eye_cells_row_reference(const EyeCellsRow& row) {
  const int side = row.side;
  const float half = 0.5f * static_cast<float>(side);
  for (int x = 0; x < row.count; ++x) {
    const float dx = row.x0 + static_cast<float>(x) * row.dx;
    const float n = std::abs(dx) + (std::abs(row.dy) + std::abs(row.dz));
    float u = dx / n, v = row.dy / n;
    if (row.dz < 0.0f) {  // the lower hemisphere folded out
      const float fu = std::copysign(1.0f - std::abs(v), u), fv = std::copysign(1.0f - std::abs(u), v);
      u = fu, v = fv;
    }
    const float fs = std::clamp((u + 1.0f) * half - 0.5f, 0.0f, static_cast<float>(side - 1));
    const float ft = std::clamp((v + 1.0f) * half - 0.5f, 0.0f, static_cast<float>(side - 1));
    const int s0 = std::min(static_cast<int>(fs), side - 2), t0 = std::min(static_cast<int>(ft), side - 2);
    const float a = fs - static_cast<float>(s0), b = ft - static_cast<float>(t0);
    const float w00 = (1.0f - a) * (1.0f - b), w10 = a * (1.0f - b), w01 = (1.0f - a) * b, w11 = a * b;
    const auto stride = static_cast<size_t>(row.stride);
    const float* p00 = row.table + (static_cast<size_t>(t0) * static_cast<size_t>(side) + static_cast<size_t>(s0)) * stride;
    const float* p10 = p00 + stride;
    const float* p01 = p00 + static_cast<size_t>(side) * stride;
    const float* p11 = p01 + stride;
    for (int ch = 0; ch < row.channels; ++ch) {
      const float* m = row.moments[ch] + static_cast<size_t>(x) * static_cast<size_t>(row.terms);
      float j = 0.0f;
      for (int k = 0; k < row.terms; ++k) j += (w00 * p00[k] + w10 * p10[k] + w01 * p01[k] + w11 * p11[k]) * m[k];
      row.out[ch][x] = row.scale[ch] * std::max(0.0f, j);
    }
  }
}

}  // namespace haze::grids
#endif  // HWY_ONCE
