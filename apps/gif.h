// An animated GIF (giflib), looping: the previews `haze demo` writes of each paper's scene moving.
#pragma once

#include <haze/core/image.h>

#include <filesystem>
#include <string>
#include <vector>

struct GifFileType;

namespace haze::app {

class AnimatedGif {
 public:
  // Opens `path` for frames of width x height shown `delay_cs` hundredths of a second each; throws
  // haze::Error naming the path when giflib cannot write it.
  AnimatedGif(const std::filesystem::path& path, int width, int height, int delay_cs);
  ~AnimatedGif();
  AnimatedGif(const AnimatedGif&) = delete;
  AnimatedGif& operator=(const AnimatedGif&) = delete;

  // One frame of linear radiance, tone-mapped as write_png does (exposure, Reinhard, sRGB) and
  // reduced to its own 256 colours (giflib's median cut).
  void add(const Image& radiance, double exposure);
  // Writes the trailer; throws haze::Error if giflib fails (the destructor closes silently).
  void close();

 private:
  void check(int status, const char* what);
  std::filesystem::path path_;
  int width_, height_, delay_cs_;
  GifFileType* gif_ = nullptr;
  std::vector<unsigned char> red_, green_, blue_, indices_;
};

}  // namespace haze::app
