// The discrete-ordinate row sweep on every compiled Highway target against its scalar reference.
#include <haze/core/rng.h>
#include <haze/simd/dom_sweep.h>

#include <gtest/gtest.h>
#include <hwy/tests/hwy_gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace haze::simd {
namespace {

class DomSweep : public hwy::TestWithParamTarget {};
HWY_TARGET_INSTANTIATE_TEST_SUITE_P(DomSweep);

// Random octant data (P = 8, 24 and 40 directions: one, three and five vectors of 8; N = 5, 24,
// 33 terms), a row of 13 cells in both sweep orders, with and without the first-collision source
// (in float32 or, scaled, in float16) and the incoming moments. Every output (the moments added to, the upwind values carried on)
// within 1e-5 relative (plus 1e-6 of the largest) of the reference: FMA and summation order differ.
TEST_P(DomSweep, MatchesScalarReferenceOnEveryTarget) {
  Rng rng(3);
  auto fill = [&](std::vector<float>& v, float lo, float hi) {
    for (float& e : v) e = lo + (hi - lo) * static_cast<float>(rng.uniform());
  };
  for (int p : {8, 24, 40})
    for (int n : {5, 24, 33})
      for (int step : {1, -1})
        for (int sources = 0; sources < 6; ++sources) {  // first: none, float32, float16; m_in: no, yes
          const int np = (n + 7) / 8 * 8, count = 13, cells = 20;
          const auto up = static_cast<size_t>(p);
          std::vector<float> a(4 * up), lq(static_cast<size_t>(n) * up), q(up * static_cast<size_t>(np), 0.0f);
          fill(a, 0.0f, 3.0f), fill(lq, -0.2f, 0.3f);
          for (size_t d = 0; d < up; ++d) {
            a[3 * up + d] = a[d] + a[up + d] + a[2 * up + d];
            for (int k = 0; k < n; ++k) q[d * static_cast<size_t>(np) + static_cast<size_t>(k)] = static_cast<float>(rng.uniform()) - 0.5f;
          }
          const DomOctant octant{p, n, np, a.data(), lq.data(), q.data()};
          std::vector<float> density(cells), first(static_cast<size_t>(cells) * up), m_in(static_cast<size_t>(cells * n));
          fill(density, 0.0f, 4.0f), fill(first, 0.0f, 1.0f), fill(m_in, 0.0f, 2.0f);
          std::vector<Half> first_half(first.size());
          to_half_reference(first.data(), first_half.data(), first.size());
          std::vector<float> first_scale(density.size());
          fill(first_scale, 0.5f, 3.0f);
          density[3] = 0.0f;  // an empty cell: pure transport
          std::vector<float> state[2];  // m_out, x_run, y_row, z_row, one after another
          for (auto& s : state) {
            s.resize(static_cast<size_t>(cells * n) + up + 2 * static_cast<size_t>(count) * up);
            Rng same(9);
            for (float& e : s) e = static_cast<float>(same.uniform());
          }
          for (int which = 0; which < 2; ++which) {
            float* base = state[which].data();
            std::vector<float> scratch(up + static_cast<size_t>(np));
            DomRow row;
            row.count = count, row.step = step, row.x0 = step > 0 ? 0 : count - 1;
            row.cell0 = static_cast<size_t>(3 + row.x0);
            row.density = density.data(), row.sigma_t_scale = 1.7f, row.albedo = 0.9f;
            row.first = sources % 3 == 1 ? first.data() : nullptr, row.first_stride = up;
            row.first_half = sources % 3 == 2 ? first_half.data() : nullptr, row.first_scale = first_scale.data();
            row.m_in = sources / 3 ? m_in.data() : nullptr;
            row.m_out = base;
            row.x_run = base + cells * n;
            row.y_row = row.x_run + up, row.z_row = row.y_row + static_cast<size_t>(count) * up;
            row.scratch = scratch.data();
            (which == 0 ? dom_sweep_row : dom_sweep_row_reference)(octant, row);
          }
          const float peak = *std::max_element(state[1].begin(), state[1].end());
          for (size_t i = 0; i < state[0].size(); ++i)
            ASSERT_NEAR(state[0][i], state[1][i], 1e-5f * std::abs(state[1][i]) + 1e-6f * peak)
                << "P " << p << " N " << n << " step " << step << " sources " << sources << " at " << i << " target "
                << hwy::TargetName(GetParam());
        }
}

}  // namespace
}  // namespace haze::simd
