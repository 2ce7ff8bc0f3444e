#include <haze/core/error.h>
#include <haze/core/image.h>
#include <haze/core/progress.h>

#include "exr_layout.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <png.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string_view>

namespace haze {

Image::Image(int width, int height) {
  if (width <= 0 || height <= 0 || static_cast<long long>(width) * height > (1LL << 28))
    throw Error("image size", to_text(width) + " x " + to_text(height), "positive sizes with at most 2^28 pixels");
  width_ = width, height_ = height;
  pixels_.assign(3 * static_cast<size_t>(width) * static_cast<size_t>(height), 0.0f);
}

template <class Float>
void check_span(const BasicImageSpan<Float>& span, std::string_view field) {
  const auto name = [&](const char* part) { return std::string(field) + part; };  // only on an error: a frame's checks allocate nothing
  if (!span.data || span.width < 1 || span.height < 1)
    throw Error(name(""), to_text(span.width) + " x " + to_text(span.height) + (span.data ? "" : " without data"), "an image of at least 1 x 1 pixels");
  if (span.channels != 3 && span.channels != 4) throw Error(name(".channels"), to_text(span.channels), "3 (RGB) or 4 (RGBA)");
  if (span.stride && span.stride < static_cast<std::size_t>(span.width) * static_cast<std::size_t>(span.channels))
    throw Error(name(".stride"), to_text(span.stride) + " floats", "at least width x channels = " + to_text(span.width * span.channels));
}
template void check_span(const BasicImageSpan<float>&, std::string_view);
template void check_span(const BasicImageSpan<const float>&, std::string_view);

Rgb Image::mean() const {
  Rgb sum(0.0);
  for (size_t i = 0; i < pixels_.size(); i += 3) sum += Rgb(pixels_[i], pixels_[i + 1], pixels_[i + 2]);
  return pixels_.empty() ? sum : sum / static_cast<double>(pixels_.size() / 3);
}

namespace {

const char* kChannels[3] = {"R", "G", "B"};

void insert_layer(Imf::FrameBuffer& fb, const std::string& prefix, const Image& image) {
  auto* base = const_cast<char*>(reinterpret_cast<const char*>(image.data().data()));
  for (int c = 0; c < 3; ++c)
    fb.insert(prefix + kChannels[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), 3 * sizeof(float),
                                                3 * sizeof(float) * static_cast<size_t>(image.width())));
}

void check_same_size(const Image& a, const Image& b, const char* what) {
  if (a.width() != b.width() || a.height() != b.height())
    throw Error(what, to_text(b.width()) + " x " + to_text(b.height()),
                "the size of the image, " + to_text(a.width()) + " x " + to_text(a.height()));
}

constexpr long long kMaxPixels = 1LL << 28;  // as Image's

// The size of an open EXR's data window, checked before its pixels are allocated (naming
// `field`): a header of a few bytes may claim any size, and missing pixels would read as zeros.
void window_size(const Imf::InputFile& file, const std::string& field, std::size_t bytes_per_pixel, int& width, int& height) {
  const auto window = file.header().dataWindow();  // OpenEXR keeps its corners within +-2^30
  const long long w = static_cast<long long>(window.max.x) - window.min.x + 1, h = static_cast<long long>(window.max.y) - window.min.y + 1;
  if (w <= 0 || h <= 0 || w * h > kMaxPixels)
    throw Error(field, "a data window of " + to_text(w) + " x " + to_text(h) + " pixels", "at most 2^28 pixels");
  check_memory(static_cast<std::size_t>(w * h) * bytes_per_pixel, 0, field, to_text(w) + " x " + to_text(h) + " pixels", "a smaller image");
  if (!file.isComplete()) throw Error(field, "a file whose pixels are not all there", "a complete OpenEXR file");
  width = static_cast<int>(w), height = static_cast<int>(h);
}

// One float channel of an open EXR, x fastest from its data window's corner; its size through
// width and height.
// The slice base OpenEXR addresses pixel (x, y) of the data window from: `data` less the window
// origin's offset, in integers (a window not at 0 puts it outside the buffer, which pointer
// arithmetic may not reach: the fuzzer's undefined-behaviour check found one).
char* window_base(void* data, const Imath::Box2i& window, int width, size_t pixel_bytes) {
  const auto offset = (static_cast<ptrdiff_t>(window.min.y) * width + window.min.x) * static_cast<ptrdiff_t>(pixel_bytes);
  return reinterpret_cast<char*>(reinterpret_cast<uintptr_t>(data) - static_cast<uintptr_t>(offset));
}

std::vector<float> read_channel(Imf::InputFile& file, const std::string& field, const char* channel, int& width, int& height) {
  window_size(file, field, sizeof(float), width, height);
  const auto window = file.header().dataWindow();
  std::vector<float> values(static_cast<size_t>(width) * static_cast<size_t>(height));
  Imf::FrameBuffer fb;
  fb.insert(channel, Imf::Slice(Imf::FLOAT, window_base(values.data(), window, width, sizeof(float)), sizeof(float), sizeof(float) * static_cast<size_t>(width)));
  file.setFrameBuffer(fb);
  file.readPixels(window.min.y, window.max.y);
  return values;
}

}  // namespace

void write_exr(const std::filesystem::path& path, const Image& image, const Image* std_error) {
  std::vector<std::pair<std::string, const Image*>> layers;
  if (std_error) layers.emplace_back("stderr", std_error);
  write_exr(path, image, layers);
}

void write_exr(const std::filesystem::path& path, const Image& image, const std::vector<std::pair<std::string, const Image*>>& layers) {
  for (const auto& [name, layer] : layers) check_same_size(image, *layer, (name + " image size").c_str());
  try {
    Imf::Header header(image.width(), image.height());
    Imf::FrameBuffer fb;
    for (const char* c : kChannels) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    insert_layer(fb, "", image);
    for (const auto& [name, layer] : layers) {
      for (const char* c : kChannels) header.channels().insert(name + "." + c, Imf::Channel(Imf::FLOAT));
      insert_layer(fb, name + ".", *layer);
    }
    Imf::OutputFile file(path.string().c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(image.height());
  } catch (const std::exception& e) {
    throw Error("exr output " + path.string(), e.what(), "a writable file");
  }
}

Image read_exr(const std::filesystem::path& path, std::optional<Image>* std_error) {
  const std::string field = "exr input " + path.string();
  try {
    check_exr_layout(path, field);
    Imf::InputFile file(path.string().c_str());
    // Missing channels would read as zeros: an image of other channels (a 1-channel Y or Z) is refused.
    std::string channels;
    for (auto c = file.header().channels().begin(); c != file.header().channels().end(); ++c) channels += (channels.empty() ? "" : ", ") + std::string(c.name());
    for (const char* name : {"R", "G", "B"})
      if (!file.header().channels().findChannel(name))
        throw Error(field, "channels " + (channels.empty() ? std::string("(none)") : channels), "channels R, G and B");
    const bool has_error = file.header().channels().findChannel("stderr.R") != nullptr;
    int width = 0, height = 0;
    window_size(file, field, (std_error && has_error ? 2 : 1) * 3 * sizeof(float), width, height);
    const auto window = file.header().dataWindow();
    Image image(width, height);
    if (std_error) *std_error = has_error ? std::optional<Image>(Image(image.width(), image.height())) : std::nullopt;
    Imf::FrameBuffer fb;
    insert_layer(fb, "", image);
    if (std_error && has_error) insert_layer(fb, "stderr.", **std_error);
    // The slices are addressed from the data window's origin.
    for (auto it = fb.begin(); it != fb.end(); ++it) {
      auto& slice = it.slice();
      slice.base = window_base(slice.base, window, image.width(), 3 * sizeof(float));
    }
    file.setFrameBuffer(fb);
    file.readPixels(window.min.y, window.max.y);
    return image;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(field, e.what(), "a readable OpenEXR file");
  }
}

std::vector<float> read_exr_depth(const std::filesystem::path& path, int& width, int& height) {
  const std::string field = "depth " + path.string();
  try {
    check_exr_layout(path, field);
    Imf::InputFile file(path.string().c_str());
    const char* channel = file.header().channels().findChannel("Z") ? "Z" : file.header().channels().findChannel("depth") ? "depth" : nullptr;
    if (!channel)
      throw Error(field, "no channel Z or depth", "an EXR with a float channel Z (or depth): distances along each pixel's ray");
    return read_channel(file, field, channel, width, height);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(field, e.what(), "a readable OpenEXR file");
  }
}

void write_exr_table(const std::filesystem::path& path, int width, int height, const std::vector<float>& values,
                     const std::map<std::string, std::string>& attributes) {
  if (width <= 0 || height <= 0 || values.size() != static_cast<size_t>(width) * static_cast<size_t>(height))
    throw Error("table size", to_text(values.size()) + " values", to_text(width) + " x " + to_text(height));
  try {
    Imf::Header header(width, height);
    header.channels().insert("T", Imf::Channel(Imf::FLOAT));
    for (const auto& [key, value] : attributes) header.insert("haze." + key, Imf::StringAttribute(value));
    Imf::FrameBuffer fb;
    fb.insert("T", Imf::Slice(Imf::FLOAT, const_cast<char*>(reinterpret_cast<const char*>(values.data())), sizeof(float),
                              sizeof(float) * static_cast<size_t>(width)));
    Imf::OutputFile file(path.string().c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(height);
  } catch (const std::exception& e) {
    throw Error("exr output " + path.string(), e.what(), "a writable file");
  }
}

std::vector<float> read_exr_table(const std::filesystem::path& path, int& width, int& height,
                                  std::map<std::string, std::string>& attributes) {
  const std::string field = "exr table " + path.string();
  try {
    check_exr_layout(path, field);
    Imf::InputFile file(path.string().c_str());
    if (!file.header().channels().findChannel("T")) throw Error(field, "no channel T", "a Haze table");
    attributes.clear();
    for (auto it = file.header().begin(); it != file.header().end(); ++it) {
      std::string name = it.name();
      if (name.rfind("haze.", 0) != 0) continue;
      if (auto* a = dynamic_cast<const Imf::StringAttribute*>(&it.attribute())) attributes[name.substr(5)] = a->value();
    }
    return read_channel(file, field, "T", width, height);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(field, e.what(), "a readable OpenEXR table");
  }
}

unsigned char preview_byte(double v) {
  v = std::isfinite(v) ? std::max(0.0, v) : 0.0;
  v = v / (1.0 + v);
  v = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  return static_cast<unsigned char>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
}

void write_png(const std::filesystem::path& path, const Image& image, double exposure) {
  std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.string().c_str(), "wb"), &std::fclose);
  if (!file) throw Error("png output", path.string(), "a writable file");
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, nullptr);
    throw Error("png output", path.string(), "memory for libpng");
  }
  std::vector<unsigned char> row(3 * static_cast<size_t>(image.width()));
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw Error("png output", path.string(), "a file libpng could write");
  }
  png_init_io(png, file.get());
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width()), static_cast<png_uint_32>(image.height()), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_text text{};
  text.compression = PNG_TEXT_COMPRESSION_NONE;
  text.key = const_cast<char*>("Comment");
  text.text = const_cast<char*>("Haze preview: tone-mapped (exposure, Reinhard, sRGB), not data; the EXR holds linear radiance");
  png_set_text(png, info, &text, 1);
  png_write_info(png, info);
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      const Rgb c = image.at(x, y) * exposure;
      for (int k = 0; k < 3; ++k) row[3 * static_cast<size_t>(x) + static_cast<size_t>(k)] = preview_byte(c[k]);
    }
    png_write_row(png, row.data());
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
}

double rmse(const Image& a, const Image& b) {
  check_same_size(a, b, "image size");
  double sum = 0.0;
  for (size_t i = 0; i < a.data().size(); ++i) {
    double d = static_cast<double>(a.data()[i]) - static_cast<double>(b.data()[i]);
    sum += d * d;
  }
  return std::sqrt(sum / static_cast<double>(a.data().size()));
}

double rms(const Image& image) {
  double sum = 0.0;
  for (float v : image.data()) sum += static_cast<double>(v) * static_cast<double>(v);
  return std::sqrt(sum / static_cast<double>(std::max<size_t>(1, image.data().size())));
}

double relative_rmse(const Image& a, const Image& reference) {
  double scale = rms(reference);
  return scale > 0.0 ? rmse(a, reference) / scale : rmse(a, reference);
}

namespace {

// Calls visit(x, y, d, se) for every lit pixel (luminance of `mask` at least `threshold` times its
// peak), d = (image - reference) / reference and se = standard error / reference (0 without
// reference_std_error), all in luminance: the pixels lit_pixel_error and worst_pixels measure.
template <class Visit>
void for_each_lit_pixel(const Image& image, const Image& reference, const Image* reference_std_error, const Image& mask,
                        double threshold, const Visit& visit) {
  if (image.width() != reference.width() || image.height() != reference.height() || mask.width() != reference.width() ||
      mask.height() != reference.height())
    throw Error("image", to_text(image.width()) + " x " + to_text(image.height()),
                "the reference's size, " + to_text(reference.width()) + " x " + to_text(reference.height()));
  double peak = 0.0;
  for (int y = 0; y < mask.height(); ++y)
    for (int x = 0; x < mask.width(); ++x) peak = std::max(peak, luminance(mask.at(x, y)));
  for (int y = 0; y < reference.height(); ++y)
    for (int x = 0; x < reference.width(); ++x) {
      if (luminance(mask.at(x, y)) < threshold * peak) continue;
      const double ref = luminance(reference.at(x, y));
      visit(x, y, (luminance(image.at(x, y)) - ref) / ref, reference_std_error ? luminance(reference_std_error->at(x, y)) / ref : 0.0);
    }
}

}  // namespace

LitPixelError lit_pixel_error(const Image& image, const Image& reference, const Image* reference_std_error, const Image* lit,
                              double threshold) {
  LitPixelError e;
  double squared = 0.0, noise = 0.0;
  for_each_lit_pixel(image, reference, reference_std_error, lit ? *lit : reference, threshold, [&](int, int, double d, double se) {
    e.mean_abs += std::abs(d), e.signed_mean += d, squared += d * d, noise += se * se;
    ++e.pixels;
  });
  if (e.pixels == 0) return e;
  const double n = e.pixels;
  e.mean_abs /= n, e.signed_mean /= n;
  if (reference_std_error) {
    e.noise_rms = std::sqrt(noise / n);
    e.signed_mean_error = std::sqrt(noise) / n;
    e.rms_noise_removed = std::sqrt(std::max(0.0, (squared - noise) / n));
  }
  return e;
}

std::vector<PixelError> worst_pixels(const Image& image, const Image& reference, const Image* reference_std_error, int count,
                                     double threshold) {
  std::vector<PixelError> all;
  double total = 0.0;
  for_each_lit_pixel(image, reference, reference_std_error, reference, threshold, [&](int x, int y, double d, double se) {
    all.push_back({x, y, d, se, d * d - se * se});
    total += all.back().share;
  });
  const auto n = std::min(all.size(), static_cast<size_t>(std::max(count, 0)));
  std::partial_sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(n), all.end(),
                    [](const PixelError& a, const PixelError& b) { return a.share > b.share; });
  all.resize(n);
  for (PixelError& e : all) e.share = total > 0.0 ? e.share / total : 0.0;
  return all;
}

}  // namespace haze
