// Geometry and colour types: GLM double vectors for geometry and RGB, rays, boxes, frames.
// float64 is used for geometry and estimates; float32 is for stored fields and SIMD kernels.
#pragma once

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

using Vec3 = glm::dvec3;
using Vec3f = glm::vec3;
// Linear RGB radiance, coefficients or albedo: one value per channel.
using Rgb = glm::dvec3;

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kInv4Pi = 1.0 / (4.0 * std::numbers::pi);
inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

struct Ray {
  Vec3 origin{0.0};
  Vec3 direction{0.0, 0.0, 1.0};  // unit length
  Vec3 at(double t) const { return origin + t * direction; }
};

// The largest |component|: the max norm.
inline double max_abs(const Vec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

// "[x, y, z]", for error messages (error.h's to_text for points and directions).
inline std::string to_text(const Vec3& v) {
  std::ostringstream out;
  out << '[' << v.x << ", " << v.y << ", " << v.z << ']';
  return out.str();
}

// d scaled to unit length, or false (d unchanged) for a zero or non-finite vector. Dividing by the
// largest component first keeps huge and tiny vectors (1e-300, 1e200) from under- or overflowing.
inline bool make_unit(Vec3& d) {
  const double m = max_abs(d);
  if (!(m > 0.0) || !std::isfinite(m)) return false;
  d = glm::normalize(d / m);
  return true;
}

// Axis-aligned box; the default box is unbounded (all of space).
struct Aabb {
  Vec3 lo{-kInfinity};
  Vec3 hi{kInfinity};

  bool bounded() const { return std::isfinite(lo.x + lo.y + lo.z + hi.x + hi.y + hi.z); }
  bool contains(const Vec3& p) const {
    return p.x >= lo.x && p.y >= lo.y && p.z >= lo.z && p.x <= hi.x && p.y <= hi.y && p.z <= hi.z;
  }
  Vec3 extent() const { return hi - lo; }
  bool operator==(const Aabb&) const = default;
  // Clips the ray's [t0, t1] to the box (slab test); false when they do not overlap.
  bool clip(const Ray& ray, double& t0, double& t1) const;
};

// An orthonormal frame around a unit vector (Duff et al. 2017, branchless).
struct Frame {
  Vec3 s, t, n;
  static Frame from_z(const Vec3& n);
  Vec3 to_world(const Vec3& local) const { return local.x * s + local.y * t + local.z * n; }
};

// Direction with the given cosine to `axis` and azimuth phi around it.
Vec3 direction_around(const Vec3& axis, double cos_theta, double phi);

inline double luminance(const Rgb& c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }
// The same value in every channel: a grey coefficient or light, which one channel can carry.
inline bool is_grey(const Rgb& c) { return c.r == c.g && c.g == c.b; }

}  // namespace haze

#pragma GCC visibility pop
