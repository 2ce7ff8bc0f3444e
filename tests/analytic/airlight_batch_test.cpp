// The batched airlight on every compiled target against its scalar reference, and the reference
// against the float64 table path.
#include <haze/core/camera.h>
#include <haze/core/rng.h>
#include <haze/analytic/airlight_batch.h>
#include <haze/analytic/surface_batch.h>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <gtest/gtest.h>
#include <algorithm>
#include <cstdio>
#include <hwy/tests/hwy_gtest.h>

namespace haze::analytic {
namespace {

struct Segments {
  std::vector<float> ox, oy, oz, dx, dy, dz, length;
  SegmentBatch batch() const {
    return {ox.data(), oy.data(), oz.data(), dx.data(), dy.data(), dz.data(), length.data(), ox.size()};
  }
};

// Camera-like segments: starts in a 4-unit box, random directions, lengths 0.01 to 20 or infinite.
Segments random_segments(size_t n, std::uint64_t seed) {
  Rng rng(seed, 5);
  Segments s;
  for (size_t i = 0; i < n; ++i) {
    s.ox.push_back(static_cast<float>(4.0 * rng.uniform() - 2.0));
    s.oy.push_back(static_cast<float>(4.0 * rng.uniform() - 2.0));
    s.oz.push_back(static_cast<float>(4.0 * rng.uniform() - 2.0));
    Vec3 d = direction_around(Vec3(0, 0, 1), 1.0 - 2.0 * rng.uniform(), 2.0 * kPi * rng.uniform());
    s.dx.push_back(static_cast<float>(d.x));
    s.dy.push_back(static_cast<float>(d.y));
    s.dz.push_back(static_cast<float>(d.z));
    s.length.push_back(i % 5 == 0 ? INFINITY : static_cast<float>(0.01 * std::pow(2000.0, rng.uniform())));
  }
  return s;
}

const AirlightTable& table() {
  static const AirlightTable t(PhaseFunction::henyey_greenstein(0.5));
  return t;
}

class AirlightBatchTargets : public hwy::TestWithParamTarget {};
HWY_TARGET_INSTANTIATE_TEST_SUITE_P(AirlightBatchTargets);

TEST_P(AirlightBatchTargets, MatchesScalarReference) {
  for (size_t n : {size_t(1), size_t(37), size_t(1000)}) {
    Segments s = random_segments(n, 3 + n);
    for (float sigma : {0.01f, 0.3f, 2.0f}) {
      AirlightChannel light{0.3f, -0.4f, 0.5f, sigma, 0.8f * sigma, 5.0f};
      std::vector<float> fast(n, 0.0f), reference(n, 0.0f);
      add_airlight(table(), light, s.batch(), fast.data());
      add_airlight_reference(table(), light, s.batch(), reference.data());
      for (size_t i = 0; i < n; ++i)
        ASSERT_NEAR(fast[i], reference[i], 2e-5f * reference[i] + 1e-30f) << "segment " << i << " sigma " << sigma;
    }
  }
}

// The shipped float32 path (and its scalar reference) against adaptive quadrature, including thick
// forward-scattering fog: the table's own 1e-3 (float64, bicubic: 5.8e-4 worst) is kept. Bilinear
// lookups in T itself were 1.2e-2 off at g 0.9, sigma_t 5.
TEST(AirlightBatch, FloatPathAgreesWithQuadrature) {
  const Segments s = random_segments(500, 9);
  for (double g : {-0.3, 0.5, 0.9}) {
    const PhaseFunction phase = PhaseFunction::henyey_greenstein(g);
    const AirlightTable table(phase);
    for (float sigma : {0.01f, 0.3f, 2.0f, 5.0f}) {
      const AirlightChannel light{0.3f, -0.4f, 0.5f, sigma, 0.8f * sigma, 5.0f};
      std::vector<float> fast(s.ox.size(), 0.0f), reference(s.ox.size(), 0.0f);
      add_airlight(table, light, s.batch(), fast.data());
      add_airlight_reference(table, light, s.batch(), reference.data());
      double worst = 0.0;
      for (size_t i = 0; i < fast.size(); ++i) {
        const Vec3 o(s.ox[i], s.oy[i], s.oz[i]), d(s.dx[i], s.dy[i], s.dz[i]);
        const double length = std::isfinite(s.length[i]) ? static_cast<double>(s.length[i]) : kInfinity;
        const double exact = airlight_quadrature(phase, {static_cast<double>(sigma), 0.8 * static_cast<double>(sigma), 5.0},
                                                 AirlightSegment::from_points(o, glm::normalize(d), Vec3(0.3f, -0.4f, 0.5f), length), 1e-9);
        if (!(exact > 1e-30)) continue;  // underflows in float32
        for (float v : {fast[i], reference[i]}) worst = std::max(worst, std::abs(static_cast<double>(v) - exact) / exact);
      }
      std::printf("g %.1f sigma_t %.2f: float32 airlight against quadrature, worst relative error %.2e\n", g, double(sigma), worst);
      EXPECT_LT(worst, 1e-3) << "g " << g << " sigma_t " << sigma;
    }
  }
}

// A row of froxel columns toward three lights: rays from near the origin in random directions,
// some passing within 1e-4 of a light; unbounded, boxed (t1 finite) and missing the medium.
struct SliceRow {
  static constexpr size_t kLights = 3;
  std::vector<Ray> rays;
  std::vector<Vec3> lights{Vec3(0.3, -0.4, 2.5), Vec3(-1.0, 0.5, 6.0), Vec3(2.0, 1.0, -1.0)};
  std::vector<float> t0, t1, geometry, whole;
  std::vector<TailLight> tails;
  TailRow row;
  SliceRow(size_t n, std::uint64_t seed, Rgb sigma_t, Rgb sigma_s, const AirlightTable& table) {
    Rng rng(seed, 11);
    const size_t padded = (n + 15) / 16 * 16;
    t0.assign(padded, 0.0f), t1.assign(padded, 0.0f), geometry.assign(2 * kLights * padded, 1.0f), whole.assign(3 * padded, 0.0f);
    for (size_t i = 0; i < n; ++i) {
      const Vec3 o(0.1 * rng.uniform(), 0.1 * rng.uniform(), -0.1 * rng.uniform());
      Vec3 v = direction_around(Vec3(0, 0, 1), 1.0 - 2.0 * rng.uniform(), 2.0 * kPi * rng.uniform());
      if (i % 7 == 3) v = glm::normalize(glm::normalize(lights[0] - o) + Vec3(1e-4, 0.0, 0.0));  // the light in view
      rays.push_back({o, v});
      t0[i] = i % 3 == 0 ? 0.0f : static_cast<float>(0.5 * rng.uniform());
      t1[i] = i % 3 == 0 ? INFINITY : i % 3 == 1 ? t0[i] + static_cast<float>(0.1 + 8.0 * rng.uniform()) : t0[i];
      for (size_t l = 0; l < kLights; ++l) {
        const Vec3 to = lights[l] - o;
        const double t = glm::dot(to, v);
        geometry[2 * l * padded + i] = static_cast<float>(t);
        geometry[(2 * l + 1) * padded + i] = static_cast<float>(glm::length(to - t * v));
      }
    }
    const bool grey = sigma_t == Rgb(sigma_t.r) && sigma_s == Rgb(sigma_s.r);
    for (size_t l = 0; l < kLights; ++l)
      for (int c = 0; c < (grey ? 1 : 3); ++c) {
        TailLight tail{geometry.data() + 2 * l * padded, geometry.data() + (2 * l + 1) * padded, static_cast<float>(sigma_t[c]), {}};
        for (int e = 0; e < 3; ++e)
          if (grey || e == c) tail.weight[e] = static_cast<float>(sigma_s[e] * (1.0 + static_cast<double>(l)));
        tails.push_back(tail);
      }
    float* const sums[3] = {whole.data(), whole.data() + padded, whole.data() + 2 * padded};
    row = TailRow{tails.data(), tails.size(), t0.data(), t1.data(), {sums[0], sums[1], sums[2]}, {}, n};
    for (int c = 0; c < 3; ++c) row.sigma_t[c] = static_cast<float>(sigma_t[c]);
    tail_sums_reference(table, row, t0.data(), sums);
  }
};

TEST_P(AirlightBatchTargets, SlicesMatchScalarReference) {
  for (size_t n : {size_t(1), size_t(37), size_t(160)})
    for (const Rgb& sigma_t : {Rgb(0.26), Rgb(0.05, 0.3, 2.0)}) {
      const SliceRow r(n, 5 + n, sigma_t, 0.9 * sigma_t, table());
      const size_t padded = (n + 15) / 16 * 16;
      std::vector<float> sums(3 * padded), reference(3 * padded);
      float* const s[3] = {sums.data(), sums.data() + padded, sums.data() + 2 * padded};
      float* const ref[3] = {reference.data(), reference.data() + padded, reference.data() + 2 * padded};
      tail_sums(table(), r.row, r.t0.data(), s);
      tail_sums_reference(table(), r.row, r.t0.data(), ref);
      for (size_t c = 0; c < 3; ++c)
        for (size_t i = 0; i < n; ++i) ASSERT_NEAR(s[c][i], ref[c][i], 2e-5f * ref[c][i]) << "ray " << i << " channel " << c;
      for (float distance : {0.05f, 0.4f, 2.0f, 30.0f}) {
        std::vector<float> l(3 * n), t(3 * n), l_ref(3 * n), t_ref(3 * n);
        airlight_slice(table(), r.row, distance, l.data(), t.data());
        airlight_slice_reference(table(), r.row, distance, l_ref.data(), t_ref.data());
        for (size_t i = 0; i < 3 * n; ++i) {
          // L_in = whole - T g: the kernel's rounding is relative to the whole ray's in-scatter.
          ASSERT_NEAR(l[i], l_ref[i], 2e-5f * r.whole[(i % 3) * padded + i / 3] + 1e-30f) << "ray " << i / 3 << " at " << distance;
          ASSERT_NEAR(t[i], t_ref[i], 1e-6f * t_ref[i]) << "ray " << i / 3 << " at " << distance;
        }
      }
      // Every slice at once, slice-major with room between slices, is each slice alone.
      const std::vector<float> distances{0.05f, 0.4f, 2.0f, 30.0f};
      const size_t stride = 3 * n + 5;
      std::vector<float> l(stride * distances.size(), -1.0f), t(l.size(), -1.0f);
      airlight_slices(table(), r.row, distances, l.data(), t.data(), stride);
      for (size_t k = 0; k < distances.size(); ++k) {
        std::vector<float> l_one(3 * n), t_one(3 * n);
        airlight_slice(table(), r.row, distances[k], l_one.data(), t_one.data());
        EXPECT_TRUE(std::equal(l_one.begin(), l_one.end(), l.begin() + static_cast<std::ptrdiff_t>(k * stride))) << "slice " << k;
        EXPECT_TRUE(std::equal(t_one.begin(), t_one.end(), t.begin() + static_cast<std::ptrdiff_t>(k * stride))) << "slice " << k;
        EXPECT_EQ(l[k * stride + 3 * n], -1.0f) << "written past slice " << k;
      }
    }
}

// Many slices out to where the tails are spent (T g below 1e-6 of g(t0): the kernel stops
// evaluating them) against each slice by the reference: within the kernel's rounding plus, where
// the cubic between slices stands for a slice's tails, kSliceTolerance of the whole ray's L_in.
TEST_P(AirlightBatchTargets, SpentSlicesMatchScalarReference) {
  const size_t n = 37, padded = 48;
  const SliceRow r(n, 23, Rgb(0.26), Rgb(0.234), table());
  std::vector<float> distances;
  for (int k = 0; k < 64; ++k) distances.push_back(static_cast<float>(0.1 * std::pow(1000.0, (k + 1) / 64.0)));
  const size_t stride = 3 * n;
  std::vector<float> l(stride * distances.size()), t(l.size());
  airlight_slices(table(), r.row, distances, l.data(), t.data(), stride);
  for (size_t k = 0; k < distances.size(); ++k) {
    std::vector<float> l_ref(3 * n), t_ref(3 * n);
    airlight_slice_reference(table(), r.row, distances[k], l_ref.data(), t_ref.data());
    for (size_t i = 0; i < 3 * n; ++i) {
      ASSERT_NEAR(l[k * stride + i], l_ref[i], (2e-5f + kSliceTolerance) * r.whole[(i % 3) * padded + i / 3] + 1e-30f)
          << "ray " << i / 3 << " slice " << k;
      ASSERT_NEAR(t[k * stride + i], t_ref[i], 1e-6f * t_ref[i]) << "ray " << i / 3 << " slice " << k;
    }
  }
}

// Per-pixel layers from a row's tails at its entries and ends, against the reference; ends before
// the entry, at infinity and nearly at it (the tails cancelling: flagged for float64) included.
TEST_P(AirlightBatchTargets, LayersFromTailsMatchScalarReference) {
  for (const Rgb& sigma_t : {Rgb(0.26), Rgb(0.05, 0.3, 2.0)}) {
    const size_t n = 37, padded = 48;
    const SliceRow r(n, 29, sigma_t, 0.9 * sigma_t, table());
    std::vector<float> ends(padded, 0.0f), at(padded, 0.0f), sums(3 * padded, 0.0f);
    for (size_t i = 0; i < n; ++i) {
      ends[i] = i % 4 == 0 ? INFINITY : i % 4 == 1 ? r.t0[i] - 0.1f : r.t0[i] + (i % 4 == 2 ? 0.01f : 3.0f);
      at[i] = std::isfinite(ends[i]) ? std::max(ends[i], r.t0[i]) : r.t0[i];
    }
    float* const s[3] = {sums.data(), sums.data() + padded, sums.data() + 2 * padded};
    tail_sums_reference(table(), r.row, at.data(), s);
    std::vector<float> l(3 * padded), t(3 * padded), redo(padded), l_ref(3 * padded), t_ref(3 * padded), redo_ref(padded);
    layers_from_tails(r.row, ends.data(), s, l.data(), t.data(), redo.data());
    layers_from_tails_reference(r.row, ends.data(), s, l_ref.data(), t_ref.data(), redo_ref.data());
    size_t flagged = 0;
    for (size_t i = 0; i < n; ++i) {
      ASSERT_EQ(redo[i], redo_ref[i]) << "ray " << i;
      flagged += redo[i] != 0.0f;
      for (size_t c = 0; c < 3; ++c) {
        ASSERT_NEAR(t[3 * i + c], t_ref[3 * i + c], 1e-6f * t_ref[3 * i + c]) << "ray " << i << " channel " << c;
        ASSERT_NEAR(l[3 * i + c], l_ref[3 * i + c], 1e-6f * r.whole[c * padded + i] + 1e-30f) << "ray " << i << " channel " << c;
      }
    }
    EXPECT_GT(flagged, 0u) << "the short stretches cancel";
  }
}

// A row frame's geometry in float64 lanes against the same rays one at a time: pinhole and a host's
// perspective matrices, in a box and unbounded, a light on a ray among them.
// Surface shading in lanes against its scalar reference: points on and off a box of fog, lights
// seen and hidden, Lambert and Phong with their J tables, grey and coloured media.
TEST_P(AirlightBatchTargets, ShadePointsMatchScalarReference) {
  static const SurfaceAirlightTable lambert(table(), 0.0, 32, 32), phong(table(), 24.0, 32, 32);
  Rng rng(19, 3);
  const size_t n = 37, padded = 48;
  std::vector<float> f(10 * padded, 0.0f), visible(2 * padded, 0.0f);
  for (size_t i = 0; i < n; ++i) {
    const Vec3 normal = direction_around(Vec3(0, 1, 0), rng.uniform(), 2.0 * kPi * rng.uniform());
    const Vec3 view = direction_around(-normal, rng.uniform(), 2.0 * kPi * rng.uniform());
    for (size_t e = 0; e < 3; ++e) {
      f[e * padded + i] = static_cast<float>(6.0 * rng.uniform() - 3.0);
      f[(3 + e) * padded + i] = static_cast<float>(normal[static_cast<int>(e)]), f[(6 + e) * padded + i] = static_cast<float>(view[static_cast<int>(e)]);
    }
    f[9 * padded + i] = i % 4 == 0 ? 0.0f : 1.0f;
    visible[i] = i % 5 == 0 ? 0.0f : 1.0f, visible[padded + i] = 1.0f;
  }
  const auto part = [&](size_t k) { return f.data() + k * padded; };
  const ShadingPoints points{{part(0), part(1), part(2)}, {part(3), part(4), part(5)}, {part(6), part(7), part(8)}, part(9), n};
  const ShadingLight lights[2] = {{{0.5f, 2.0f, 0.3f}, {5.0f, 4.0f, 3.0f}, visible.data()}, {{-1.5f, 1.0f, -2.0f}, {1.0f, 2.0f, 3.0f}, visible.data() + padded}};
  for (bool grey : {true, false})
    for (bool specular : {false, true}) {
      const ShadingMedium medium{{-2.0, -2.0, -HUGE_VAL}, {2.0, 2.5, HUGE_VAL}, {0.3f, grey ? 0.3f : 0.5f, grey ? 0.3f : 0.9f}, {0.25f, 0.2f, 0.1f}};
      const ShadingMaterial material{{0.6f, 0.3f, 0.2f}, {specular ? 0.4f : 0.0f, specular ? 0.4f : 0.0f, specular ? 0.4f : 0.0f}, 24.0f, &lambert,
                                     specular ? &phong : nullptr};
      std::vector<float> got(3 * n), want(3 * n);
      shade_points(medium, material, lights, 2, points, got.data());
      shade_points_reference(medium, material, lights, 2, points, want.data());
      for (size_t k = 0; k < 3 * n; ++k) ASSERT_NEAR(got[k], want[k], 1e-4f * (std::abs(want[k]) + 1e-3f)) << "value " << k << " grey " << grey << " specular " << specular;
    }
}

TEST_P(AirlightBatchTargets, RowGeometryMatchesRays) {
  Camera pinhole;
  pinhole.position = Vec3(0.2, 1.5, 6.0), pinhole.look_at = Vec3(0.0, 0.5, 0.0), pinhole.width_px = 53, pinhole.height_px = 31;
  const Camera host = Camera::from_matrices(glm::lookAt(glm::dvec3(0.2, 1.5, 6.0), glm::dvec3(0.0, 0.5, 0.0), glm::dvec3(0.0, 1.0, 0.0)),
                                            glm::perspective(0.8, 53.0 / 31.0, 0.1, 100.0), 53, 31);
  for (const Camera& camera : {pinhole, host}) {
    const Ray on_ray = camera.pixel_ray(17, 9);
    const std::vector<double> lights{0.3, -0.4, 0.5, on_ray.at(4.0).x, on_ray.at(4.0).y, on_ray.at(4.0).z, -2.0, 3.0, 1.0};
    for (const Aabb& box : {Aabb{Vec3(-1.5), Vec3(1.5)}, Aabb{}}) {
      const size_t n = 53, padded = 64;
      std::vector<float> fast(8 * padded, 0.0f), slow(8 * padded, 0.0f);
      const auto geometry = [&](std::vector<float>& v) {
        return RowGeometry{{box.lo.x, box.lo.y, box.lo.z}, {box.hi.x, box.hi.y, box.hi.z}, lights.data(), 3, v.data(), v.data() + padded,
                           v.data() + 2 * padded, 2 * padded, padded};
      };
      const RowGeometry g_fast = geometry(fast), g_slow = geometry(slow);
      Vec3 a, b;
      ASSERT_TRUE(camera.row_frame(9.5, a, b));
      const double origin[3] = {camera.position.x, camera.position.y, camera.position.z}, a3[3] = {a.x, a.y, a.z}, b3[3] = {b.x, b.y, b.z};
      row_geometry(g_fast, origin, a3, b3, 0.5, n);
      std::vector<Ray> rays(n);
      camera.row_rays(9, rays.data());
      row_geometry_rays(g_slow, rays.data(), n);
      for (size_t x = 0; x < n; ++x) {
        ASSERT_NEAR(fast[x], slow[x], 1e-6f * (1.0f + slow[x])) << "t0 of ray " << x;
        if (std::isinf(slow[padded + x])) ASSERT_EQ(fast[padded + x], slow[padded + x]) << "t1 of ray " << x;
        else ASSERT_NEAR(fast[padded + x], slow[padded + x], 1e-6f * (1.0f + slow[padded + x])) << "t1 of ray " << x;
        for (size_t l = 0; l < 3; ++l) {
          ASSERT_NEAR(g_fast.t(l)[x], g_slow.t(l)[x], 1e-6f * (1.0f + std::abs(g_slow.t(l)[x]))) << "t of ray " << x << ", light " << l;
          ASSERT_NEAR(g_fast.h(l)[x], g_slow.h(l)[x], 1e-6f * (1.0f + g_slow.h(l)[x])) << "h of ray " << x << ", light " << l;
        }
      }
      EXPECT_LT(g_fast.h(1)[17], 1e-6f) << "the light on ray 17";
    }
  }
}

// Slices against adaptive quadrature of the stretch [t0, min(d, t1)]: within 1e-3 of the whole
// ray's in-scatter (the table's error relative to g(t0)), rays within 1e-4 of a light included.
TEST(AirlightBatch, SlicesAgreeWithQuadrature) {
  for (double g : {0.0, 0.6, 0.9}) {
    const PhaseFunction phase = PhaseFunction::henyey_greenstein(g);
    const AirlightTable table(phase);
    const Rgb sigma_t(0.26, 0.5, 2.0), sigma_s = 0.9 * sigma_t;
    const SliceRow r(64, 17, sigma_t, sigma_s, table);
    const size_t padded = 64;
    double worst = 0.0;
    for (float distance : {0.3f, 1.0f, 2.5f, 7.0f, 40.0f}) {
      std::vector<float> l(3 * 64), t(3 * 64);
      airlight_slice(table, r.row, distance, l.data(), t.data());
      for (size_t i = 0; i < 64; ++i) {
        const double a = r.t0[i], b = std::min(static_cast<double>(distance), static_cast<double>(r.t1[i]));
        for (int c = 0; c < 3; ++c) {
          double exact = 0.0;
          if (b > a)
            for (size_t k = 0; k < SliceRow::kLights; ++k)
              exact += airlight_quadrature(phase, {sigma_t[c], sigma_s[c], 1.0 + static_cast<double>(k)},
                                           AirlightSegment::from_points(r.rays[i].at(a), r.rays[i].direction, r.lights[k], b - a), 1e-9);
          const double whole = r.whole[static_cast<size_t>(c) * padded + i];
          const double error = std::abs(static_cast<double>(l[3 * i + static_cast<size_t>(c)]) - exact) / std::max(whole, 1e-30);
          if (b > a) worst = std::max(worst, error);
          ASSERT_LT(error, 1e-3) << "g " << g << " ray " << i << " channel " << c << " at " << distance << ": " << l[3 * i + static_cast<size_t>(c)]
                                 << " against " << exact;
          ASSERT_NEAR(t[3 * i + static_cast<size_t>(c)], std::exp(-sigma_t[c] * std::max(0.0, b - a)), 1e-6);
        }
      }
    }
    std::printf("g %.1f: froxel slices against quadrature, worst error %.2e of the whole ray's in-scatter\n", g, worst);
  }
}

// The difference of one ray's tails at two points, g(a) - e^(-sigma_t (b - a)) g(b), against
// quadrature of [a, b] as the far tail nears the near one: the table's errors at the two points
// nearly cancel (airlight_batch.h, kTailsCancel). Lights in an 8-unit box, stretches 1e-3 to 10.
TEST(AirlightBatch, TailDifferencesKeepTheirPrecisionBelowTheCancelShare) {
  for (double g : {0.0, 0.5, 0.9}) {
    const PhaseFunction phase = PhaseFunction::henyey_greenstein(g);
    const AirlightTable table(phase);
    const float sigma = 0.26f;
    const Vec3 light(0.3, 1.5, 0.2);
    Rng rng(3, 1);
    const size_t n = 2048;
    std::vector<float> t_c(n), h_c(n), a(n, 0.0f), b(n), near(n), far(n), unused(3 * n);
    std::vector<Ray> rays(n);
    for (size_t i = 0; i < n; ++i) {
      rays[i] = {Vec3(8.0 * rng.uniform() - 4.0, 3.5 * rng.uniform(), 8.0 * rng.uniform() - 4.0),
                 direction_around(Vec3(0, 0, 1), 1.0 - 2.0 * rng.uniform(), 2.0 * kPi * rng.uniform())};
      const Vec3 to = light - rays[i].origin;
      const double t = glm::dot(to, rays[i].direction);
      t_c[i] = static_cast<float>(t), h_c[i] = static_cast<float>(glm::length(to - t * rays[i].direction));
      b[i] = static_cast<float>(0.001 * std::pow(10000.0, rng.uniform()));
    }
    const TailLight tail{t_c.data(), h_c.data(), sigma, {1.0f, 0.0f, 0.0f}};
    const TailRow row{&tail, 1, a.data(), b.data(), {}, {sigma, sigma, sigma}, n};
    float* const at_a[3] = {near.data(), unused.data(), unused.data() + n};
    float* const at_b[3] = {far.data(), unused.data(), unused.data() + n};
    tail_sums(table, row, a.data(), at_a);
    tail_sums(table, row, b.data(), at_b);
    double worst_below_09 = 0.0, worst = 0.0;
    for (size_t i = 0; i < n; ++i) {
      const double T = std::exp(-static_cast<double>(sigma * b[i]));
      const double ratio = T * static_cast<double>(far[i]) / static_cast<double>(near[i]);
      if (ratio > static_cast<double>(kTailsCancel)) continue;  // the float64 path's
      const double exact = airlight_quadrature(phase, {sigma, 1.0, 1.0}, AirlightSegment::from_points(rays[i].origin, rays[i].direction, light, b[i]), 1e-10);
      const double error = std::abs(static_cast<double>(near[i]) - T * static_cast<double>(far[i]) - exact) / exact;
      (ratio < 0.9 ? worst_below_09 : worst) = std::max(ratio < 0.9 ? worst_below_09 : worst, error);
    }
    std::printf("g %.1f: tails' differences against quadrature, worst %.2e below a far share of 0.9, %.2e up to %.3f\n", g, worst_below_09, worst,
                static_cast<double>(kTailsCancel));
    EXPECT_LT(worst_below_09, 3e-3) << g;
    EXPECT_LT(worst, 1.5e-2) << g;
  }
}

}  // namespace
}  // namespace haze::analytic
