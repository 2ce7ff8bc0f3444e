// A headless context comes up on a machine with no display (EGL surfaceless or OSMesa).
#include <haze/gl/context.h>

#include <gtest/gtest.h>

namespace haze::gl {
namespace {

TEST(HeadlessContext, MakesAnOpenGL33Context) {
  GlInfo info = probe();
  ASSERT_TRUE(info.available) << info.error;
  EXPECT_TRUE(info.backend == "egl-surfaceless" || info.backend == "osmesa") << info.backend;
  EXPECT_FALSE(info.renderer.empty());
  // "3.3 (Core Profile) Mesa ..." or a later version.
  EXPECT_GE(std::stod(info.version.substr(0, 3)), 3.3) << info.version;
}

}  // namespace
}  // namespace haze::gl
