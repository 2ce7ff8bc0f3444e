// The temporal froxels' reprojection row kernel (haze/froxels/reproject_row.h) on every compiled
// target against its scalar reference: random volumes and rays, points behind the previous eye
// (clip w <= 0), outside the previous frustum, before near and past far, rows shorter and longer
// than a vector, the volume's last froxel tapped.
#include <haze/core/rng.h>
#include <haze/froxels/reproject_row.h>

#include <gtest/gtest.h>
#include <hwy/tests/hwy_gtest.h>

#include <cmath>
#include <vector>

// Outside namespace haze: Highway's macro names `testing::`, which haze::testing (the shared test
// scenes, beside this file in one unity build) would shadow.
namespace {

using haze::Rng;
using namespace haze::froxels_detail;

class ReprojectTargets : public hwy::TestWithParamTarget {};
HWY_TARGET_INSTANTIATE_TEST_SUITE_P(ReprojectTargets);

TEST_P(ReprojectTargets, RowKernelMatchesTheScalarReference) {
  Rng rng(33, 0);
  struct Shape {
    int nx, ny, nz;
  };
  for (const Shape s : {Shape{12, 7, 9}, Shape{1, 1, 1}, Shape{37, 5, 16}}) {
    const size_t froxels = static_cast<size_t>(s.nx * s.ny * s.nz);
    std::vector<float> L(3 * froxels), T(3 * froxels);
    for (size_t i = 0; i < L.size(); ++i) L[i] = static_cast<float>(rng.uniform()), T[i] = static_cast<float>(rng.uniform());
    const float near = 0.2f, far = 30.0f;
    const CompositeVolume volume{L.data(), T.data(), s.nx, s.ny, s.nz, near, std::log(near), static_cast<float>(s.nz / std::log(far / near))};
    // Columns: clip x, y within about twice the frustum, w mostly positive; eyes near and far.
    const auto n = static_cast<size_t>(s.nx);
    std::vector<float> columns(8 * n);
    for (size_t i = 0; i < n; ++i) {
      const auto u = [&](double lo, double hi) { return static_cast<float>(lo + (hi - lo) * rng.uniform()); };
      float* c = columns.data() + i;
      c[0] = u(-0.5, 0.5), c[n] = u(-0.5, 0.5), c[2 * n] = u(-0.3, 0.2), c[3 * n] = u(-1.5, 1.5), c[4 * n] = u(-1.5, 1.5), c[5 * n] = u(0.8, 1.2);
      c[6 * n] = u(0.0, 0.5), c[7 * n] = u(-1.0, 1.0);
    }
    const float* c = columns.data();
    size_t blended = 0;
    for (float distance : {0.05f, 0.3f, 2.0f, 29.0f, 80.0f})
      for (float keep : {0.9f, 0.5f}) {
        std::vector<float> row_l(3 * n), row_t(3 * n);
        for (size_t i = 0; i < row_l.size(); ++i) row_l[i] = static_cast<float>(rng.uniform()), row_t[i] = static_cast<float>(rng.uniform());
        std::vector<float> fast_l = row_l, fast_t = row_t, ref_l = row_l, ref_t = row_t;
        const auto row = [&](float* l, float* t) {
          return ReprojectRow{c, c + n, c + 2 * n, c + 3 * n, c + 4 * n, c + 5 * n, c + 6 * n, c + 7 * n, distance, keep, s.nx, l, t};
        };
        reproject_row(volume, row(fast_l.data(), fast_t.data()));
        reproject_row_reference(volume, row(ref_l.data(), ref_t.data()));
        for (size_t i = 0; i < ref_l.size(); ++i) {
          ASSERT_NEAR(fast_l[i], ref_l[i], 2e-5f) << s.nx << " x " << s.ny << " x " << s.nz << " at " << distance << ", froxel " << i / 3;
          ASSERT_NEAR(fast_t[i], ref_t[i], 2e-5f) << s.nx << " x " << s.ny << " x " << s.nz << " at " << distance << ", froxel " << i / 3;
          blended += ref_l[i] != row_l[i];
        }
      }
    EXPECT_GT(blended, 0u) << s.nx << " x " << s.ny << " x " << s.nz << ": no froxel blended";
  }
}

}  // namespace
