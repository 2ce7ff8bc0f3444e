// Image files: EXR round trip (with the standard-error layer), PNG preview, error measures.
#include <haze/core/error.h>
#include <haze/core/image.h>

#include <gtest/gtest.h>

#include <fstream>

namespace haze {
namespace {

std::filesystem::path temp_path(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("haze_image_test_" + std::to_string(::getpid()) + "_" + name);
}

TEST(Image, ExrRoundTripKeepsLinearFloats) {
  Image img(5, 3), err(5, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) {
      img.set(x, y, Rgb(x * 0.1, y * 10.0, 1e-6 + x * y));
      err.set(x, y, Rgb(0.01 * x, 0.02, 0.03 * y));
    }
  auto path = temp_path("a.exr");
  write_exr(path, img, &err);
  std::optional<Image> err_back;
  Image back = read_exr(path, &err_back);
  ASSERT_EQ(back.width(), 5);
  ASSERT_EQ(back.height(), 3);
  ASSERT_TRUE(err_back.has_value());
  EXPECT_EQ(back.data(), img.data());
  EXPECT_EQ(err_back->data(), err.data());
  write_exr(path, img);
  read_exr(path, &err_back);
  EXPECT_FALSE(err_back.has_value());
  std::filesystem::remove(path);
}

TEST(Image, PngPreviewIsWritten) {
  Image img(4, 4);
  img.set(1, 1, Rgb(1.0, 0.5, 100.0));
  auto path = temp_path("b.png");
  write_png(path, img);
  std::ifstream in(path, std::ios::binary);
  char sig[8] = {};
  in.read(sig, 8);
  EXPECT_EQ(std::string(sig + 1, 3), "PNG");
  std::filesystem::remove(path);
}

TEST(Image, ErrorsNameTheProblem) {
  EXPECT_THROW(Image(0, 4), Error);
  EXPECT_THROW(read_exr("/nonexistent/haze.exr"), Error);
  EXPECT_THROW(write_png("/nonexistent/dir/x.png", Image(1, 1)), Error);
  EXPECT_THROW(rmse(Image(1, 2), Image(2, 1)), Error);
}

TEST(Image, RmseAndMean) {
  Image a(2, 1), b(2, 1);
  a.set(0, 0, Rgb(1.0));
  b.set(0, 0, Rgb(1.0));
  b.set(1, 0, Rgb(1.0));
  EXPECT_NEAR(rmse(a, b), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(relative_rmse(a, b), std::sqrt(0.5), 1e-12);
  EXPECT_EQ(b.mean(), Rgb(1.0));
}

}  // namespace
}  // namespace haze
