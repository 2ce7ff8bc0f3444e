// Cameras: pinhole and orthographic, a host renderer's own view and projection matrices, or its
// own per-pixel rays. Image rows run top to bottom; pixel (x, y)'s ray goes through its centre,
// (x + 0.5, y + 0.5). Ray directions are unit vectors, so distances along a ray (a depth buffer's)
// are world lengths from its origin.
#pragma once

#include <haze/core/math.h>

#include <glm/mat4x4.hpp>

#include <memory>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

struct Camera {
  // matrices: OpenGL's conventions (docs/HOST.md): `view` takes world to eye space, the eye looking
  // down -z; `projection` takes eye to clip space, NDC x, y, z in [-1, 1] after the divide by w
  // (glm::perspective, glm::ortho, glm::frustum: column-major glm::dmat4). Pixel (x, y) is at
  // NDC x = 2 (x + 0.5) / width_px - 1, y = 1 - 2 (y + 0.5) / height_px (row 0 at the top, as
  // Haze's images; GL's window rows run bottom up). A perspective ray starts at the eye, an
  // orthographic one on the eye plane (eye z = 0), through the pixel's point on the near plane.
  // rays: `rays` holds width_px * height_px rays, row-major, rows top to bottom, unit directions;
  // shared, not copied.
  enum class Type { pinhole, orthographic, matrices, rays };
  Type type = Type::pinhole;
  Vec3 position{0.0, 0.0, 5.0};
  Vec3 look_at{0.0};
  Vec3 up{0.0, 1.0, 0.0};
  double height = 2.0;     // orthographic: world extent of the image height
  double fov_y_deg = 40.0; // pinhole: full vertical field of view
  int width_px = 64;
  int height_px = 64;
  // Type::matrices, set by from_matrices (with their inverses, which rays are made from).
  glm::dmat4 view{1.0}, projection{1.0}, view_inverse{1.0}, projection_inverse{1.0};
  std::shared_ptr<const std::vector<Ray>> rays;  // Type::rays

  // A camera from a host's matrices or rays, checked: a projection that cannot be inverted, or
  // rays of the wrong count or with a direction not of unit length (within 1e-6) or not finite,
  // throw haze::Error naming the field.
  static Camera from_matrices(const glm::dmat4& view, const glm::dmat4& projection, int width_px, int height_px);
  static Camera from_rays(std::shared_ptr<const std::vector<Ray>> rays, int width_px, int height_px);

  // Ray through film position (px, py) in pixels, (0, 0) the top-left corner.
  Ray generate_ray(double px, double py) const;
  Ray pixel_ray(int x, int y) const { return generate_ray(x + 0.5, y + 0.5); }
  // The rays of row y's pixels, out[x] = pixel_ray(x, y) (the camera's frame made once per row).
  void row_rays(int y, Ray* out) const { row_rays(y, 0, width_px, out); }
  // Those of pixels [x0, x1) of row y, out[x - x0].
  void row_rays(int y, int x0, int x1, Ray* out) const;
  // The film position (px, py) whose ray passes through `point` (generate_ray's inverse), for a
  // pinhole camera or a host's perspective matrices; false for a point behind the eye and for
  // other cameras.
  bool film_position(const Vec3& point, double& px, double& py) const;
  // The rays of film row py leave `position` along normalize(a + b px) for every px: a pinhole
  // camera, or a host's perspective matrices (their w not depending on x); false for others.
  bool row_frame(double py, Vec3& a, Vec3& b) const;
  // The point every ray leaves from: a pinhole camera's position, a host's perspective matrices'
  // eye; false for others.
  bool eye(Vec3& at) const;
  // The angle between the rays of the two pixels right of the film's centre (radians): a pixel's
  // width as seen from the eye there.
  double pixel_angle() const;
  bool operator==(const Camera&) const = default;

 private:
  // Film positions (px[i], py) of one row; pinhole and orthographic make their frame once.
  void row_rays_at(double py, const double* px, int count, Ray* out) const;
  // A pinhole or orthographic camera's unit frame.
  void frame(Vec3& forward, Vec3& right, Vec3& true_up) const;
};

}  // namespace haze

#pragma GCC visibility pop
