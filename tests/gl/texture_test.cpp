// Textures: what goes up through the pixel-buffer ring comes back (float32 exactly, float16 to its
// rounding), brick uploads change only their bricks, bad input is refused with the field named.
#include <haze/core/error.h>
#include <haze/gl/context.h>
#include <haze/gl/texture.h>

#include <gtest/gtest.h>

#include <cmath>

namespace haze::gl {
namespace {

std::vector<float> ramp(size_t n, float scale) {
  std::vector<float> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = scale * std::sin(0.37f * static_cast<float>(i)) + 0.001f * static_cast<float>(i);
  return v;
}

TEST(Texture, VolumeRoundTripsFloat32ExactlyAndFloat16ToItsRounding) {
  HeadlessContext context;
  const std::array<int, 3> n{13, 7, 5};  // odd sizes: rows are not 4-byte aligned in float16
  for (int channels : {1, 3, 4}) {
    const std::vector<float> values = ramp(13 * 7 * 5 * static_cast<size_t>(channels), 2.0f);
    Texture full = Texture::volume(n, channels, TexelFormat::float32);
    full.upload(values);
    EXPECT_EQ(full.read(), values) << channels;
    Texture half = Texture::volume(n, channels, TexelFormat::float16);
    half.upload(values);
    const std::vector<float> back = half.read();
    ASSERT_EQ(back.size(), values.size());
    for (size_t i = 0; i < values.size(); ++i) ASSERT_NEAR(back[i], values[i], std::abs(values[i]) * 0x1p-11f + 1e-7f) << i;
    // GL 4.4 and later (llvmpipe offers 4.5) keep the pixel buffer mapped.
    if (std::stod(context.info().version.substr(0, 3)) >= 4.4) {
      EXPECT_TRUE(full.stats().persistent);
    }
  }
}

TEST(Texture, RepeatedUploadsCycleThroughTheRingAndKeepTheLatest) {
  HeadlessContext context;
  Texture t = Texture::plane(9, 4, 2, TexelFormat::float32);
  for (int frame = 0; frame < 5; ++frame) {
    const std::vector<float> values = ramp(9 * 4 * 2, static_cast<float>(frame + 1));
    t.upload(values);
    ASSERT_EQ(t.read(), values) << frame;
  }
  EXPECT_EQ(t.stats().uploads, 5u);
  EXPECT_EQ(t.stats().bytes, 5u * 9 * 4 * 2 * 4);
}

TEST(Texture, BrickUploadChangesOnlyItsBricks) {
  HeadlessContext context;
  const std::array<int, 3> n{20, 12, 9};
  const size_t cells = 20 * 12 * 9;
  for (TexelFormat format : {TexelFormat::float32, TexelFormat::float16}) {
    Texture t = Texture::volume(n, 2, format);
    const std::vector<float> before(2 * cells, 0.25f);
    t.upload(before);
    std::vector<float> after = ramp(2 * cells, 1.0f);
    std::vector<unsigned char> changed(cells, 0);
    changed[(3 * 12 + 5) * 20 + 17] = 1;  // cell (17, 5, 3)
    changed[(8 * 12 + 11) * 20 + 0] = 1;  // cell (0, 11, 8)
    const std::vector<Brick> bricks = changed_bricks(n, changed, 8);
    ASSERT_EQ(bricks.size(), 2u);
    EXPECT_EQ(bricks[0].origin, (std::array<int, 3>{16, 0, 0}));
    EXPECT_EQ(bricks[0].size, (std::array<int, 3>{4, 8, 8}));  // cut at the edge in x
    EXPECT_EQ(bricks[1].size, (std::array<int, 3>{8, 4, 1}));
    t.upload(after, bricks);
    const std::vector<float> back = t.read();
    size_t inside = 0;
    for (int z = 0; z < n[2]; ++z)
      for (int y = 0; y < n[1]; ++y)
        for (int x = 0; x < n[0]; ++x) {
          bool in = false;
          for (const Brick& b : bricks)
            in = in || (x >= b.origin[0] && x < b.origin[0] + b.size[0] && y >= b.origin[1] && y < b.origin[1] + b.size[1] &&
                        z >= b.origin[2] && z < b.origin[2] + b.size[2]);
          inside += in;
          for (size_t c = 0; c < 2; ++c) {
            const size_t i = 2 * ((static_cast<size_t>(z) * 12 + static_cast<size_t>(y)) * 20 + static_cast<size_t>(x)) + c;
            const float want = in ? after[i] : before[i];
            ASSERT_NEAR(back[i], want, std::abs(want) * 0x1p-11f + 1e-7f) << name(format) << " " << x << " " << y << " " << z;
          }
        }
    EXPECT_EQ(inside, 4u * 8 * 8 + 8 * 4 * 1);
    const size_t scalar = format == TexelFormat::float16 ? 2 : 4;
    EXPECT_EQ(t.stats().bytes, (cells + inside) * 2 * scalar);
  }
}

TEST(Texture, RefusesBadInputNamingTheField) {
  HeadlessContext context;
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([] { Texture::volume({4, 0, 4}, 1, TexelFormat::float32); }).find("texture size"), std::string::npos);
  EXPECT_NE(message([] { Texture::plane(4, 4, 5, TexelFormat::float32); }).find("texture channels"), std::string::npos);
  Texture t = Texture::volume({4, 4, 4}, 1, TexelFormat::float32);
  const std::vector<float> short_values(63, 1.0f), values(64, 1.0f);
  EXPECT_NE(message([&] { t.upload(short_values); }).find("63 floats"), std::string::npos);
  const Brick outside{{2, 0, 0}, {3, 1, 1}};
  EXPECT_NE(message([&] { t.upload(values, std::span(&outside, 1)); }).find("bricks[0]"), std::string::npos);
}

TEST(Texture, NeedsACurrentContext) {
  EXPECT_THROW(Texture::plane(4, 4, 1, TexelFormat::float32), Error);
}

}  // namespace
}  // namespace haze::gl
