// Opaque surfaces that block and reflect light: planes, spheres and triangle meshes (mesh.h) with energy-normalized BRDFs
// (docs/SCENES.md, "surfaces"): Lambert kd / pi plus Phong ks (n + 2) / (2 pi) cos^n(alpha). The thesis (seed 002)
// writes kd and ks cos^n; its constants are folded in here.
#pragma once

#include <haze/core/math.h>
#include <haze/core/mesh.h>

#include <memory>

#include <utility>
#include <variant>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

struct Plane {
  Vec3 point{0.0};
  Vec3 normal{0.0, 1.0, 0.0};  // unit
};

struct Sphere {
  Vec3 center{0.0};
  double radius = 1.0;
};

// A triangle mesh, shared between copies of a scene.
struct Mesh {
  std::shared_ptr<const TriangleMesh> triangles;
};

// A surface Haze does not shade (the host does: "shaded": false in a scene file) has kd = ks = 0:
// it casts shadows, ends view rays as a host's depth would (C = 0) and reflects nothing.
struct Surface {
  std::variant<Plane, Sphere, Mesh> shape;
  Rgb kd{0.5};
  Rgb ks{0.0};
  double shininess = 1.0;

  // Nearest hit with t in (t_min, t_max); writes t and the unit normal facing the ray's origin.
  bool intersect(const Ray& ray, double t_min, double t_max, double& t, Vec3& normal) const;
  // f(wi, wo) per steradian: wi points toward the light, wo toward the viewer, n the unit normal.
  Rgb brdf(const Vec3& wi, const Vec3& wo, const Vec3& n) const;
};

// How far a ray leaving a surface starts off it, along the normal: the least t a hit may have.
inline constexpr double kSurfaceOffset = 1e-7;

// The nearest of `surfaces` hit by the ray with t in (kSurfaceOffset, t_max), or nullptr; writes its t and
// normal (facing the ray's origin).
const Surface* nearest_surface(const std::vector<Surface>& surfaces, const Ray& ray, double t_max, double& t, Vec3& normal);
// Whether a surface blocks the segment from x along the unit dir over distance (infinite for the
// sun and the sky), short of its end by 1e-9 of it: a light on a surface is not hidden by it.
bool occluded(const std::vector<Surface>& surfaces, const Vec3& x, const Vec3& dir, double distance);
// Surface point p stepped off along `normal` by 1e-9 of its size: enough to leave a face of the
// medium's box the surface lies on, which rounding alone puts in or out point by point.
inline Vec3 off_surface(const Vec3& p, const Vec3& normal) { return p + 1e-9 * (1.0 + glm::length(p)) * normal; }

// The stretches [a, b] of ray.at(t), t in [t0, t1] (t1 may be infinite), from which a light at
// `light` is not hidden by a surface, in order; appended to `out`. Exact for planes and spheres:
// the line crosses a shadow's edge only where it crosses a plane, a sphere or the cone from the
// light tangent to a sphere, so between those crossings occluded() at one point decides. A mesh's
// shadow edges are found by bisection between 64 points along the stretch (a shadow shorter than
// 1/64 of it can be missed).
void lit_stretches(const std::vector<Surface>& surfaces, const Ray& ray, double t0, double t1, const Vec3& light,
                   std::vector<std::pair<double, double>>& out);

// The cheap questions before lit_stretches and occluded() for one point light, its constants per
// surface computed once. classify: does the light see all of a view stretch, none of it, or part
// of it? Planes' and spheres' shadow edges (their surfaces and the tangent cones past their
// tangent circles) in closed form; with no edge inside the stretch, hidden() at its middle decides. A
// mesh in the scene makes every stretch `partial` (lit_stretches bisects it). hidden: occluded()
// from x toward the light, planes and spheres in closed form, meshes by their own test; `self`,
// a plane or sphere x lies on with the light on its outer side, is left out. The surfaces must
// outlive this object.
class LightShadows {
 public:
  enum class Stretch { lit, dark, partial };
  LightShadows(const std::vector<Surface>& surfaces, const Vec3& light);
  Stretch classify(const Ray& ray, double t0, double t1) const;
  bool hidden(const Vec3& x, const Surface* self = nullptr) const;

  // The constants, for batched forms of these tests (method analytic's shadow_batch.h).
  struct Cone {
    const Surface* surface;
    Vec3 center, axis;  // the sphere's centre; the unit axis from the light through it
    double r2, cos2;    // radius squared; cos^2 of the tangent cone's half-angle (0: the light inside)
  };
  struct Face {
    const Surface* surface;
    Vec3 point, normal;
  };
  const Vec3& light() const { return light_; }
  const std::vector<Cone>& spheres() const { return spheres_; }
  const std::vector<Face>& planes() const { return planes_; }
  bool meshes() const { return !meshes_.empty(); }

 private:
  Vec3 light_;
  std::vector<Cone> spheres_;
  std::vector<Face> planes_;
  std::vector<const Surface*> meshes_;
};

}  // namespace haze

#pragma GCC visibility pop
