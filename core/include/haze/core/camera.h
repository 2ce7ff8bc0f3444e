// Cameras: pinhole and orthographic. Image rows run top to bottom; pixel (x, y)'s ray goes through
// its centre, (x + 0.5, y + 0.5).
#pragma once

#include <haze/core/math.h>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

struct Camera {
  enum class Type { pinhole, orthographic };
  Type type = Type::pinhole;
  Vec3 position{0.0, 0.0, 5.0};
  Vec3 look_at{0.0};
  Vec3 up{0.0, 1.0, 0.0};
  double height = 2.0;     // orthographic: world extent of the image height
  double fov_y_deg = 40.0; // pinhole: full vertical field of view
  int width_px = 64;
  int height_px = 64;

  // Ray through film position (px, py) in pixels, (0, 0) the top-left corner.
  Ray generate_ray(double px, double py) const;
  Ray pixel_ray(int x, int y) const { return generate_ray(x + 0.5, y + 0.5); }
  bool operator==(const Camera&) const = default;
};

}  // namespace haze

#pragma GCC visibility pop
