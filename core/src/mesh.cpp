#include <haze/core/error.h>
#include <haze/core/limits.h>
#include <haze/core/mesh.h>

#include <embree3/rtcore.h>
#include <glm/common.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>

namespace haze {

namespace {

// One Embree device for the process, made on first use (devices are thread-safe).
RTCDevice device() {
  static std::once_flag once;
  static RTCDevice shared = nullptr;
  std::call_once(once, [] { shared = rtcNewDevice("verbose=0"); });
  if (!shared) throw Error("mesh", "Embree", "an Embree device (rtcNewDevice failed: " + std::to_string(rtcGetDeviceError(nullptr)) + ")");
  return shared;
}

bool finite(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return m[0][3] == 0.0 && m[1][3] == 0.0 && m[2][3] == 0.0 && m[3][3] == 1.0;
}

// Skip distance for a ray from `origin` (TriangleMesh::kSelfHit).
float near_limit(const Ray& ray, double t_min) {
  const double scale = 1.0 + max_abs(ray.origin);
  return static_cast<float>(std::max(t_min, TriangleMesh::kSelfHit * scale));
}

// Embree refuses rays whose origin lies past 1.8e18 (its FLT_LARGE): rays from farther than
// kLargest start near the mesh's bounds instead (vertices lie within kMaxCoordinate).
constexpr double kLargest = 1e15;

// The ray, or for a far origin the same line from where it meets `bounds` (t_min and t_max moved
// with it); false when a far ray misses the bounds.
bool near_start(const Ray& ray, const Aabb& bounds, Ray& local, double& t_min, double& t_max) {
  local = ray;
  if (max_abs(ray.origin) <= kLargest) return true;
  const Vec3 pad(1e-3 * (1.0 + glm::length(bounds.extent())));
  double t0 = t_min, t1 = t_max;
  if (!Aabb{bounds.lo - pad, bounds.hi + pad}.clip(ray, t0, t1)) return false;
  // Clamped: origin + t0 direction cancels to within the origin's rounding, which may be far.
  local.origin = glm::clamp(ray.origin + t0 * ray.direction, bounds.lo - pad, bounds.hi + pad);
  t_min -= t0, t_max -= t0;
  return true;
}

RTCRay embree_ray(const Ray& ray, double t_min, double t_max) {
  RTCRay r;
  r.org_x = static_cast<float>(ray.origin.x), r.org_y = static_cast<float>(ray.origin.y), r.org_z = static_cast<float>(ray.origin.z);
  r.dir_x = static_cast<float>(ray.direction.x), r.dir_y = static_cast<float>(ray.direction.y), r.dir_z = static_cast<float>(ray.direction.z);
  r.tnear = near_limit(ray, t_min);
  r.tfar = std::isfinite(t_max) ? static_cast<float>(t_max) : std::numeric_limits<float>::infinity();
  r.time = 0.0f, r.mask = ~0u, r.id = 0, r.flags = 0;
  return r;
}

}  // namespace

struct TriangleMesh::Embree {
  RTCScene scene = nullptr;
  ~Embree() {
    if (scene) rtcReleaseScene(scene);
  }
};

TriangleMesh::~TriangleMesh() = default;

glm::dmat4 placement(const Vec3& translate, const Vec3& rotate_deg, const Vec3& scale) {
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), translate);
  m = glm::rotate(m, glm::radians(rotate_deg.z), Vec3(0.0, 0.0, 1.0));
  m = glm::rotate(m, glm::radians(rotate_deg.y), Vec3(0.0, 1.0, 0.0));
  m = glm::rotate(m, glm::radians(rotate_deg.x), Vec3(1.0, 0.0, 0.0));
  return glm::scale(m, scale);
}

void TriangleMesh::build(const std::string& field) {
  const size_t vertices = positions_.size();
  for (size_t i = 0; i < indices_.size(); ++i)
    if (indices_[i] >= vertices)
      throw Error(field + ".indices[" + std::to_string(i) + "]", std::to_string(indices_[i]),
                  "an index below the vertex count, " + std::to_string(vertices));
  if (indices_.empty()) throw Error(field, "no triangles", "a mesh of at least one triangle");
  bounds_ = Aabb{Vec3(kInfinity), Vec3(-kInfinity)};
  for (const Vec3f& p : positions_) bounds_.lo = glm::min(bounds_.lo, Vec3(p)), bounds_.hi = glm::max(bounds_.hi, Vec3(p));

  RTCDevice dev = device();
  embree_ = std::make_unique<Embree>();
  embree_->scene = rtcNewScene(dev);
  // Robust traversal: a ray through a shared edge or vertex hits one of its triangles.
  rtcSetSceneFlags(embree_->scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(embree_->scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry geometry = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
  // Embree's own buffers (padded as it needs); positions_ and indices_ stay for other uses.
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertices));
  auto* t = static_cast<std::uint32_t*>(
      rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), triangle_count()));
  if (!v || !t) {
    rtcReleaseGeometry(geometry);
    throw Error(field, std::to_string(triangle_count()) + " triangles", "a mesh that fits in memory (Embree could not allocate it)");
  }
  std::memcpy(v, positions_.data(), vertices * 3 * sizeof(float));
  std::memcpy(t, indices_.data(), indices_.size() * sizeof(std::uint32_t));
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(embree_->scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(embree_->scene);
  if (const RTCError e = rtcGetDeviceError(dev); e != RTC_ERROR_NONE)
    throw Error(field, std::to_string(triangle_count()) + " triangles", "a mesh Embree can build (error " + std::to_string(e) + ")");
}

std::shared_ptr<const TriangleMesh> TriangleMesh::from_buffers(const MeshBuffers& b, const glm::dmat4& transform, const std::string& field) {
  if (!finite(transform)) throw Error(field + ".transform", "a matrix with a non-finite or projective entry", "an affine transform of finite numbers");
  if (!b.positions && b.vertex_count > 0) throw Error(field + ".positions", "null", "a pointer to vertex_count positions");
  if (b.stride_bytes < 3 * sizeof(float)) throw Error(field + ".stride_bytes", std::to_string(b.stride_bytes), "at least 12 (3 floats)");
  if (b.indices.size() % 3 != 0)
    throw Error(field + ".indices", std::to_string(b.indices.size()) + " indices", "a multiple of 3 (one triple per triangle)");
  if (b.vertex_count > UINT32_MAX) throw Error(field + ".vertex_count", std::to_string(b.vertex_count), "at most 2^32 - 1 vertices");
  std::shared_ptr<TriangleMesh> mesh(new TriangleMesh());
  mesh->positions_.resize(b.vertex_count);
  const auto* bytes = reinterpret_cast<const unsigned char*>(b.positions);
  for (size_t i = 0; i < b.vertex_count; ++i) {
    float p[3];
    std::memcpy(p, bytes + i * b.stride_bytes, sizeof p);
    const Vec3 world = Vec3(transform * glm::dvec4(p[0], p[1], p[2], 1.0));
    if (!within_reach(world))
      throw Error(field + ".positions[" + std::to_string(i) + "]", to_text(p[0]) + ", " + to_text(p[1]) + ", " + to_text(p[2]),
                  "finite coordinates within 1e9 of the origin once placed (haze::kMaxCoordinate)");
    mesh->positions_[i] = Vec3f(world);
  }
  mesh->indices_.assign(b.indices.begin(), b.indices.end());
  mesh->build(field);
  return mesh;
}

std::shared_ptr<const TriangleMesh> TriangleMesh::load_obj(const std::filesystem::path& file, const glm::dmat4& transform,
                                                           const std::string& field) {
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  config.mtl_search_path = "";  // materials are not read
  tinyobj::ObjReader reader;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw Error(field, file.string(), "an existing OBJ file, but there is none at that path");
  if (!reader.ParseFromFile(file.string(), config)) {
    std::string why = reader.Error();
    while (!why.empty() && (why.back() == '\n' || why.back() == '\r')) why.pop_back();
    throw Error(field, file.string(), "an OBJ file tinyobjloader can read (" + (why.empty() ? std::string("it could not") : why) + ")");
  }
  const auto& positions = reader.GetAttrib().vertices;
  std::vector<std::uint32_t> indices;
  for (const tinyobj::shape_t& shape : reader.GetShapes())
    for (const tinyobj::index_t& index : shape.mesh.indices) {
      if (index.vertex_index < 0 || static_cast<size_t>(index.vertex_index) * 3 >= positions.size())
        throw Error(field, file.string(), "an OBJ file whose faces name existing vertices (a face names vertex " +
                                             std::to_string(index.vertex_index + 1) + ")");
      indices.push_back(static_cast<std::uint32_t>(index.vertex_index));
    }
  if (indices.empty()) throw Error(field, file.string(), "an OBJ file with at least one face (f lines)");
  static_assert(std::is_same_v<tinyobj::real_t, float>);
  return from_buffers({positions.data(), positions.size() / 3, 3 * sizeof(float), indices}, transform, field);
}

bool TriangleMesh::intersect(const Ray& ray, double t_min, double t_max, double& t, Vec3& normal, std::uint32_t* triangle) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  Ray local;
  double near = t_min, far = t_max;
  if (!near_start(ray, bounds_, local, near, far)) return false;
  RTCRayHit hit;
  hit.ray = embree_ray(local, near, far);
  if (!(hit.ray.tfar > hit.ray.tnear)) return false;
  hit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  hit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(embree_->scene, &context, &hit);
  if (hit.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  // The hit's t in double from the triangle's plane: float32's t is off by 1e-7 of the distance.
  const size_t tri = hit.hit.primID;
  const Vec3 a = vertex(tri, 0), c = glm::cross(vertex(tri, 1) - a, vertex(tri, 2) - a);
  const double area2 = glm::length(c);
  if (!(area2 > 0.0)) return false;  // degenerate in double: no face to hit
  const Vec3 n = c / area2;
  const double denom = glm::dot(n, ray.direction);
  const double th = std::abs(denom) > 1e-12 ? glm::dot(a - ray.origin, n) / denom : static_cast<double>(hit.ray.tfar) + (t_min - near);
  if (!(th > t_min && th < t_max)) return false;
  t = th;
  normal = denom < 0.0 ? n : -n;
  if (triangle) *triangle = hit.hit.primID;
  return true;
}

bool TriangleMesh::occluded(const Ray& ray, double t_min, double t_max) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  Ray local;
  if (!near_start(ray, bounds_, local, t_min, t_max)) return false;
  RTCRay r = embree_ray(local, t_min, t_max);
  if (!(r.tfar > r.tnear)) return false;
  rtcOccluded1(embree_->scene, &context, &r);
  return r.tfar == -std::numeric_limits<float>::infinity();
}

}  // namespace haze
