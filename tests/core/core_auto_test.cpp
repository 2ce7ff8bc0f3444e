// Method auto with core's methods only (this program registers no module): what no registered
// method offers goes to the reference, and the explanation says which declined and why. A
// method's table of measured offers gives the cheapest row the tolerance meets.
#include <haze/auto/auto.h>

#include <gtest/gtest.h>

namespace haze {
namespace {

TEST(AutoMethod, WhatNothingRegisteredOffersGoesToTheReference) {
  Scene scene;
  scene.camera.width_px = scene.camera.height_px = 8;
  MediumDesc medium;
  medium.bounds = {Vec3(-1.0), Vec3(1.0)};
  medium.sigma_t = Rgb(3.0);
  medium.albedo = Rgb(0.95);
  scene.medium = medium;
  scene.lights.push_back(PointLight{Vec3(0.0, 2.0, 0.0), Rgb(5.0)});
  const AutoChoice choice = choose_method(scene, 0.1);  // with grids registered: dom
  EXPECT_EQ(choice.method, "reference");
  EXPECT_EQ(choice.expected_seconds, 0.0);
  std::string why;
  for (const auto& line : choice.why) why += line + "\n";
  EXPECT_NE(why.find("analytic declines: multiple scattering matters"), std::string::npos) << why;
  EXPECT_NE(why.find("no registered method offers"), std::string::npos) << why;
  EXPECT_EQ(why.find("dom"), std::string::npos) << why;
}

TEST(AutoMethod, MeasuredOffersGiveTheCheapestRowTheToleranceMeets) {
  const MeasuredOffer table[] = {{0.05, {{"resolution", 16}}, 0.3, "a 4% at 16^3"}, {0.02, {{"resolution", 32}}, 1.5, "a 1.6% at 32^3"}};
  const AutoOffer coarse = offer_from(table, 0.1, "fog", "none"), fine = offer_from(table, 0.03, "fog", "none"),
                  edge = offer_from(table, 0.02, "fog", "none"), none = offer_from(table, 0.019, "fog", "1.6% at best");
  EXPECT_TRUE(coarse.offered && fine.offered && edge.offered);
  EXPECT_EQ(coarse.settings["resolution"], 16);
  EXPECT_EQ(coarse.why, "fog: a 4% at 16^3");
  EXPECT_EQ(fine.settings["resolution"], 32);
  EXPECT_EQ(fine.expected_seconds, 1.5);
  EXPECT_EQ(edge.settings["resolution"], 32);
  EXPECT_FALSE(none.offered);
  EXPECT_EQ(none.why, "1.6% at best");
}

}  // namespace
}  // namespace haze
