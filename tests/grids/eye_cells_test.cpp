// Dom's moments toward one eye, a row of cells at a time (eye_cells_row): the SIMD kernel on every
// compiled target against its scalar reference.
#include <haze/core/rng.h>
#include <haze/grids/eye_cells.h>

#include <gtest/gtest.h>
#include <hwy/tests/hwy_gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace haze::grids {
namespace {

class EyeCellsTargets : public hwy::TestWithParamTarget {};
HWY_TARGET_INSTANTIATE_TEST_SUITE_P(EyeCellsTargets);

// Random weights and moments, 9 and 25 terms (strides 16 and 32), one and three channels, rows of
// 1, 21 and 130 cells (no multiple of any vector's lanes) above and below the eye, crossing the
// map's fold and reaching its edges, the moments ending with the row (its last cells' vector
// loads would reach past them): within 1e-5 of the largest |c . m| (the dots' sums in another order).
TEST_P(EyeCellsTargets, MatchesTheScalarReference) {
  Rng rng(7, 3);
  constexpr int kSide = 16;
  for (int terms : {9, 25})
    for (int channels : {1, 3})
      for (int count : {1, 21, 130})
        for (float dz : {0.8f, -0.3f, 0.0f}) {
          const int stride = (terms + 15) / 16 * 16;
          std::vector<float> table(static_cast<size_t>(kSide * kSide * stride), 0.0f);
          for (int e = 0; e < kSide * kSide; ++e)
            for (int k = 0; k < terms; ++k) table[static_cast<size_t>(e * stride + k)] = static_cast<float>(rng.uniform() - 0.3);
          std::vector<std::vector<float>> moments(3, std::vector<float>(static_cast<size_t>(count * terms)));
          for (auto& m : moments)
            for (float& v : m) v = static_cast<float>(2.0 * rng.uniform() - 0.5);
          std::vector<std::vector<float>> out(3, std::vector<float>(static_cast<size_t>(count))), ref = out;
          const float* m[3] = {moments[0].data(), moments[1].data(), moments[2].data()};
          float* o[3] = {out[0].data(), out[1].data(), out[2].data()};
          float* r[3] = {ref[0].data(), ref[1].data(), ref[2].data()};
          const float scale[3] = {1.0f, 0.5f, 2.0f};
          EyeCellsRow row;
          row.table = table.data(), row.side = kSide, row.terms = terms, row.stride = stride;
          row.moments = m, row.readable = moments[0].size(), row.scale = scale, row.channels = channels;
          row.x0 = -1.3f, row.dx = 2.6f / static_cast<float>(count), row.dy = 0.4f, row.dz = dz, row.count = count;
          row.out = o;
          eye_cells_row(row);
          row.out = r;
          eye_cells_row_reference(row);
          for (int ch = 0; ch < channels; ++ch) {
            float largest = 1e-3f;
            for (float v : ref[static_cast<size_t>(ch)]) largest = std::max(largest, v);
            for (int x = 0; x < count; ++x)
              ASSERT_NEAR(out[static_cast<size_t>(ch)][static_cast<size_t>(x)], ref[static_cast<size_t>(ch)][static_cast<size_t>(x)], 1e-5f * largest)
                  << terms << " terms, channel " << ch << ", cell " << x << " of " << count << ", dz " << dz;
          }
        }
}

}  // namespace
}  // namespace haze::grids
