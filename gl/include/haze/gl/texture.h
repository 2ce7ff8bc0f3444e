// Textures haze::gl streams Haze's fields into: volumes (3D: density, optical depth per light,
// multiple-scattering moments) and planes (2D: network arrays), stored as float16 or float32.
// Uploads go through a pair of pixel-buffer regions (persistently mapped under GL 4.4, mapped per
// upload before that): the CPU writes the next update into one while GL may still read the last
// from the other, and a fence per region says when it is free again. A partial upload writes only
// the bricks that changed.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze::gl {

enum class TexelFormat { float16, float32 };
const char* name(TexelFormat format);

// A box of cells (texels): origin and size along x, y, z (z: origin 0, size 1 for a plane).
struct Brick {
  std::array<int, 3> origin{0, 0, 0};
  std::array<int, 3> size{0, 0, 0};
};

struct UploadStats {
  size_t uploads = 0;
  size_t bytes = 0;          // texel bytes written into the pixel buffer (after float16 packing)
  bool persistent = false;   // the pixel buffer stays mapped (GL 4.4 buffer storage)
};

class Texture {
 public:
  // Both need a current HeadlessContext on the calling thread, and use it for their lifetime.
  // `channels` values per texel (1 to 4), interleaved. Throws haze::Error for a size < 1, more than
  // the driver's largest texture, or channels outside 1..4.
  static Texture volume(std::array<int, 3> resolution, int channels, TexelFormat format);
  static Texture plane(int width, int height, int channels, TexelFormat format);
  Texture(Texture&&) noexcept;
  Texture& operator=(Texture&&) noexcept;
  ~Texture();

  // Every texel, from `values`: channels per texel, x fastest, then y, then z (DenseGrid's order).
  // Throws haze::Error when values.size() is not texels * channels.
  void upload(std::span<const float> values);
  // Only the texels inside `bricks`, read from the whole field `values` (same layout as above).
  // Throws haze::Error for a brick outside the texture.
  void upload(std::span<const float> values, std::span<const Brick> bricks);
  // The texels as GL holds them (float16 ones widened), in upload()'s layout.
  std::vector<float> read() const;

  unsigned id() const;
  bool is_volume() const;
  const std::array<int, 3>& size() const;  // x, y, z (z = 1 for a plane)
  int channels() const;
  TexelFormat format() const;
  const UploadStats& stats() const;

 private:
  struct Impl;
  explicit Texture(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// The bricks of a `brick_size`^3 tiling of `resolution` in which `changed` (one flag per cell,
// DenseGrid order) has any cell set; the last bricks along an axis are cut at the edge.
std::vector<Brick> changed_bricks(const std::array<int, 3>& resolution, std::span<const unsigned char> changed, int brick_size = 16);

}  // namespace haze::gl

#pragma GCC visibility pop
