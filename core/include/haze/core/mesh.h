// Triangle meshes as opaque surfaces (docs/SCENES.md, "surfaces"): from OBJ files (tinyobjloader) or
// from a caller's vertex and index buffers, placed by an affine transform, ray queries through
// Embree. A mesh is shared, immutable once built, and safe to query from any thread.
#pragma once

#include <haze/core/math.h>

#include <glm/mat4x4.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

// A view of the caller's buffers: `vertex_count` positions of 3 floats, `stride_bytes` apart (an
// interleaved vertex buffer works as it is), and triangles as index triples into them.
struct MeshBuffers {
  const float* positions = nullptr;
  std::size_t vertex_count = 0;
  std::size_t stride_bytes = 3 * sizeof(float);
  std::span<const std::uint32_t> indices = {};
};

class TriangleMesh {
 public:
  // From the caller's buffers, world = transform * local (glm's column-major 4 x 4, affine). The
  // positions are transformed and copied into the acceleration structure once: a change to the
  // buffers needs a new mesh. A bad view (null positions, a count of indices not a multiple of 3,
  // an index past the vertices, a non-finite position or transform) is a haze::Error naming
  // `field` and what was wrong.
  static std::shared_ptr<const TriangleMesh> from_buffers(const MeshBuffers& buffers, const glm::dmat4& transform = glm::dmat4(1.0),
                                                          const std::string& field = "mesh");
  // Every shape and group of an OBJ file, triangulated (polygons fanned); materials, normals and
  // texture coordinates are not read. A file that is missing or does not parse, or holds no
  // triangle, is a haze::Error naming `field` and the file.
  static std::shared_ptr<const TriangleMesh> load_obj(const std::filesystem::path& file, const glm::dmat4& transform = glm::dmat4(1.0),
                                                      const std::string& field = "file");
  ~TriangleMesh();
  TriangleMesh(const TriangleMesh&) = delete;
  TriangleMesh& operator=(const TriangleMesh&) = delete;

  // The nearest hit with t in (t_min, t_max): writes t, the unit geometric normal facing the ray's
  // origin and the triangle's index. Rays are traced in float32 (Embree): hits closer than
  // kSelfHit (1 + |origin|) are skipped, so that a ray leaving a mesh's face does not hit it again.
  bool intersect(const Ray& ray, double t_min, double t_max, double& t, Vec3& normal, std::uint32_t* triangle = nullptr) const;
  // Whether any triangle is hit with t in (t_min, t_max), with the same skip.
  bool occluded(const Ray& ray, double t_min, double t_max) const;

  std::size_t triangle_count() const { return indices_.size() / 3; }
  const std::vector<Vec3f>& positions() const { return positions_; }  // world space
  const std::vector<std::uint32_t>& indices() const { return indices_; }
  Vec3 vertex(std::size_t triangle, int corner) const { return Vec3(positions_[indices_[3 * triangle + static_cast<std::size_t>(corner)]]); }
  const Aabb& bounds() const { return bounds_; }

  static constexpr double kSelfHit = 1e-5;

 private:
  TriangleMesh() = default;
  void build(const std::string& field);
  std::vector<Vec3f> positions_;  // as placed (Embree holds its own padded copy)
  std::vector<std::uint32_t> indices_;
  Aabb bounds_;
  struct Embree;
  std::unique_ptr<Embree> embree_;
};

// An affine placement from its parts: scale (per axis), then rotations about x, y and z in turn
// (degrees, right-handed), then the translation.
glm::dmat4 placement(const Vec3& translate, const Vec3& rotate_deg, const Vec3& scale);

}  // namespace haze

#pragma GCC visibility pop
