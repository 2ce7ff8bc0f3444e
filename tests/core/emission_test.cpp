// Emission (DESIGN.md, "Emission"): blackbody colours against Planck's law, the closed form of a
// uniformly emitting box through every method that renders emission, the scene block and its errors.
#include <haze/core/blackbody.h>
#include <haze/core/error.h>
#include <haze/core/method.h>
#include <haze/core/scene.h>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace haze {
namespace {

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

// The table agrees with the direct integration to 1e-3 (of luminance 1) between its entries.
TEST(Blackbody, TableMatchesPlanckIntegration) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> log_t(std::log(600.0), std::log(40000.0));
  double worst = 0.0;
  for (int i = 0; i < 300; ++i) {
    const double t = std::exp(log_t(rng));
    const Rgb a = blackbody_color(t), b = blackbody_color_integrated(t);
    EXPECT_NEAR(0.2126 * a.r + 0.7152 * a.g + 0.0722 * a.b, 1.0, 1e-9) << t;
    const Rgb d = glm::abs(a - b);
    worst = std::max({worst, d.r, d.g, d.b});
  }
  EXPECT_LT(worst, 1e-3);
  // Colour with temperature: red-heavy when cool, blue-heavy when hot, near white at 6500 K.
  EXPECT_GT(blackbody_color(1500.0).r, 3.0 * blackbody_color(1500.0).b);
  EXPECT_GT(blackbody_color(15000.0).b, blackbody_color(15000.0).r);
  const Rgb white = blackbody_color(6500.0);
  EXPECT_NEAR(white.r, 1.0, 0.1);
  EXPECT_NEAR(white.b, 1.0, 0.1);
}

// The integration's chromaticities are the Planckian locus's: CIE illuminant A is a 2856 K
// blackbody, (x, y) = (0.44757, 0.40745) (CIE 15:2004); 6500 K lies at (0.3135, 0.3236). Within
// the colour-matching fit's own error (Wyman et al. 2013).
TEST(Blackbody, ChromaticityOnThePlanckianLocus) {
  const Vec3 a = blackbody_chromaticity(2856.0), d = blackbody_chromaticity(6500.0);
  EXPECT_NEAR(a.x, 0.44757, 2e-3);
  EXPECT_NEAR(a.y, 0.40745, 2e-3);
  EXPECT_NEAR(d.x, 0.3135, 2e-3);
  EXPECT_NEAR(d.y, 0.3236, 2e-3);
}

// A uniformly emitting, non-scattering box: along each ray through it L = L_e (1 - e^-tau) / sigma_t,
// tau = sigma_t times the chord; with blackbody L_e = strength color + intensity tint(T) sigma T^4.
Scene emitting_box() {
  const nlohmann::json j = {
      {"camera", {{"position", {0.3, 0.2, 4.0}}, {"look_at", {0, 0, 0}}, {"fov_y_deg", 40}, {"width_px", 16}, {"height_px", 12}}},
      {"medium",
       {{"bounds", {{-1, -0.8, -0.6}, {1, 0.8, 0.6}}},
        {"density", {{"type", "constant"}, {"value", 1.0}}},
        {"sigma_t", {1.0, 2.0, 0.5}},
        {"albedo", 0.0},
        {"emission", {{"strength", 2.0}, {"color", {1.0, 0.5, 0.25}}}},
        {"blackbody", {{"intensity", 0.5}, {"temperature", 1500}}}}}};
  return Scene::from_json(j);
}

TEST(Emission, UniformBoxHasTheClosedForm) {
  const Scene scene = emitting_box();
  const Rgb L_e = 2.0 * Rgb(1.0, 0.5, 0.25) + 0.5 * blackbody_color(1500.0) * (kBlackbodySigma * std::pow(1500.0, 4));
  const Rgb sigma(1.0, 2.0, 0.5);
  RenderOptions reference;
  reference.settings = {{"spp", 1024}, {"seed", 3}};
  const RenderResult q = render(scene, "quadrature"), r = render(scene, "reference", reference);
  int inside = 0;
  double z_worst = 0.0, z_sum = 0.0;
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 16; ++x) {
      const Ray ray = scene.camera.pixel_ray(x, y);
      double t0 = 0.0, t1 = kInfinity;
      const bool hits = scene.medium->bounds.clip(ray, t0, t1);
      const Rgb expected = hits ? L_e * (Rgb(1.0) - glm::exp(-sigma * (t1 - t0))) / sigma : Rgb(0.0);
      inside += hits;
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(q.radiance.at(x, y)[c], expected[c], 1e-4 * std::max(1.0, expected[c])) << x << "," << y;
        const double error = std::abs(r.radiance.at(x, y)[c] - expected[c]), noise = r.std_error->at(x, y)[c];
        EXPECT_LE(error, 5.0 * noise + 1e-6 * expected[c]) << "reference " << x << "," << y << " channel " << c;
        if (noise > 0.0) z_worst = std::max(z_worst, error / noise), z_sum += (r.radiance.at(x, y)[c] - expected[c]) / noise;
      }
    }
  EXPECT_GT(inside, 60);
  // Over the 3 x inside channels the signed errors in standard errors average about 0 (their
  // mean's own standard error is 1 / sqrt(3 inside)).
  const double z_mean = z_sum / (3.0 * inside);
  std::printf("reference: worst |error| / standard error %.2f, mean signed %.3f over %d pixels\n", z_worst, z_mean, inside);
  EXPECT_LT(std::abs(z_mean), 4.0 / std::sqrt(3.0 * inside));
  // auto renders it with a method that renders emission.
  const std::string chosen = render(scene, "auto").stats["auto"]["method"].get<std::string>();
  EXPECT_TRUE(chosen == "quadrature" || chosen == "reference") << chosen;
}

TEST(Emission, SceneBlockAndErrors) {
  const Scene scene = emitting_box();
  const Emission& e = scene.medium->emission;
  EXPECT_EQ(e.strength, 2.0);
  EXPECT_EQ(e.blackbody_intensity, 0.5);
  EXPECT_EQ(e.temperature, 1500.0);
  auto with = [](const nlohmann::json& medium_extra) {
    nlohmann::json j = {{"camera", {{"position", {0, 0, 4}}, {"look_at", {0, 0, 0}}}},
                        {"medium", {{"bounds", {{-1, -1, -1}, {1, 1, 1}}}, {"density", {{"type", "constant"}}}, {"sigma_t", 1.0}}}};
    j["medium"].update(medium_extra);
    return Scene::from_json(j);
  };
  EXPECT_NE(message_of([&] { with({{"emission", {{"strength", -1}}}}); }).find("medium.emission.strength"), std::string::npos);
  EXPECT_NE(message_of([&] { with({{"emission", {{"strenght", 1}}}}); }).find("medium.emission.strenght"), std::string::npos);
  EXPECT_NE(message_of([&] { with({{"blackbody", {{"temperature", 2e6}}}}); }).find("medium.blackbody.temperature"), std::string::npos);
  EXPECT_NE(message_of([&] { with({{"emission", {{"grid", "flame"}}}}); }).find("medium.emission.grid: got \"flame\""), std::string::npos);
  // Methods that do not render emission refuse it by name, listing those that do.
  const std::string refused = message_of([&] { render(emitting_box(), "analytic"); });
  EXPECT_NE(refused.find("medium.emission"), std::string::npos) << refused;
  EXPECT_NE(refused.find("quadrature"), std::string::npos) << refused;
  EXPECT_NE(refused.find("reference"), std::string::npos) << refused;
}

}  // namespace
}  // namespace haze
