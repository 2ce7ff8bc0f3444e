// Image files: EXR round trip (with the standard-error layer), PNG preview, error measures.
#include <haze/core/error.h>
#include <haze/core/image.h>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>

namespace haze {
namespace {

std::filesystem::path temp_path(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("haze_image_test_" + std::to_string(::getpid()) + "_" + name);
}

std::string file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
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

// Layers beside the image as name.R/G/B; a host's depth buffer read from a Z (or depth) channel,
// and a file with neither is an error naming the file.
TEST(Image, ExrLayersAndDepthChannel) {
  Image img(3, 2), l(3, 2);
  l.set(2, 1, Rgb(0.5, 0.25, 4.0));
  const auto path = temp_path("layers.exr");
  write_exr(path, img, {{"inscatter", &l}, {"transmittance", &img}});
  {
    Imf::InputFile file(path.string().c_str());
    for (const char* c : {"R", "inscatter.R", "inscatter.B", "transmittance.G"}) EXPECT_NE(file.header().channels().findChannel(c), nullptr) << c;
  }
  const std::vector<float> z = {1.0f, 2.5f, INFINITY, 0.0f, 7.0f, 3.0f};
  int w = 0, h = 0;
  for (const char* name : {"Z", "depth"}) {
    {
      Imf::Header header(3, 2);
      header.channels().insert(name, Imf::Channel(Imf::FLOAT));
      Imf::FrameBuffer fb;
      fb.insert(name, Imf::Slice(Imf::FLOAT, const_cast<char*>(reinterpret_cast<const char*>(z.data())), sizeof(float), 3 * sizeof(float)));
      Imf::OutputFile out(path.string().c_str(), header);
      out.setFrameBuffer(fb);
      out.writePixels(2);
    }
    EXPECT_EQ(read_exr_depth(path, w, h), z) << name;
    EXPECT_EQ(w, 3);
    EXPECT_EQ(h, 2);
    // Read as an image (haze compare), its missing R, G, B would be zeros: refused, naming what it has.
    try {
      read_exr(path);
      FAIL() << "read a " << name << "-only EXR as RGB";
    } catch (const Error& e) {
      EXPECT_EQ(e.value(), std::string("channels ") + name) << e.what();
      EXPECT_EQ(e.expected(), "channels R, G and B");
    }
  }
  write_exr(path, img);
  try {
    read_exr_depth(path, w, h);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(e.field().find(path.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no channel Z or depth"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

// A header is checked before anything it claims is allocated: a file of 256 KB may claim a data
// window of 2^29 pixels (2 GB a channel), and one whose pixels are not all written would read as zeros.
TEST(Image, ExrHeadersAreCheckedBeforeThePixels) {
  const auto path = temp_path("claims.exr");
  write_exr(path, Image(1, 1));
  std::string bytes = file_bytes(path);
  // dataWindow's value: int size 16, then min.x, min.y, max.x, max.y.
  const std::string name("dataWindow\0box2i\0", 17);
  const auto at = bytes.find(name);
  ASSERT_NE(at, std::string::npos);
  const std::int32_t max[2] = {(1 << 15) - 1, (1 << 14) - 1};
  bytes.replace(at + name.size() + 4 + 8, 8, reinterpret_cast<const char*>(max), 8);
  bytes.append(std::size_t{1} << 18, '\0');  // room for the line offsets OpenEXR reads first
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  try {
    read_exr(path);
    FAIL() << "read a header claiming 2^29 pixels";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "exr input " + path.string());
    EXPECT_EQ(e.value(), "a data window of 32768 x 16384 pixels");
    EXPECT_EQ(e.expected(), "at most 2^28 pixels");
  }
  // Before OpenEXR reads a header: an attribute claiming 1.2 GB (OpenEXR would fill a string that
  // long), and a window of more chunks than the file has bytes for their offsets.
  write_exr_table(path, 1, 1, {0.5f}, {{"key", "abc"}});
  bytes = file_bytes(path);
  const std::string key("haze.key\0string\0", 16);
  const auto key_at = bytes.find(key);
  ASSERT_NE(key_at, std::string::npos);
  const std::int32_t claim = 0x4a000019;
  bytes.replace(key_at + key.size(), 4, reinterpret_cast<const char*>(&claim), 4);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  int w = 0, h = 0;
  std::map<std::string, std::string> attributes;
  try {
    read_exr_table(path, w, h, attributes);
    FAIL() << "read a header claiming a 1.2 GB attribute";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "exr table " + path.string());
    EXPECT_EQ(e.value().rfind("an attribute 'haze.key' of 1241514009 bytes with ", 0), 0u) << e.value();
  }
  write_exr(path, Image(1, 1));
  bytes = file_bytes(path);
  const std::int32_t tall[2] = {0, (1 << 30) - 1};
  bytes.replace(bytes.find(name) + name.size() + 4 + 8, 8, reinterpret_cast<const char*>(tall), 8);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  try {
    read_exr_depth(path, w, h);
    FAIL() << "read a header claiming 2^30 lines";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "depth " + path.string());
    EXPECT_NE(e.value().find("a data window of 1 x 1073741824 pixels in 1 x "), std::string::npos) << e.value();
    EXPECT_EQ(e.expected(), "a file that holds its chunks' offsets (8 bytes each)");
  }
  // A channel list stated 4 bytes longer than its entries: OpenEXR reads the entries and goes on
  // from their end, so the walk must not trust the stated size (fuzz_exr's second finding hid a
  // 1 GB string attribute that way).
  write_exr(path, Image(1, 1));
  bytes = file_bytes(path);
  const std::string channels("channels\0chlist\0", 16);
  const auto size_at = bytes.find(channels) + channels.size();
  std::int32_t stated;
  std::memcpy(&stated, bytes.data() + size_at, 4);
  stated += 4;
  bytes.replace(size_at, 4, reinterpret_cast<const char*>(&stated), 4);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  try {
    read_exr(path);
    FAIL() << "read a channel list shorter than stated";
  } catch (const Error& e) {
    EXPECT_EQ(e.value(), "an attribute 'channels' of type chlist whose value ends before its stated size") << e.what();
  }
  {  // One line of two written: the other's offset stays zero.
    Imf::Header header(3, 2);
    header.compression() = Imf::NO_COMPRESSION;
    header.channels().insert("Z", Imf::Channel(Imf::FLOAT));
    const std::vector<float> z(6, 1.0f);
    Imf::FrameBuffer fb;
    fb.insert("Z", Imf::Slice(Imf::FLOAT, const_cast<char*>(reinterpret_cast<const char*>(z.data())), sizeof(float), 3 * sizeof(float)));
    Imf::OutputFile out(path.string().c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(1);
  }
  try {
    read_exr_depth(path, w, h);
    FAIL() << "read an EXR with a line missing";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "depth " + path.string());
    EXPECT_EQ(e.value(), "a file whose pixels are not all there");
  }
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

// Three pixels lit (the fourth is below 1% of the peak), errors +10%, -20%, 0; standard errors 5%.
// Images hold float32, hence 1e-7.
TEST(Image, LitPixelError) {
  Image image(4, 1), reference(4, 1), se(4, 1);
  const double ref[4] = {1.0, 2.0, 4.0, 0.001}, ours[4] = {1.1, 1.6, 4.0, 7.0};
  for (int x = 0; x < 4; ++x) {
    reference.set(x, 0, Rgb(ref[x]));
    image.set(x, 0, Rgb(ours[x]));
    se.set(x, 0, Rgb(0.05 * ref[x]));
  }
  const LitPixelError e = lit_pixel_error(image, reference, &se);
  EXPECT_EQ(e.pixels, 3);
  EXPECT_NEAR(e.mean_abs, 0.1, 1e-7);
  EXPECT_NEAR(e.signed_mean, -0.1 / 3.0, 1e-7);
  EXPECT_NEAR(e.noise_rms, 0.05, 1e-7);
  EXPECT_NEAR(e.signed_mean_error, std::sqrt(3 * 0.0025) / 3.0, 1e-7);
  EXPECT_NEAR(e.rms_noise_removed, std::sqrt((0.01 + 0.04 - 3 * 0.0025) / 3.0), 1e-7);
  EXPECT_EQ(lit_pixel_error(image, reference, nullptr, &image).pixels, 4);  // lit by another image
  EXPECT_THROW(lit_pixel_error(Image(3, 1), reference), Error);

  // The same pixels by their share of the squared error less the noise: 0.04 - 0.0025 first,
  // 0.01 - 0.0025 next, of a sum 0.0425 (the exact pixel's -0.0025 included).
  const std::vector<PixelError> worst = worst_pixels(image, reference, &se, 2);
  ASSERT_EQ(worst.size(), 2u);
  EXPECT_EQ(worst[0].x, 1);
  EXPECT_NEAR(worst[0].relative, -0.2, 1e-7);
  EXPECT_NEAR(worst[0].noise, 0.05, 1e-7);
  EXPECT_NEAR(worst[0].share, 0.0375 / 0.0425, 1e-6);
  EXPECT_EQ(worst[1].x, 0);
  EXPECT_NEAR(worst[1].share, 0.0075 / 0.0425, 1e-6);
  EXPECT_EQ(worst_pixels(image, reference, &se, 10).size(), 3u);  // the lit ones, at most
  EXPECT_THROW(worst_pixels(Image(3, 1), reference, nullptr, 1), Error);
}

}  // namespace
}  // namespace haze
