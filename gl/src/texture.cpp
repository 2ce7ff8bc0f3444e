// Texture upload through a two-region pixel-buffer ring with a fence per region (texture.h).
#include <haze/gl/texture.h>

#include <haze/core/error.h>
#include <haze/simd/half.h>

#include "api.h"

#include <algorithm>
#include <cstring>
#include <string>

namespace haze::gl {

using internal::Api;

const char* name(TexelFormat format) { return format == TexelFormat::float16 ? "float16" : "float32"; }

namespace {

constexpr int kRegions = 2;

GLenum pixel_format(int channels) {
  const GLenum formats[] = {GL_RED, GL_RG, GL_RGB, GL_RGBA};
  return formats[channels - 1];
}

GLenum internal_format(int channels, TexelFormat format) {
  const GLenum half[] = {GL_R16F, GL_RG16F, GL_RGB16F, GL_RGBA16F};
  const GLenum full[] = {GL_R32F, GL_RG32F, GL_RGB32F, GL_RGBA32F};
  return (format == TexelFormat::float16 ? half : full)[channels - 1];
}

std::string dims(const std::array<int, 3>& n) {
  return std::to_string(n[0]) + " x " + std::to_string(n[1]) + " x " + std::to_string(n[2]);
}

}  // namespace

struct Texture::Impl {
  const Api& gl = internal::api();
  GLenum target = GL_TEXTURE_3D;
  GLuint texture = 0, buffer = 0;
  std::array<int, 3> size{1, 1, 1};
  int channels = 1;
  TexelFormat format = TexelFormat::float32;
  size_t region_bytes = 0;  // one whole upload
  unsigned char* mapped = nullptr;  // persistent mapping of both regions, or nullptr
  GLsync fences[kRegions] = {nullptr, nullptr};
  int next = 0;
  UploadStats stats;

  Impl(GLenum target_, std::array<int, 3> size_, int channels_, TexelFormat format_)
      : target(target_), size(size_), channels(channels_), format(format_) {
    if (channels < 1 || channels > 4) throw Error("texture channels", std::to_string(channels), "1 to 4");
    GLint largest = 0;
    gl.GetIntegerv(target == GL_TEXTURE_3D ? GL_MAX_3D_TEXTURE_SIZE : GL_MAX_TEXTURE_SIZE, &largest);
    for (int n : size)
      if (n < 1 || n > largest)
        throw Error("texture size", dims(size), "every side in 1.." + std::to_string(largest) + " (this driver's largest)");
    region_bytes = texels() * static_cast<size_t>(channels) * texel_scalar_bytes();

    gl.GenTextures(1, &texture);
    gl.BindTexture(target, texture);
    const GLenum ifmt = internal_format(channels, format);
    if (target == GL_TEXTURE_3D) {
      gl.TexImage3D(target, 0, static_cast<GLint>(ifmt), size[0], size[1], size[2], 0, pixel_format(channels), GL_FLOAT, nullptr);
      gl.TexParameteri(target, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    } else {
      gl.TexImage2D(target, 0, static_cast<GLint>(ifmt), size[0], size[1], 0, pixel_format(channels), GL_FLOAT, nullptr);
    }
    // Linear filtering over cell-centred texels, clamped to the edge cells: the CPU's trilinear stencil.
    gl.TexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl.TexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.TexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);

    gl.GenBuffers(1, &buffer);
    gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, buffer);
    const auto total = static_cast<GLsizeiptr>(kRegions * region_bytes);
    if (gl.BufferStorage) {
      const GLbitfield flags = GL_MAP_WRITE_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
      gl.BufferStorage(GL_PIXEL_UNPACK_BUFFER, total, nullptr, flags);
      mapped = static_cast<unsigned char*>(gl.MapBufferRange(GL_PIXEL_UNPACK_BUFFER, 0, total, flags));
    } else {
      gl.BufferData(GL_PIXEL_UNPACK_BUFFER, total, nullptr, GL_STREAM_DRAW);
    }
    gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    stats.persistent = mapped != nullptr;
    internal::check(gl, "texture creation");
  }

  ~Impl() {
    for (GLsync& f : fences)
      if (f) gl.DeleteSync(f);
    if (mapped) {
      gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, buffer);
      gl.UnmapBuffer(GL_PIXEL_UNPACK_BUFFER);
      gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    }
    gl.DeleteBuffers(1, &buffer);
    gl.DeleteTextures(1, &texture);
  }

  size_t texels() const { return static_cast<size_t>(size[0]) * static_cast<size_t>(size[1]) * static_cast<size_t>(size[2]); }
  size_t texel_scalar_bytes() const { return format == TexelFormat::float16 ? 2 : 4; }

  // Waits until GL has finished reading the next region, then gives the CPU a pointer into it.
  unsigned char* acquire(size_t bytes) {
    GLsync& fence = fences[next];
    if (fence) {
      while (gl.ClientWaitSync(fence, GL_SYNC_FLUSH_COMMANDS_BIT, 1000000000) == GL_TIMEOUT_EXPIRED) {
      }
      gl.DeleteSync(fence);
      fence = nullptr;
    }
    gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, buffer);
    const size_t offset = static_cast<size_t>(next) * region_bytes;
    if (mapped) return mapped + offset;
    // The fence has passed, so nothing reads this range: no need for GL to synchronize.
    const GLbitfield flags = GL_MAP_WRITE_BIT | GL_MAP_INVALIDATE_RANGE_BIT | GL_MAP_UNSYNCHRONIZED_BIT;
    return static_cast<unsigned char*>(gl.MapBufferRange(GL_PIXEL_UNPACK_BUFFER, static_cast<GLintptr>(offset),
                                                         static_cast<GLsizeiptr>(std::max<size_t>(bytes, 1)), flags));
  }

  // After the CPU wrote: unmap (when not persistent); copy() issues the texture copies from the region.
  template <class Copy>
  void release(size_t bytes, Copy copy) {
    if (!mapped) gl.UnmapBuffer(GL_PIXEL_UNPACK_BUFFER);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    copy(static_cast<size_t>(next) * region_bytes);
    gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    fences[next] = gl.FenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    next = (next + 1) % kRegions;
    stats.uploads += 1;
    stats.bytes += bytes;
    internal::check(gl, "texture upload");
  }

  // `count` floats to the region as float32 or float16.
  void write(const float* from, size_t count, unsigned char* to) const {
    if (format == TexelFormat::float16) {
      simd::to_half(from, reinterpret_cast<simd::Half*>(to), count);
    } else {
      std::memcpy(to, from, count * sizeof(float));
    }
  }

  GLenum type() const { return format == TexelFormat::float16 ? GL_HALF_FLOAT : GL_FLOAT; }

  void sub_image(const Brick& b, size_t offset) const {
    const auto* at = reinterpret_cast<const void*>(offset);
    if (target == GL_TEXTURE_3D) {
      gl.TexSubImage3D(target, 0, b.origin[0], b.origin[1], b.origin[2], b.size[0], b.size[1], b.size[2], pixel_format(channels), type(), at);
    } else {
      gl.TexSubImage2D(target, 0, b.origin[0], b.origin[1], b.size[0], b.size[1], pixel_format(channels), type(), at);
    }
  }

  void check_values(std::span<const float> values) const {
    if (values.size() != texels() * static_cast<size_t>(channels))
      throw Error("texture values", std::to_string(values.size()) + " floats",
                  std::to_string(texels() * static_cast<size_t>(channels)) + " (" + dims(size) + " texels x " + std::to_string(channels) +
                      " channels)");
  }
};

Texture::Texture(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Texture::Texture(Texture&&) noexcept = default;
Texture& Texture::operator=(Texture&&) noexcept = default;
Texture::~Texture() = default;

Texture Texture::volume(std::array<int, 3> resolution, int channels, TexelFormat format) {
  return Texture(std::make_unique<Impl>(GL_TEXTURE_3D, resolution, channels, format));
}

Texture Texture::plane(int width, int height, int channels, TexelFormat format) {
  return Texture(std::make_unique<Impl>(GL_TEXTURE_2D, std::array<int, 3>{width, height, 1}, channels, format));
}

void Texture::upload(std::span<const float> values) {
  Impl& t = *impl_;
  t.check_values(values);
  unsigned char* region = t.acquire(t.region_bytes);
  t.write(values.data(), values.size(), region);
  t.gl.BindTexture(t.target, t.texture);
  t.release(t.region_bytes, [&](size_t offset) { t.sub_image(Brick{{0, 0, 0}, t.size}, offset); });
}

void Texture::upload(std::span<const float> values, std::span<const Brick> bricks) {
  Impl& t = *impl_;
  t.check_values(values);
  size_t bytes = 0;
  for (size_t i = 0; i < bricks.size(); ++i) {
    const Brick& b = bricks[i];
    for (int a = 0; a < 3; ++a)
      if (b.size[a] < 1 || b.origin[a] < 0 || b.origin[a] + b.size[a] > t.size[static_cast<size_t>(a)])
        throw Error("bricks[" + std::to_string(i) + "]", "origin " + dims(b.origin) + ", size " + dims(b.size),
                    "a non-empty box inside the texture's " + dims(t.size) + " texels");
    bytes += static_cast<size_t>(b.size[0]) * static_cast<size_t>(b.size[1]) * static_cast<size_t>(b.size[2]) *
             static_cast<size_t>(t.channels) * t.texel_scalar_bytes();
  }
  if (bytes == 0) return;
  unsigned char* region = t.acquire(bytes);
  // Each brick packed row by row (rows of channels * size.x floats are contiguous in the field).
  const auto c = static_cast<size_t>(t.channels);
  size_t at = 0;
  for (const Brick& b : bricks)
    for (int z = b.origin[2]; z < b.origin[2] + b.size[2]; ++z)
      for (int y = b.origin[1]; y < b.origin[1] + b.size[1]; ++y) {
        const size_t first = ((static_cast<size_t>(z) * static_cast<size_t>(t.size[1]) + static_cast<size_t>(y)) * static_cast<size_t>(t.size[0]) +
                              static_cast<size_t>(b.origin[0])) * c;
        const size_t count = static_cast<size_t>(b.size[0]) * c;
        t.write(values.data() + first, count, region + at);
        at += count * t.texel_scalar_bytes();
      }
  t.gl.BindTexture(t.target, t.texture);
  t.release(bytes, [&](size_t offset) {
    for (const Brick& b : bricks) {
      t.sub_image(b, offset);
      offset += static_cast<size_t>(b.size[0]) * static_cast<size_t>(b.size[1]) * static_cast<size_t>(b.size[2]) * c * t.texel_scalar_bytes();
    }
  });
}

std::vector<float> Texture::read() const {
  const Impl& t = *impl_;
  std::vector<float> values(t.texels() * static_cast<size_t>(t.channels));
  t.gl.BindTexture(t.target, t.texture);
  t.gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  t.gl.GetTexImage(t.target, 0, pixel_format(t.channels), GL_FLOAT, values.data());
  internal::check(t.gl, "texture read");
  return values;
}

unsigned Texture::id() const { return impl_->texture; }
bool Texture::is_volume() const { return impl_->target == GL_TEXTURE_3D; }
const std::array<int, 3>& Texture::size() const { return impl_->size; }
int Texture::channels() const { return impl_->channels; }
TexelFormat Texture::format() const { return impl_->format; }
const UploadStats& Texture::stats() const { return impl_->stats; }

std::vector<Brick> changed_bricks(const std::array<int, 3>& resolution, std::span<const unsigned char> changed, int brick_size) {
  if (brick_size < 1) throw Error("brick_size", std::to_string(brick_size), "at least 1");
  const size_t cells = static_cast<size_t>(resolution[0]) * static_cast<size_t>(resolution[1]) * static_cast<size_t>(resolution[2]);
  if (changed.size() != cells) throw Error("changed", std::to_string(changed.size()) + " flags", std::to_string(cells) + ", one per cell");
  std::vector<Brick> bricks;
  for (int z0 = 0; z0 < resolution[2]; z0 += brick_size)
    for (int y0 = 0; y0 < resolution[1]; y0 += brick_size)
      for (int x0 = 0; x0 < resolution[0]; x0 += brick_size) {
        const Brick b{{x0, y0, z0},
                      {std::min(brick_size, resolution[0] - x0), std::min(brick_size, resolution[1] - y0), std::min(brick_size, resolution[2] - z0)}};
        bool any = false;
        for (int z = z0; z < z0 + b.size[2] && !any; ++z)
          for (int y = y0; y < y0 + b.size[1] && !any; ++y) {
            const size_t row = (static_cast<size_t>(z) * static_cast<size_t>(resolution[1]) + static_cast<size_t>(y)) * static_cast<size_t>(resolution[0]);
            any = std::any_of(changed.begin() + static_cast<std::ptrdiff_t>(row + static_cast<size_t>(x0)),
                              changed.begin() + static_cast<std::ptrdiff_t>(row + static_cast<size_t>(x0 + b.size[0])), [](unsigned char f) { return f != 0; });
          }
        if (any) bricks.push_back(b);
      }
  return bricks;
}

}  // namespace haze::gl
