// An animated GIF through giflib 5: the NETSCAPE2.0 loop block, then per frame a graphics control
// block (its delay) and an image with its own colour map.
#include "gif.h"

#include <haze/core/error.h>

#include <fcntl.h>
#include <gif_lib.h>
#include <unistd.h>

#include <array>

namespace haze::app {

AnimatedGif::AnimatedGif(const std::filesystem::path& path, int width, int height, int delay_cs)
    : path_(path), width_(width), height_(height), delay_cs_(delay_cs) {
  int error = 0;
  // giflib's EGifOpenFileName makes the file private (0600); a preview is made to be shared.
  const int fd = ::open(path.string().c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0666);
  if (fd < 0) throw Error("gif output", path.string(), "a writable file");
  gif_ = EGifOpenFileHandle(fd, &error);
  if (!gif_) ::close(fd);
  if (!gif_) throw Error("gif output", path.string(), std::string("a file giflib can write (") + GifErrorString(error) + ")");
  EGifSetGifVersion(gif_, true);
  check(EGifPutScreenDesc(gif_, width, height, 8, 0, nullptr), "its screen");
  const std::array<GifByteType, 3> loop_forever{1, 0, 0};
  check(EGifPutExtensionLeader(gif_, APPLICATION_EXT_FUNC_CODE), "its loop block");
  check(EGifPutExtensionBlock(gif_, 11, "NETSCAPE2.0"), "its loop block");
  check(EGifPutExtensionBlock(gif_, static_cast<int>(loop_forever.size()), loop_forever.data()), "its loop block");
  check(EGifPutExtensionTrailer(gif_), "its loop block");
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  red_.resize(pixels), green_.resize(pixels), blue_.resize(pixels), indices_.resize(pixels);
}

AnimatedGif::~AnimatedGif() {
  if (gif_) EGifCloseFile(gif_, nullptr);
}

void AnimatedGif::check(int status, const char* what) {
  if (status == GIF_OK) return;
  const int code = gif_ ? gif_->Error : 0;
  throw Error("gif output", path_.string(), std::string("a file giflib can write ") + what + " to (" + GifErrorString(code) + ")");
}

void AnimatedGif::add(const Image& radiance, double exposure) {
  if (radiance.width() != width_ || radiance.height() != height_)
    throw Error("gif frame", std::to_string(radiance.width()) + "x" + std::to_string(radiance.height()),
                "the animation's size, " + std::to_string(width_) + "x" + std::to_string(height_));
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const Rgb c = radiance.at(x, y) * exposure;
      const size_t i = static_cast<size_t>(y) * static_cast<size_t>(width_) + static_cast<size_t>(x);
      red_[i] = preview_byte(c.r), green_[i] = preview_byte(c.g), blue_[i] = preview_byte(c.b);
    }
  std::array<GifColorType, 256> colours{};
  int size = static_cast<int>(colours.size());
  check(GifQuantizeBuffer(static_cast<unsigned>(width_), static_cast<unsigned>(height_), &size, red_.data(), green_.data(), blue_.data(),
                          indices_.data(), colours.data()),
        "a frame's colours");
  ColorMapObject* map = GifMakeMapObject(256, colours.data());
  if (!map) throw Error("gif output", path_.string(), "memory for a colour map");
  GraphicsControlBlock control{};
  control.DisposalMode = DISPOSE_DO_NOT;
  control.DelayTime = delay_cs_;
  control.TransparentColor = NO_TRANSPARENT_COLOR;
  std::array<GifByteType, 4> block{};
  EGifGCBToExtension(&control, block.data());
  int status = EGifPutExtension(gif_, GRAPHICS_EXT_FUNC_CODE, static_cast<int>(block.size()), block.data());
  if (status == GIF_OK) status = EGifPutImageDesc(gif_, 0, 0, width_, height_, false, map);
  for (int y = 0; y < height_ && status == GIF_OK; ++y) status = EGifPutLine(gif_, &indices_[static_cast<size_t>(y) * static_cast<size_t>(width_)], width_);
  GifFreeMapObject(map);
  check(status, "a frame");
}

void AnimatedGif::close() {
  int error = 0;
  GifFileType* gif = gif_;
  gif_ = nullptr;
  if (gif && EGifCloseFile(gif, &error) != GIF_OK)
    throw Error("gif output", path_.string(), std::string("a file giflib can finish (") + GifErrorString(error) + ")");
}

}  // namespace haze::app
