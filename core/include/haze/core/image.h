// RGB float images (linear, rows top to bottom) and their files: OpenEXR holds linear float data,
// PNG holds a tone-mapped 8-bit preview only.
#pragma once

#include <haze/core/math.h>

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <optional>
#include <utility>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

class Image {
 public:
  Image() = default;
  Image(int width, int height);  // zero-filled; throws haze::Error for sizes <= 0 or too large

  int width() const { return width_; }
  int height() const { return height_; }
  Rgb at(int x, int y) const {
    const float* p = &pixels_[index(x, y)];
    return {p[0], p[1], p[2]};
  }
  void set(int x, int y, const Rgb& c) {
    float* p = &pixels_[index(x, y)];
    p[0] = static_cast<float>(c.r), p[1] = static_cast<float>(c.g), p[2] = static_cast<float>(c.b);
  }
  // Interleaved RGB, 3 floats per pixel.
  const std::vector<float>& data() const { return pixels_; }
  std::vector<float>& data() { return pixels_; }
  Rgb mean() const;

 private:
  size_t index(int x, int y) const { return 3 * (static_cast<size_t>(y) * static_cast<size_t>(width_) + static_cast<size_t>(x)); }
  int width_ = 0, height_ = 0;
  std::vector<float> pixels_;
};

// A caller's float32 image in its own memory, as a GL pixel-buffer upload takes it: `channels`
// floats a pixel (3: RGB; 4: RGBA, the fourth left as it is), rows top to bottom `stride` floats
// apart (0: width * channels). Viewed, never owned.
template <class Float>
struct BasicImageSpan {
  Float* data = nullptr;
  int width = 0, height = 0, channels = 3;
  std::size_t stride = 0;
  std::size_t row_floats() const { return stride ? stride : static_cast<std::size_t>(width) * static_cast<std::size_t>(channels); }
  Float* pixel(int x, int y) const { return data + static_cast<std::size_t>(y) * row_floats() + static_cast<std::size_t>(x) * static_cast<std::size_t>(channels); }
};
using ImageSpan = BasicImageSpan<float>;
using ConstImageSpan = BasicImageSpan<const float>;
// Throws haze::Error naming `field` unless the span has data, a size >= 1, 3 or 4 channels, and
// rows at least width * channels floats apart.
template <class Float>
void check_span(const BasicImageSpan<Float>& span, std::string_view field);

// Writes linear float RGB ("R", "G", "B"); with std_error, also its layer "stderr.R/G/B".
void write_exr(const std::filesystem::path& path, const Image& image, const Image* std_error = nullptr);
// The same with named layers of the same size beside it, each as "name.R/G/B" ("stderr",
// "inscatter", "transmittance", "surface").
void write_exr(const std::filesystem::path& path, const Image& image, const std::vector<std::pair<std::string, const Image*>>& layers);
// A host's depth buffer: the one float channel "Z" (or "depth") of an EXR, rows top to bottom;
// its size comes back through width and height. A file without either channel throws haze::Error.
std::vector<float> read_exr_depth(const std::filesystem::path& path, int& width, int& height);
// Reads the "R", "G", "B" channels; with std_error, also the "stderr" layer when present.
Image read_exr(const std::filesystem::path& path, std::optional<Image>* std_error = nullptr);
// 8-bit sRGB preview, tone-mapped with exposure then Reinhard x / (1 + x): not data.
void write_png(const std::filesystem::path& path, const Image& image, double exposure = 1.0);
// A linear value as write_png shows it: Reinhard x / (1 + x), sRGB, 8 bits (0 for NaN or below 0).
unsigned char preview_byte(double linear);

// One float channel "T" (a precomputed table, x fastest) with string attributes, as an EXR.
void write_exr_table(const std::filesystem::path& path, int width, int height, const std::vector<float>& values,
                     const std::map<std::string, std::string>& attributes);
// Reads a table written by write_exr_table; sizes and attributes come back through the arguments.
std::vector<float> read_exr_table(const std::filesystem::path& path, int& width, int& height,
                                  std::map<std::string, std::string>& attributes);

// Root mean square over pixels and channels.
double rms(const Image& image);
// Root mean square over pixels and channels of (a - b); sizes must match.
double rmse(const Image& a, const Image& b);
// rmse(a, b) / rms(b): the relative error `haze demo` reports against the reference.
double relative_rmse(const Image& a, const Image& reference);

// Per-pixel relative error of `image` against `reference` (luminance), over the lit pixels: those
// where `lit` (the reference when null) is at least `threshold` of its peak. With the reference's
// per-pixel standard error, also its noise and what it does to the measures.
struct LitPixelError {
  int pixels = 0;
  double mean_abs = 0.0;     // mean |d|, d = (image - reference) / reference
  double signed_mean = 0.0;  // mean d: the bias, in which the reference's noise averages out
  // With reference_std_error (zero otherwise):
  double noise_rms = 0.0;           // sqrt(mean se^2), se = standard error / reference
  double signed_mean_error = 0.0;   // standard error of signed_mean, sqrt(sum se^2) / pixels
  double rms_noise_removed = 0.0;   // sqrt(max(0, mean(d^2 - se^2))): bounds the noise-free mean |d|
};
LitPixelError lit_pixel_error(const Image& image, const Image& reference, const Image* reference_std_error = nullptr,
                              const Image* lit = nullptr, double threshold = 0.01);

// Where lit_pixel_error's error comes from: the `count` lit pixels with the largest d^2 - se^2,
// largest first, each with its share of that sum over all lit pixels.
struct PixelError {
  int x = 0, y = 0;
  double relative = 0.0;  // d
  double noise = 0.0;     // se (0 without reference_std_error)
  double share = 0.0;
};
std::vector<PixelError> worst_pixels(const Image& image, const Image& reference, const Image* reference_std_error, int count,
                                     double threshold = 0.01);

}  // namespace haze

#pragma GCC visibility pop
