// The splat of particles onto camera rays on every compiled Highway target: one particle's opacity
// and radiance in closed form, its clip to the ray's [0, t_end], and random tiles against the
// float64 reference, grey and coloured.
#include <haze/core/rng.h>
#include <haze/particles/field.h>
#include <haze/particles/splat.h>

#include <gtest/gtest.h>
#include <hwy/tests/hwy_gtest.h>

#include <array>
#include <cmath>
#include <vector>

namespace haze::particles {
namespace {

class Splat : public hwy::TestWithParamTarget {};
HWY_TARGET_INSTANTIATE_TEST_SUITE_P(Splat);

struct Particles {
  std::vector<float> x, y, z, h, amplitude, source[3], direct[3], gx, gy, gz, max_log, shift, spread;
  std::vector<uint32_t> order;
  void add(float px, float py, float pz, float width, float a, std::array<float, 3> s, std::array<float, 3> e = {}, std::array<float, 3> g = {},
           float m = 0.0f, float half_v = 0.0f) {
    order.push_back(static_cast<uint32_t>(x.size()));
    x.push_back(px), y.push_back(py), z.push_back(pz), h.push_back(width), amplitude.push_back(a);
    for (int c = 0; c < 3; ++c) source[c].push_back(s[static_cast<size_t>(c)]), direct[c].push_back(e[static_cast<size_t>(c)]);
    gx.push_back(g[0]), gy.push_back(g[1]), gz.push_back(g[2]), max_log.push_back(3.0f), shift.push_back(m), spread.push_back(half_v);
  }
  SplatParticles view() const {
    return {x.data(), y.data(), z.data(), h.data(), amplitude.data(), {source[0].data(), source[1].data(), source[2].data()},
            {direct[0].data(), direct[1].data(), direct[2].data()}, gx.data(), gy.data(), gz.data(), max_log.data(), shift.data(), spread.data(),
            order.data(), order.size()};
  }
};

struct Rays {
  std::vector<float> ox, oy, oz, dx, dy, dz, t_end, radiance[3], transmittance[3];
  void add(Vec3 o, Vec3 d, double end) {
    d = glm::normalize(d);
    ox.push_back(static_cast<float>(o.x)), oy.push_back(static_cast<float>(o.y)), oz.push_back(static_cast<float>(o.z));
    dx.push_back(static_cast<float>(d.x)), dy.push_back(static_cast<float>(d.y)), dz.push_back(static_cast<float>(d.z));
    t_end.push_back(static_cast<float>(end));
  }
  // Padded to kSplatPad with copies of the last ray.
  SplatRays view(bool ends) {
    while (ox.size() % kSplatPad) add(Vec3(ox.back(), oy.back(), oz.back()), Vec3(dx.back(), dy.back(), dz.back()), t_end.back());
    for (int c = 0; c < 3; ++c) radiance[c].assign(ox.size(), -1.0f), transmittance[c].assign(ox.size(), -1.0f);
    return {ox.data(), oy.data(), oz.data(), dx.data(), dy.data(), dz.data(), ends ? t_end.data() : nullptr,
            {radiance[0].data(), radiance[1].data(), radiance[2].data()}, {transmittance[0].data(), transmittance[1].data(), transmittance[2].data()},
            ox.size()};
  }
};

// One particle 5 ahead, rays at r = 0, h and 2h from its centre: tau = a exp(-(r/h)^2), T = e^(-sigma
// tau), L = (1 - T) (s + e) for a flat direct light; one past kCut h leaves the ray untouched.
TEST_P(Splat, OneParticleInClosedForm) {
  Particles p;
  p.add(0.0f, 0.0f, 5.0f, 0.2f, 0.8f, {0.5f, 0.25f, 0.125f}, {0.1f, 0.2f, 0.3f});
  Rays r;
  for (double offset : {0.0, 0.2, 0.4, 0.61}) r.add(Vec3(offset, 0.0, 0.0), Vec3(0.0, 0.0, 1.0), kInfinity);
  const float sigma_t[3] = {2.0f, 3.0f, 4.0f};
  splat_rays(p.view(), sigma_t, 3, r.view(false));
  for (int j = 0; j < 4; ++j) {
    const double tau = j == 3 ? 0.0 : 0.8 * std::exp(-j * j);
    for (int c = 0; c < 3; ++c) {
      const double t = std::exp(-static_cast<double>(sigma_t[c]) * tau), s = static_cast<double>(p.source[c][0] + p.direct[c][0]);
      EXPECT_NEAR(r.transmittance[c][static_cast<size_t>(j)], t, 2e-6) << "ray " << j << " channel " << c;
      EXPECT_NEAR(r.radiance[c][static_cast<size_t>(j)], (1.0 - t) * s, 2e-6) << "ray " << j << " channel " << c;
    }
  }
}

// The ray's end at the centre keeps half of the Gaussian (erf(kCut) / 2 of it: it ends at kCut h); a
// start at its centre (the eye inside it) the other half; an end kCut h before it none.
TEST_P(Splat, ClipsTheGaussianToTheRay) {
  Particles p;
  p.add(0.0f, 0.0f, 2.0f, 0.25f, 1.0f, {1.0f, 1.0f, 1.0f});
  Rays r;
  r.add(Vec3(0.0), Vec3(0.0, 0.0, 1.0), 2.0);
  r.add(Vec3(0.0, 0.0, 2.0), Vec3(0.0, 0.0, 1.0), kInfinity);
  r.add(Vec3(0.0), Vec3(0.0, 0.0, 1.0), 2.0 - kCut * 0.25 - 1e-3);
  const float sigma_t[3] = {1.5f, 1.5f, 1.5f};
  splat_rays(p.view(), sigma_t, 1, r.view(true));
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(r.transmittance[1][static_cast<size_t>(j)], j == 2 ? 1.0 : std::exp(-1.5 * 0.5 * std::erf(kCut)), 2e-6) << "ray " << j;
}

// Random particles (some within reach of the rays' origins, directions varied, log-linear direct
// light) against the float64 reference, ends and no ends, grey and coloured.
TEST_P(Splat, AgreesWithTheFloat64Reference) {
  Rng rng(11);
  const auto u = [&] { return static_cast<float>(rng.uniform()); };
  double worst = 0.0;
  for (int trial = 0; trial < 40; ++trial) {
    Particles p;
    for (int i = 0; i < 200; ++i) {
      const float h = 0.05f + 0.15f * u();
      p.add(2.0f * u() - 1.0f, 2.0f * u() - 1.0f, 3.0f * u() - 0.5f, h, 2.0f * h * u(), {u(), u(), u()}, {u(), u(), u()},
            {(4.0f * u() - 2.0f) / h, (4.0f * u() - 2.0f) / h, (4.0f * u() - 2.0f) / h}, -0.5f * h * u(), 0.25f * h * h * u());
    }
    Rays r;
    for (int j = 0; j < 64; ++j)
      r.add(Vec3(0.2 * rng.uniform(), 0.2 * rng.uniform(), -0.3 + 0.6 * rng.uniform()), Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, 1.0), 0.5 + 3.0 * rng.uniform());
    const bool ends = trial % 2 == 0;
    const int channels = trial % 4 < 2 ? 1 : 3;
    const float sigma_t[3] = {3.0f, channels == 1 ? 3.0f : 3.5f, channels == 1 ? 3.0f : 4.0f};
    Rays want = r;
    splat_rays_reference(p.view(), sigma_t, want.view(ends));
    splat_rays(p.view(), sigma_t, channels, r.view(ends));
    for (int c = 0; c < 3; ++c)
      for (size_t j = 0; j < r.ox.size(); ++j) {
        const double dl = std::abs(static_cast<double>(r.radiance[c][j] - want.radiance[c][j])) / (1.0 + static_cast<double>(want.radiance[c][j]));
        const double dt = std::abs(static_cast<double>(r.transmittance[c][j] - want.transmittance[c][j]));
        worst = std::max({worst, dl, dt});
        ASSERT_LT(dl, 2e-4) << "trial " << trial << " ray " << j << " channel " << c << " target " << hwy::TargetName(GetParam());
        ASSERT_LT(dt, 2e-5) << "trial " << trial << " ray " << j << " channel " << c << " target " << hwy::TargetName(GetParam());
      }
  }
  std::printf("%s: largest difference from the float64 reference %.2e\n", hwy::TargetName(GetParam()), worst);
}

}  // namespace
}  // namespace haze::particles
