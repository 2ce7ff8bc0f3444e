// The composite's row kernel (haze/froxels/composite_row.h) on every compiled target against its
// scalar reference: random volumes, RGB and RGBA rows, depths before near, inside every slice,
// past far (the volume's last froxel tapped at the image's corner) and the background.
#include <haze/core/rng.h>
#include <haze/froxels/composite_row.h>

#include <gtest/gtest.h>
#include <hwy/tests/hwy_gtest.h>

#include <cmath>
#include <limits>
#include <vector>

// Outside namespace haze: Highway's macro names `testing::`, which haze::testing (the shared test
// scenes, beside this file in one unity build) would shadow.
namespace {

using haze::Rng;
using namespace haze::froxels_detail;

class CompositeTargets : public hwy::TestWithParamTarget {};
HWY_TARGET_INSTANTIATE_TEST_SUITE_P(CompositeTargets);

TEST_P(CompositeTargets, RowKernelMatchesTheScalarReference) {
  Rng rng(21, 0);
  struct Shape {
    int nx, ny, nz, w, h;
  };
  for (const Shape s : {Shape{12, 7, 9, 37, 23}, Shape{1, 1, 1, 5, 3}, Shape{16, 9, 12, 200, 9}}) {
    const size_t froxels = static_cast<size_t>(s.nx * s.ny * s.nz);
    std::vector<float> L(3 * froxels), T(3 * froxels);
    for (size_t i = 0; i < L.size(); ++i) L[i] = static_cast<float>(rng.uniform()), T[i] = static_cast<float>(rng.uniform());
    const float near = 0.2f, far = 30.0f;
    const CompositeVolume volume{L.data(), T.data(), s.nx, s.ny, s.nz, near, std::log(near), static_cast<float>(s.nz / std::log(far / near))};
    for (int channels : {3, 4}) {
      std::vector<float> colour(static_cast<size_t>(channels * s.w * s.h)), depth(static_cast<size_t>(s.w * s.h));
      for (float& c : colour) c = static_cast<float>(rng.uniform());
      for (size_t i = 0; i < depth.size(); ++i) {
        const double u = rng.uniform();
        depth[i] = u < 0.1 ? std::numeric_limits<float>::infinity() : u < 0.15 ? 0.5f * near : static_cast<float>(0.1 * std::pow(400.0, u));
      }
      depth.back() = 2.0f * far;
      std::vector<float> fast = colour, reference = colour;
      for (int py = 0; py < s.h; ++py) {
        const size_t row = static_cast<size_t>(py * s.w);
        composite_row(volume, {colour.data() + channels * row, channels, depth.data() + row, fast.data() + channels * row, channels, s.w, s.h, py});
        composite_row_reference(volume, {colour.data() + channels * row, channels, depth.data() + row, reference.data() + channels * row, channels,
                                         s.w, s.h, py});
      }
      for (size_t i = 0; i < fast.size(); ++i)
        ASSERT_NEAR(fast[i], reference[i], 2e-5f * std::max(1.0f, std::abs(reference[i])))
            << s.nx << " x " << s.ny << " x " << s.nz << ", " << channels << " channels, pixel " << i / static_cast<size_t>(channels);
    }
  }
}

}  // namespace
