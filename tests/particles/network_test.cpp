// Method "network" (seed 001) against the reference path tracer on the particles' continuous
// density, its visibility network's invariants, and degenerate particle sets.
#include <haze/core/error.h>
#include <haze/core/method.h>
#include <haze/core/rng.h>
#include <haze/particles/methods.h>
#include <haze/particles/network.h>

#include <gtest/gtest.h>

#include <cstdio>

namespace haze::particles {
namespace {

// `count` particles uniform in a ball of radius 1 (sigma_t 4: optical radius 4), a sun and a point
// light, a small camera.
Scene ball(int count, double albedo, int width, int height, std::uint64_t seed = 3) {
  Rng rng(seed);
  nlohmann::json positions = nlohmann::json::array();
  while (static_cast<int>(positions.size()) < count) {
    const Vec3 x(2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
    if (glm::dot(x, x) < 1.0) positions.push_back({x.x, x.y, x.z});
  }
  nlohmann::json j = {
      {"camera", {{"position", {0.0, 0.4, 4.0}}, {"look_at", {0.0, 0.0, 0.0}}, {"fov_y_deg", 38.0}, {"width_px", width}, {"height_px", height}}},
      {"particles", {{"positions", positions}, {"sigma_t", 4.0}, {"albedo", albedo}, {"phase", {{"type", "hg"}, {"g", 0.3}}}}},
      {"lights", {{{"type", "directional"}, {"direction", {-0.5, -0.7, -0.5}}, {"irradiance", 1.0}},
                  {{"type", "point"}, {"position", {1.3, -0.4, 1.2}}, {"intensity", 1.5}}}},
      {"background", {0.0, 0.0, 0.0}}};
  return Scene::from_json(j);
}

// The camera's transmittance through the particles (background 1, no lights) agrees with the
// reference path tracer on the particles' continuous density (a 96-cell grid of it): the splat
// march integrates each Gaussian exactly. Signed mean within 1% plus three standard errors.
TEST(NetworkRender, TransmittanceMatchesTheReference) {
  register_methods();
  Scene scene = ball(2000, 0.9, 32, 24);
  scene.lights.clear();
  scene.background = Rgb(1.0);
  RenderOptions reference_options;
  reference_options.settings = {{"spp", 256}, {"seed", 5}, {"max_scattering", 0}};
  const RenderResult reference = render(scene, "reference", reference_options);
  const RenderResult network = render(scene, "network", RenderOptions{0, {{"iterations", 0}}, {}, {}});
  const LitPixelError e = lit_pixel_error(network.radiance, reference.radiance, &*reference.std_error, nullptr, 0.05);
  std::printf("transmittance over %d pixels: signed %+.4f +- %.4f\n", e.pixels, e.signed_mean, e.signed_mean_error);
  EXPECT_GT(e.pixels, 300);
  EXPECT_LT(std::abs(e.signed_mean), 0.01 + 3.0 * e.signed_mean_error);
}

// Single scattering (no network iterations) against the reference path tracer limited to one
// scattering event: the direct light comes from the lights' depth maps at every ray step, so the
// only approximations left are the maps' interpolation and the march's steps. Lit pixels: signed
// mean within 2% plus three standard errors, rms (reference noise removed) under 4%.
TEST(NetworkRender, SingleScatteringMatchesTheReference) {
  register_methods();
  const Scene scene = ball(2000, 0.9, 32, 24);
  RenderOptions reference_options;
  reference_options.settings = {{"spp", 256}, {"seed", 5}, {"max_scattering", 1}};
  const RenderResult reference = render(scene, "reference", reference_options);
  const RenderResult network = render(scene, "network", RenderOptions{0, {{"iterations", 0}}, {}, {}});
  const LitPixelError e = lit_pixel_error(network.radiance, reference.radiance, &*reference.std_error);
  std::printf("single scattering over %d pixels: signed %+.4f +- %.4f, rms (noise removed) %.4f\n", e.pixels, e.signed_mean,
              e.signed_mean_error, e.rms_noise_removed);
  EXPECT_GT(e.pixels, 300);
  EXPECT_LT(std::abs(e.signed_mean), 0.02 + 3.0 * e.signed_mean_error);
  EXPECT_LT(e.rms_noise_removed, 0.04);
}

// The continuous density: a uniform ball of particles stands for density 1 inside (within 15%:
// the sizes come from the 8 nearest neighbours, a noisy estimate), and a line integral equals the
// sum of the density along it.
TEST(ParticleField, StandsForTheDensity) {
  const Scene scene = ball(2000, 0.9, 8, 8);
  const ParticleSet set = ParticleSet::from_json(scene.particles);
  const ParticleField field(set.view());
  EXPECT_NEAR(field.density(Vec3(0.0)), 1.0, 0.15);
  EXPECT_NEAR(field.density_integral(Vec3(0.0, 0.0, -3.0), Vec3(0.0, 0.0, 1.0), 6.0), 2.0, 0.3);
  double sum = 0.0;
  const double dt = 0.001;
  for (double t = 0.5 * dt; t < 6.0; t += dt) sum += field.density(Vec3(0.1, 0.2, -3.0 + t)) * dt;
  EXPECT_NEAR(field.density_integral(Vec3(0.1, 0.2, -3.0), Vec3(0.0, 0.0, 1.0), 6.0), sum, 1e-3 * sum);
}

// The visibility network: in every direction each particle's upstream particle is the one just
// before it in the sweep order (iterate_network relies on it) and lies behind it along the
// direction; gap depths are >= 0.
TEST(VisibilityNetwork, UpstreamComesFirst) {
  const Scene scene = ball(500, 0.9, 8, 8);
  const ParticleSet set = ParticleSet::from_json(scene.particles);
  const ParticleField field(set.view());
  const DirectionSet dirs = DirectionSet::fibonacci(32);
  const VisibilityNetwork v = build_visibility(field, field.density_at_particles(0), dirs, default_window(field), 0);
  int linked = 0;
  for (int i = 0; i < 32; ++i) {
    std::vector<int> rank(500);
    for (int k = 0; k < 500; ++k) rank[static_cast<size_t>(v.order[static_cast<size_t>(i * 500 + k)])] = k;
    for (int p = 0; p < 500; ++p) {
      const auto at = static_cast<size_t>(i * 500 + p);
      const int up = v.upstream[at];
      ASSERT_GE(v.depth[at], 0.0f);
      if (up < 0) continue;
      ++linked;
      ASSERT_EQ(rank[static_cast<size_t>(up)] + 1, rank[static_cast<size_t>(p)]);
      ASSERT_LE(glm::dot(field.position(static_cast<size_t>(up)) - field.position(static_cast<size_t>(p)), dirs[i]), 0.0);
    }
  }
  EXPECT_GT(linked, 32 * 500 / 2);  // most particles see another one upstream
}

// Warm start (the sun moved by 5 degrees): starting from the previous solution converges in fewer
// iterations to the same I (relative L2 difference within a few tolerances); grey media solve one
// channel, and the separable product agrees with the full matrix.
TEST(NetworkSolve, WarmStartAndShortcuts) {
  const Scene scene = ball(1000, 0.95, 8, 8);
  const ParticleSet set = ParticleSet::from_json(scene.particles);
  const ParticleField field(set.view());
  NetworkSettings settings;
  settings.directions = 64, settings.tolerance = 1e-4;
  const auto sun = [](double degrees) {
    const double a = degrees * kPi / 180.0;
    return std::vector<Light>{DirectionalLight{Vec3(std::sin(a), -std::cos(a), 0.0), Rgb(1.0)}};
  };
  const NetworkSolution before = solve_network(field, sun(30.0), settings);
  const NetworkSolution cold = solve_network(field, sun(35.0), settings);
  const NetworkSolution warm = solve_network(field, sun(35.0), settings, &before);
  ASSERT_TRUE(cold.converged && warm.converged);
  std::printf("iterations: cold %d, warm %d; channels %d, terms %d\n", cold.iterations, warm.iterations, cold.channels, cold.terms);
  EXPECT_LT(warm.iterations, cold.iterations);
  const auto difference = [](const std::vector<float>& a, const std::vector<float>& b) {
    double diff = 0.0, ref = 0.0;
    for (size_t e = 0; e < a.size(); ++e) {
      const double x = a[e], y = b[e];
      diff += (x - y) * (x - y), ref += y * y;
    }
    return std::sqrt(diff / ref);
  };
  EXPECT_LT(difference(warm.incoming[0], cold.incoming[0]), 5e-3);
  EXPECT_EQ(cold.channels, 1);  // grey medium, white sun
  EXPECT_LT(cold.terms, 64);
  settings.terms = 64;  // the full matrix
  const NetworkSolution full = solve_network(field, sun(35.0), settings);
  std::printf("separable (%d terms) against the full matrix: %.2e\n", cold.terms, difference(cold.incoming[0], full.incoming[0]));
  EXPECT_LT(difference(cold.incoming[0], full.incoming[0]), 3e-3);
}

// Degenerate particle sets: clear errors where no answer exists, finite images otherwise.
TEST(NetworkDegenerate, HandledOrRefused) {
  register_methods();
  auto with = [](nlohmann::json particles) {
    Scene s = ball(10, 0.9, 8, 6);
    particles["sigma_t"] = 2.0;
    s.particles = particles;
    return s;
  };
  auto message = [](const Scene& s) {
    try {
      render(s, "network");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  auto finite = [](const Image& image) {
    for (int y = 0; y < image.height(); ++y)
      for (int x = 0; x < image.width(); ++x)
        for (int c = 0; c < 3; ++c)
          if (!std::isfinite(image.at(x, y)[c])) return false;
    return true;
  };
  // A single particle, or coincident ones, without diameters: no size follows.
  EXPECT_NE(message(with({{"positions", {{0, 0, 0}}}})).find("particles.diameter"), std::string::npos);
  EXPECT_NE(message(with({{"positions", {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}}})).find("particles.diameter"), std::string::npos);
  // Zero and NaN diameters are refused with the particle's index.
  EXPECT_NE(message(with({{"positions", {{0, 0, 0}, {1, 0, 0}}}, {"diameter", {0.5, 0.0}}})).find("particles.diameter[1]"), std::string::npos);
  EXPECT_NE(message(with({{"positions", {{0, 0, 0}, {1, 0, 0}}}, {"diameter", {0.5, nullptr}}})).find("particles.diameter"), std::string::npos);
  // A single particle with a diameter, coincident particles with one, a plane of particles, an
  // empty set, and a point light inside the cloud all render finite images.
  EXPECT_TRUE(finite(render(with({{"positions", {{0, 0, 0}}}, {"diameter", 0.5}}), "network").radiance));
  EXPECT_TRUE(finite(render(with({{"positions", {{0, 0, 0}, {0, 0, 0}}}, {"diameter", 0.5}}), "network").radiance));
  nlohmann::json plane = nlohmann::json::array();
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) plane.push_back({0.2 * i - 1.0, 0.2 * j - 1.0, 0.0});
  EXPECT_TRUE(finite(render(with({{"positions", plane}}), "network").radiance));
  const Image empty = render(with({{"positions", nlohmann::json::array()}}), "network").radiance;
  EXPECT_EQ(empty.at(3, 3), Rgb(0.0));  // the scene's background
  Scene inside = ball(300, 0.9, 8, 6);
  inside.lights = {PointLight{Vec3(0.0), Rgb(1.0)}};
  EXPECT_TRUE(finite(render(inside, "network").radiance));
}

}  // namespace
}  // namespace haze::particles
