// The demo's animated GIF (apps/gif.cpp) read back by giflib's decoder: its size, frames, each
// frame's delay and the NETSCAPE2.0 loop block, and every pixel within the 8-bit preview's
// quantization of what was written; bad input gets haze::Error.
#include "gif.h"

#include <haze/core/error.h>

#include <gif_lib.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace haze::app {
namespace {

// A smooth gradient, shifted per frame, in linear radiance.
Image gradient(int width, int height, int frame) {
  Image image(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      image.set(x, y, Rgb(0.02 * ((x + frame) % width), 0.5 * y / height, 0.3 + 0.1 * frame));
  return image;
}

TEST(AnimatedGif, ReadsBackItsFramesDelayLoopAndColours) {
  const auto path = std::filesystem::path(::testing::TempDir()) / "haze_gif_test.gif";
  const int width = 40, height = 24, frames = 3;
  {
    AnimatedGif gif(path, width, height, 4);
    for (int f = 0; f < frames; ++f) gif.add(gradient(width, height, f), 2.0);
    gif.close();
  }
  int error = 0;
  GifFileType* gif = DGifOpenFileName(path.string().c_str(), &error);
  ASSERT_NE(gif, nullptr) << GifErrorString(error);
  ASSERT_EQ(DGifSlurp(gif), GIF_OK);
  EXPECT_EQ(gif->SWidth, width);
  EXPECT_EQ(gif->SHeight, height);
  ASSERT_EQ(gif->ImageCount, frames);
  // giflib keeps the blocks before an image with it: the loop block comes with the first.
  bool loops = false;
  for (int i = 0; i < gif->SavedImages[0].ExtensionBlockCount; ++i) {
    const ExtensionBlock& b = gif->SavedImages[0].ExtensionBlocks[i];
    loops |= b.Function == APPLICATION_EXT_FUNC_CODE && b.ByteCount == 11 && std::memcmp(b.Bytes, "NETSCAPE2.0", 11) == 0;
  }
  EXPECT_TRUE(loops);
  int worst = 0;
  for (int f = 0; f < frames; ++f) {
    GraphicsControlBlock control;
    ASSERT_EQ(DGifSavedExtensionToGCB(gif, f, &control), GIF_OK);
    EXPECT_EQ(control.DelayTime, 4);
    const SavedImage& frame = gif->SavedImages[f];
    const ColorMapObject* map = frame.ImageDesc.ColorMap;
    ASSERT_NE(map, nullptr);
    const Image want = gradient(width, height, f);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const GifColorType c = map->Colors[frame.RasterBits[y * width + x]];
        const Rgb w = want.at(x, y) * 2.0;
        worst = std::max({worst, std::abs(c.Red - preview_byte(w.r)), std::abs(c.Green - preview_byte(w.g)), std::abs(c.Blue - preview_byte(w.b))});
      }
  }
  // Median cut to 256 colours over a 960-pixel gradient: each channel within a few levels.
  EXPECT_LE(worst, 8);
  DGifCloseFile(gif, &error);
  std::filesystem::remove(path);
}

TEST(AnimatedGif, NamesWhatIsWrong) {
  try {
    AnimatedGif gif("/nonexistent-dir/preview.gif", 8, 8, 4);
    FAIL() << "no error for an unwritable path";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/preview.gif"), std::string::npos) << e.what();
  }
  const auto path = std::filesystem::path(::testing::TempDir()) / "haze_gif_size.gif";
  AnimatedGif gif(path, 8, 8, 4);
  try {
    gif.add(Image(9, 8), 1.0);
    FAIL() << "no error for a frame of the wrong size";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("9x8"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("8x8"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace haze::app
