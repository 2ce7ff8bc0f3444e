// The discrete-ordinate row sweep on every compiled Highway target against its scalar reference.
#include <haze/core/rng.h>
#include <haze/grids/dom_sweep.h>

#include <gtest/gtest.h>
#include <hwy/tests/hwy_gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cmath>
#include <cstdint>
#include <vector>

namespace haze::grids {
namespace {

class DomSweep : public hwy::TestWithParamTarget {};
HWY_TARGET_INSTANTIATE_TEST_SUITE_P(DomSweep);

// Random octant data (P = 8, 24 and 40 directions: one, three and five vectors of 8; N = 5, 24,
// 33 terms), a row of 13 cells in both sweep orders and both spatial schemes, with and without the first-collision source
// (in float32 or, scaled, in float16) and the incoming moments; the diamond bounded everywhere,
// nowhere, and with the fix-up marking cells. Every output (the moments added to, the upwind values carried on)
// within 1e-5 relative (plus 1e-6 of the largest) of the reference: FMA and summation order differ; the same cells marked.
TEST_P(DomSweep, MatchesScalarReferenceOnEveryTarget) {
  Rng rng(3);
  long marked = 0;
  auto fill = [&](std::vector<float>& v, float lo, float hi) {
    for (float& e : v) e = lo + (hi - lo) * static_cast<float>(rng.uniform());
  };
  for (int p : {8, 24, 40})
    for (int n : {5, 24, 33})
      for (int step : {1, -1})
        for (int case_ = 0; case_ < 72; ++case_) {  // first: none, float32, float16; m_in: no, yes; step, diamond; slopes: no, yes
          const int sources = case_ % 12;
          const int bounds = case_ / 24;  // the diamond's bound everywhere; with the fix-up; nowhere
          if (bounds > 0 && sources < 6) continue;  // step
          const int np = (n + 7) / 8 * 8, count = 13, cells = 20;
          const auto up = static_cast<size_t>(p);
          std::vector<float> a(5 * up), lq(static_cast<size_t>(n) * up), q(up * static_cast<size_t>(np), 0.0f);
          fill(a, 0.0f, 3.0f), fill(lq, -0.2f, 0.3f);
          for (size_t d = 0; d < up; ++d) {
            a[3 * up + d] = a[d] + a[up + d] + a[2 * up + d];
            a[4 * up + d] = 0.0f;
            for (int k = 0; k < n; ++k) q[d * static_cast<size_t>(np) + static_cast<size_t>(k)] = static_cast<float>(rng.uniform()) - 0.5f;
          }
          const DomOctant octant{p, n, np, a.data(), lq.data(), q.data(), sources >= 6, {1.0f, step > 0 ? 1.0f : -1.0f, -1.0f}};
          std::vector<float> density(cells), first(static_cast<size_t>(cells) * up), m_in(static_cast<size_t>(cells * n));
          std::vector<float> slope(3 * static_cast<size_t>(cells));
          fill(density, 0.0f, 4.0f), fill(first, 0.0f, 1.0f), fill(m_in, 0.0f, 2.0f), fill(slope, -2.0f, 2.0f);
          std::vector<simd::Half> first_half(first.size());
          simd::to_half_reference(first.data(), first_half.data(), first.size());
          std::vector<float> first_scale(density.size());
          fill(first_scale, 0.5f, 3.0f);
          density[3] = 0.0f;  // an empty cell: pure transport
          std::vector<float> state[2];  // m_out, x_run, y_row, z_row, one after another
          for (auto& s : state) {
            s.resize(static_cast<size_t>(cells * n) + up + 2 * static_cast<size_t>(count) * up);
            Rng same(9);
            for (float& e : s) e = static_cast<float>(same.uniform());
          }
          std::vector<std::uint8_t> marks[2] = {std::vector<std::uint8_t>(8 * static_cast<size_t>(cells)),
                                                std::vector<std::uint8_t>(8 * static_cast<size_t>(cells))};
          for (int which = 0; which < 2; ++which) {
            float* base = state[which].data();
            std::vector<float> scratch(4 * up + static_cast<size_t>(np));
            DomRow row;
            row.count = count, row.step = step, row.x0 = step > 0 ? 0 : count - 1;
            row.cell0 = static_cast<size_t>(3 + row.x0);
            row.density = density.data(), row.sigma_t_scale = 1.7f, row.albedo = 0.9f;
            row.first = sources % 3 == 1 ? first.data() : nullptr, row.first_stride = up;
            row.first_half = sources % 3 == 2 ? first_half.data() : nullptr, row.first_scale = first_scale.data();
            row.m_in = sources % 6 >= 3 ? m_in.data() : nullptr;
            row.first_slope = case_ % 24 >= 12 ? slope.data() : nullptr;
            if (bounds > 0) row.bounded = marks[which].data(), row.mark = bounds == 1;
            row.m_out = base;
            row.x_run = base + cells * n;
            row.y_row = row.x_run + up, row.z_row = row.y_row + static_cast<size_t>(count) * up;
            row.scratch = scratch.data();
            (which == 0 ? dom_sweep_row : dom_sweep_row_reference)(octant, row);
          }
          const float peak = *std::max_element(state[1].begin(), state[1].end());
          for (size_t i = 0; i < state[0].size(); ++i)
            ASSERT_NEAR(state[0][i], state[1][i], 1e-5f * std::abs(state[1][i]) + 1e-6f * peak)
                << "P " << p << " N " << n << " step " << step << " case " << case_ << " at " << i << " target "
                << hwy::TargetName(GetParam());
          ASSERT_EQ(marks[0], marks[1]) << "P " << p << " N " << n << " step " << step << " case " << case_;
          marked += std::count(marks[0].begin(), marks[0].end(), 1);
        }
  EXPECT_GT(marked, 100);  // the fix-up's path is taken
}

// A separable first-collision source (DomRow::first_rows, suns only) is the source it stands for,
// sum_l factor[cell][l] rows[l][d] given whole, on every target and in the reference (the diamond
// with slopes and the step; 1e-5 relative: summation order).
TEST_P(DomSweep, SeparableFirstCollisionIsTheSourceItStandsFor) {
  Rng rng(5);
  auto fill = [&](std::vector<float>& v, float lo, float hi) {
    for (float& e : v) e = lo + (hi - lo) * static_cast<float>(rng.uniform());
  };
  for (const bool diamond : {false, true})
    for (int lights : {1, 2, 3}) {
      const int p = 24, n = 9, np = 16, count = 13, cells = 20;
      const auto up = static_cast<size_t>(p);
      std::vector<float> a(5 * up), lq(static_cast<size_t>(n) * up), q(up * static_cast<size_t>(np), 0.0f);
      fill(a, 0.0f, 3.0f), fill(lq, -0.2f, 0.3f), fill(q, -0.5f, 0.5f);
      for (size_t d = 0; d < up; ++d) a[3 * up + d] = a[d] + a[up + d] + a[2 * up + d], a[4 * up + d] = 0.0f;
      const DomOctant octant{p, n, np, a.data(), lq.data(), q.data(), diamond, {1.0f, 1.0f, -1.0f}};
      std::vector<float> density(cells), rows(static_cast<size_t>(lights) * up), factor(static_cast<size_t>(cells * lights)), m_in(static_cast<size_t>(cells * n));
      std::vector<float> slope(3 * static_cast<size_t>(cells));
      fill(density, 0.0f, 4.0f), fill(rows, 0.0f, 1.0f), fill(factor, 0.0f, 2.0f), fill(m_in, 0.0f, 2.0f), fill(slope, -2.0f, 2.0f);
      std::vector<float> whole(static_cast<size_t>(cells) * up, 0.0f);
      for (size_t c = 0; c < static_cast<size_t>(cells); ++c)
        for (size_t d = 0; d < up; ++d)
          for (size_t l = 0; l < static_cast<size_t>(lights); ++l) whole[c * up + d] += factor[c * static_cast<size_t>(lights) + l] * rows[l * up + d];
      std::vector<float> state[4];
      for (int which = 0; which < 4; ++which) {  // kernel and reference, whole and separable
        state[which].resize(static_cast<size_t>(cells * n) + up + 2 * static_cast<size_t>(count) * up);
        Rng same(9);
        for (float& e : state[which]) e = static_cast<float>(same.uniform());
        std::vector<float> scratch(4 * up + static_cast<size_t>(np));
        DomRow row;
        row.count = count, row.cell0 = 3, row.density = density.data(), row.sigma_t_scale = 1.7f, row.albedo = 0.9f;
        row.first_stride = up, row.m_in = m_in.data(), row.first_slope = diamond ? slope.data() : nullptr;
        if (which % 2 == 0) row.first = whole.data();
        else row.first_rows = rows.data(), row.first_factor = factor.data(), row.first_lights = lights;
        row.m_out = state[which].data();
        row.x_run = row.m_out + cells * n;
        row.y_row = row.x_run + up, row.z_row = row.y_row + static_cast<size_t>(count) * up;
        row.scratch = scratch.data();
        (which < 2 ? dom_sweep_row : dom_sweep_row_reference)(octant, row);
      }
      for (int which = 1; which < 4; ++which) {
        const float peak = *std::max_element(state[0].begin(), state[0].end());
        for (size_t i = 0; i < state[0].size(); ++i)
          ASSERT_NEAR(state[which][i], state[0][i], 1e-5f * std::abs(state[0][i]) + 1e-6f * peak)
              << (diamond ? "diamond" : "step") << ", " << lights << " lights, variant " << which << " at " << i << " target " << hwy::TargetName(GetParam());
      }
    }
}

// One cell and direction through the scalar reference: the radiance leaving through the faces
// `out` and the cell's mean, for entering radiance `in`, a_e = |w_e| / h_e, extinction sigma_t,
// albedo 1 and source s.
struct Cell {
  std::array<float, 3> out;
  float mean;
};
Cell one_cell(std::array<float, 3> a, std::array<float, 3> in, float sigma_t, float s, bool diamond = true,
              std::array<float, 3> slope = {0.0f, 0.0f, 0.0f}, std::uint8_t* bounded = nullptr, bool mark = false) {
  const float octant_a[5 * 8] = {a[0], 0, 0, 0, 0, 0, 0, 0, a[1], 0, 0, 0, 0, 0, 0, 0, a[2], 0, 0, 0, 0, 0, 0, 0,
                                 a[0] + a[1] + a[2], 1, 1, 1, 1, 1, 1, 1, 0, 1, 1, 1, 1, 1, 1, 1};
  const float lq[8] = {}, q[8 * 8] = {};  // lq [k * P + d], q [d * terms_padded + k] (ASan caught q[8])
  const DomOctant octant{8, 1, 8, octant_a, lq, q, diamond};
  float density = sigma_t, first[8] = {s}, m_out = 0.0f, x[8] = {in[0]}, y[8] = {in[1]}, z[8] = {in[2]}, scratch[40];
  DomRow row;
  row.count = 1, row.density = &density, row.albedo = 1.0f, row.first = first, row.first_stride = 8;
  row.m_out = &m_out, row.x_run = x, row.y_row = y, row.z_row = z, row.scratch = scratch;
  row.first_slope = slope.data();
  row.bounded = bounded, row.mark = mark;
  dom_sweep_row_reference(octant, row);
  return {{x[0], y[0], z[0]}, scratch[0]};
}

// A random cell from optically thin to 50 thick and a direction from along an axis to grazing:
// a_e, entering radiance (30% of faces dark), sigma_t (20% empty) and source (half 0).
struct RandomCell {
  std::array<float, 3> a, in;
  float sigma_t, s;
};
RandomCell random_cell(Rng& rng) {
  RandomCell c;
  for (float& e : c.a) e = static_cast<float>(3.0 * std::pow(rng.uniform(), 3.0));
  for (float& e : c.in) e = rng.uniform() < 0.3 ? 0.0f : static_cast<float>(rng.uniform());
  c.sigma_t = rng.uniform() < 0.2 ? 0.0f : static_cast<float>(50.0 * std::pow(rng.uniform(), 3.0));
  c.s = rng.uniform() < 0.5 ? 0.0f : static_cast<float>(rng.uniform());
  return c;
}

// The diamond scheme keeps the cell's balance sum_e a_e (out_e - in_e) + sigma_t L = sigma_s S
// and leaves no negative radiance (to float rounding, where the light all but dies in the cell),
// over random cells from optically thin to 50 thick and directions from along an axis to grazing:
// where the plain diamond (alpha = 1/2) would leave negative radiance on a minor axis. Half the
// cells take their source as linear, changing by up to twice its mean across the cell.
TEST(DomDiamond, BalancedAndPositive) {
  Rng rng(17);
  for (int i = 0; i < 20000; ++i) {
    const auto [a, in, sigma_t, s] = random_cell(rng);
    std::array<float, 3> slope{0.0f, 0.0f, 0.0f};
    if (i % 2)
      for (float& e : slope) e = static_cast<float>(4.0 * rng.uniform() - 2.0);
    const Cell c = one_cell(a, in, sigma_t, s, true, slope);
    const double sigma = sigma_t, mean = c.mean, source = s;
    double balance = sigma * mean - sigma * source, scale = sigma * mean + sigma * source + 1e-30;
    for (size_t e = 0; e < 3; ++e) {
      const double ae = a[e], out = c.out[e], entering = in[e];
      balance += ae * (out - entering), scale += ae * (std::abs(out) + entering);
      ASSERT_GE(c.out[e], -1e-6f * (in[0] + in[1] + in[2] + s)) << i << " axis " << e << ": sigma_t " << sigma_t << ", a " << a[0] << " "
                                                                << a[1] << " " << a[2];
    }
    ASSERT_GE(c.mean, 0.0f) << i;
    ASSERT_LT(std::abs(balance), 1e-5 * scale) << i << ": sigma_t " << sigma_t << ", a " << a[0] << " " << a[1] << " " << a[2];
  }
}

// The fix-up: over the same random cells, a cell is marked exactly where alpha(tau) alone would
// send radiance below 0, and then leaves what the bound everywhere leaves; an unmarked cell leaves
// what alpha(tau) alone leaves. Both happen often (the test is not vacuous).
TEST(DomDiamond, FixUpBoundsExactlyTheCellsThatGoNegative) {
  Rng rng(23);
  int marked = 0, kept = 0;
  for (int i = 0; i < 20000; ++i) {
    const auto [a, in, sigma_t, s] = random_cell(rng);
    std::uint8_t alone = 0, fixed = 0;
    const Cell bounded = one_cell(a, in, sigma_t, s), free = one_cell(a, in, sigma_t, s, true, {}, &alone),
               fix = one_cell(a, in, sigma_t, s, true, {}, &fixed, true);
    bool negative = false;
    for (size_t e = 0; e < 3; ++e) negative = negative || free.out[e] + kFixUpSlack * (in[0] + in[1] + in[2] + std::abs(free.mean)) < 0.0f;
    ASSERT_EQ(alone, 0) << i;  // no marks without `mark`
    ASSERT_EQ(fixed, negative ? 1 : 0) << i;
    const Cell& expected = negative ? bounded : free;
    for (size_t e = 0; e < 3; ++e) ASSERT_EQ(fix.out[e], expected.out[e]) << i << " axis " << e;
    ASSERT_EQ(fix.mean, expected.mean) << i;
    (negative ? marked : kept) += 1;
  }
  EXPECT_GT(marked, 500);
  EXPECT_GT(kept, 5000);
}

// Light crossing an absorbing slab along x (optical thickness 2 in n cells; the closed form is
// e^-2): the step scheme's error falls as 1 / n, the diamond's at least as 1 / n^2 (in 1D
// absorption its weight makes it third order: 1.5e-4 at 16 cells, 1.9e-5 at 32).
TEST(DomDiamond, SecondOrderAcrossAnAbsorber) {
  auto error = [](int n, bool diamond) {
    const float a = static_cast<float>(n) / 2.0f;  // |w_x| / h with h = 2 / n, sigma_t = 1
    float through = 1.0f;
    for (int i = 0; i < n; ++i) through = one_cell({a, 0.0f, 0.0f}, {through, 0.0f, 0.0f}, 1.0f, 0.0f, diamond).out[0];
    return std::abs(static_cast<double>(through) / std::exp(-2.0) - 1.0);
  };
  for (bool diamond : {false, true}) {
    const double e8 = error(8, diamond), e16 = error(16, diamond), e32 = error(32, diamond);
    std::printf("%s: transmission error %.2e, %.2e, %.2e at 8, 16, 32 cells\n", diamond ? "diamond" : "step", e8, e16, e32);
    if (diamond) {
      EXPECT_GT(e16 / e32, 3.5);
      EXPECT_LT(e32, 1e-4);
    } else {
      EXPECT_NEAR(e16 / e32, 2.0, 0.2);
    }
  }
}

}  // namespace
}  // namespace haze::grids
