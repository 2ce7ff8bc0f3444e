// Triangle meshes (core/mesh.h): OBJ files and caller buffers, placement, Embree ray queries
// against closed forms, shadows, and the errors for bad input.
#include <haze/core/error.h>
#include <haze/core/scene.h>
#include <haze/core/surface.h>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

namespace haze {
namespace {

const std::string kCube = std::string(HAZE_SOURCE_DIR) + "/tests/data/cube.obj";

// The field of the haze::Error `f` throws, or "no error".
template <class F>
std::string field_of(F f) {
  try {
    f();
  } catch (const Error& e) {
    return e.field();
  }
  return "no error";
}

TEST(Mesh, ObjCubeHitsWhereTheBoxIs) {
  const auto cube = TriangleMesh::load_obj(kCube);
  EXPECT_EQ(cube->triangle_count(), 12u);
  EXPECT_EQ(cube->bounds(), (Aabb{Vec3(-0.5), Vec3(0.5)}));
  // Rays from every axis direction, off-centre: t to the face, the normal facing the origin.
  for (int axis = 0; axis < 3; ++axis)
    for (double sign : {-1.0, 1.0}) {
      Vec3 origin(0.1, -0.2, 0.3);
      origin[axis] = 3.0 * sign;
      Vec3 dir(0.0);
      dir[axis] = -sign;
      double t;
      Vec3 n;
      ASSERT_TRUE(cube->intersect({origin, dir}, 0.0, kInfinity, t, n));
      EXPECT_NEAR(t, 2.5, 1e-12);
      EXPECT_NEAR(glm::dot(n, -dir), 1.0, 1e-12);
      // From inside: the far face, its normal facing back in.
      const Vec3 inside(0.05, 0.1, -0.1);
      ASSERT_TRUE(cube->intersect({inside, dir}, 0.0, kInfinity, t, n));
      EXPECT_NEAR(t, 0.5 + sign * inside[axis], 1e-12);
      EXPECT_NEAR(glm::dot(n, -dir), 1.0, 1e-12);
      EXPECT_FALSE(cube->intersect({origin, -dir}, 0.0, kInfinity, t, n));
      EXPECT_FALSE(cube->intersect({origin, dir}, 0.0, 2.4, t, n));
      EXPECT_TRUE(cube->occluded({origin, dir}, 0.0, 2.6));
      EXPECT_FALSE(cube->occluded({origin, dir}, 0.0, 2.4));
    }
}

// Embree refuses rays from past 1.8e18 (an assertion in Debian's build aborted the process); such
// rays start at the mesh's bounds and still report t from their own origin.
TEST(Mesh, RaysFromFarAwayStillHit) {
  const auto cube = TriangleMesh::load_obj(kCube);
  for (double far : {1e16, 1e19, 1e300}) {
    const Ray ray{Vec3(0.1, -0.2, far), Vec3(0.0, 0.0, -1.0)};
    double t;
    Vec3 n;
    ASSERT_TRUE(cube->intersect(ray, 0.0, kInfinity, t, n)) << far;
    EXPECT_NEAR(t, far - 0.5, 1e-12 * far);
    EXPECT_NEAR(n.z, 1.0, 1e-12);
    EXPECT_TRUE(cube->occluded(ray, 0.0, kInfinity));
    EXPECT_FALSE(cube->occluded(ray, 0.0, 0.5 * far));
    EXPECT_FALSE(cube->intersect({Vec3(3.0, -0.2, far), ray.direction}, 0.0, kInfinity, t, n));
  }
  // Vertices are kept within haze::kMaxCoordinate.
  EXPECT_EQ(field_of([] { TriangleMesh::load_obj(kCube, placement(Vec3(0.0), Vec3(0.0), Vec3(1e10))); }), "file.positions[0]");
}

TEST(Mesh, PlacementScalesRotatesAndMoves) {
  // Scale 2 along x, a quarter turn about y (x -> -z), then up by 1: the cube spans x, y, z in
  // [-0.5, 0.5] x [0.5, 1.5] x [-1, 1].
  const auto cube = TriangleMesh::load_obj(kCube, placement(Vec3(0.0, 1.0, 0.0), Vec3(0.0, 90.0, 0.0), Vec3(2.0, 1.0, 1.0)));
  EXPECT_NEAR(cube->bounds().lo.z, -1.0, 1e-6);
  EXPECT_NEAR(cube->bounds().hi.z, 1.0, 1e-6);
  EXPECT_NEAR(cube->bounds().lo.x, -0.5, 1e-6);
  EXPECT_NEAR(cube->bounds().lo.y, 0.5, 1e-6);
  double t;
  Vec3 n;
  ASSERT_TRUE(cube->intersect({Vec3(0.0, 1.0, 5.0), Vec3(0.0, 0.0, -1.0)}, 0.0, kInfinity, t, n));
  EXPECT_NEAR(t, 4.0, 1e-6);
}

TEST(Mesh, CallerBuffersWithAStrideAreTheSameMesh) {
  // An interleaved buffer (position, normal) of a square in the plane y = 0, two triangles.
  const float interleaved[] = {-1, 0, -1, 0, 1, 0, 1, 0, -1, 0, 1, 0, 1, 0, 1, 0, 1, 0, -1, 0, 1, 0, 1, 0};
  const std::uint32_t indices[] = {0, 1, 2, 0, 2, 3};
  const auto quad = TriangleMesh::from_buffers({interleaved, 4, 6 * sizeof(float), indices});
  EXPECT_EQ(quad->triangle_count(), 2u);
  EXPECT_EQ(quad->positions()[2], Vec3f(1, 0, 1));
  double t;
  Vec3 n;
  ASSERT_TRUE(quad->intersect({Vec3(0.3, 2.0, -0.7), glm::normalize(Vec3(0.1, -1.0, 0.0))}, 0.0, kInfinity, t, n));
  EXPECT_NEAR(t, 2.0 * std::sqrt(1.01), 1e-12);
  EXPECT_EQ(n, Vec3(0.0, 1.0, 0.0));
  // The bad views.
  const std::uint32_t past[] = {0, 1, 4};
  EXPECT_EQ(field_of([&] { TriangleMesh::from_buffers({interleaved, 4, 6 * sizeof(float), past}); }), "mesh.indices[2]");
  EXPECT_EQ(field_of([&] { TriangleMesh::from_buffers({interleaved, 4, 6 * sizeof(float), std::span(indices, 5)}); }), "mesh.indices");
  EXPECT_EQ(field_of([&] { TriangleMesh::from_buffers({nullptr, 4, 12, indices}); }), "mesh.positions");
  EXPECT_EQ(field_of([&] { TriangleMesh::from_buffers({interleaved, 4, 8, indices}); }), "mesh.stride_bytes");
  glm::dmat4 projective(1.0);
  projective[2][3] = -1.0;
  EXPECT_EQ(field_of([&] { TriangleMesh::from_buffers({interleaved, 4, 24, indices}, projective); }), "mesh.transform");
}

// A mesh's shadow edges along a ray (lit_stretches' bisection) where a plane's are exact: a
// large square in the plane y = 0 in place of the plane itself, the light above.
TEST(Mesh, ShadowStretchesMatchTheExactPlanes) {
  const float square[] = {-50, 0, -50, 50, 0, -50, 50, 0, 50, -50, 0, 50};
  const std::uint32_t indices[] = {0, 2, 1, 0, 3, 2};
  const std::vector<Surface> mesh{{Mesh{TriangleMesh::from_buffers({square, 4, 12, indices})}}};
  const std::vector<Surface> plane{{Plane{Vec3(0.0), Vec3(0.0, 1.0, 0.0)}}};
  const Vec3 light(0.3, 2.0, 0.1);
  for (const Ray& ray : {Ray{Vec3(0.0, 1.0, 4.0), glm::normalize(Vec3(0.1, -0.5, -1.0))}, Ray{Vec3(0.0, -1.0, 4.0), glm::normalize(Vec3(0.0, 0.6, -1.0))}}) {
    std::vector<std::pair<double, double>> a, b;
    lit_stretches(plane, ray, 0.0, 8.0, light, a);
    lit_stretches(mesh, ray, 0.0, 8.0, light, b);
    ASSERT_EQ(a.size(), b.size());
    // Within the mesh's self-hit skip (1e-5 (1 + |x|), here about 5e-5) of the square a point is
    // not shadowed by it: the edges move by that much where the view ray crosses it.
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_NEAR(a[i].first, b[i].first, 1e-4);
      EXPECT_NEAR(a[i].second, b[i].second, 1e-4);
    }
    EXPECT_FALSE(a.empty());
  }
}

TEST(Mesh, SceneFilesReadMeshesAndNameTheirMistakes) {
  const std::string dir = std::string(HAZE_SOURCE_DIR) + "/tests/data";
  auto scene = [&](nlohmann::json surface) {
    return nlohmann::json{{"camera", {{"position", {0, 0, 5}}, {"look_at", {0, 0, 0}}}}, {"surfaces", {surface}}};
  };
  const Scene s = Scene::from_json(
      scene({{"type", "mesh"}, {"file", "cube.obj"}, {"transform", {{"translate", {0, 1, 0}}, {"scale", 2}}}, {"kd", 0.3}}), dir);
  const auto& mesh = std::get<Mesh>(s.surfaces[0].shape);
  EXPECT_NEAR(mesh.triangles->bounds().hi.y, 2.0, 1e-6);
  EXPECT_EQ(s.surfaces[0].kd, Rgb(0.3));
  const Scene row_major = Scene::from_json(
      scene({{"type", "mesh"}, {"file", "cube.obj"}, {"transform", {{"matrix", {1, 0, 0, 3, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}}}}), dir);
  EXPECT_NEAR(std::get<Mesh>(row_major.surfaces[0].shape).triangles->bounds().lo.x, 2.5, 1e-6);
  const Scene host = Scene::from_json(scene({{"type", "mesh"}, {"file", "cube.obj"}, {"shaded", false}}), dir);
  EXPECT_EQ(host.surfaces[0].kd, Rgb(0.0));
  EXPECT_EQ(host.surfaces[0].ks, Rgb(0.0));

  auto field = [&](nlohmann::json surface) { return field_of([&] { Scene::from_json(scene(surface), dir); }); };
  EXPECT_EQ(field({{"type", "mesh"}, {"file", "missing.obj"}}), "surfaces[0].file");
  EXPECT_EQ(field({{"type", "mesh"}}), "surfaces[0].file");
  EXPECT_EQ(field({{"type", "mesh"}, {"file", "cube.obj"}, {"transform", {{"scale", -1}}}}), "surfaces[0].transform.scale");
  EXPECT_EQ(field({{"type", "mesh"}, {"file", "cube.obj"}, {"transform", {{"matrix", {1, 0, 0}}}}}), "surfaces[0].transform.matrix");
  EXPECT_EQ(field({{"type", "mesh"}, {"file", "cube.obj"}, {"transform", {{"spin", 1}}}}), "surfaces[0].transform.spin");
  EXPECT_EQ(field({{"type", "mesh"}, {"file", "cube.obj"}, {"shaded", false}, {"kd", 0.5}}), "surfaces[0].kd");
  EXPECT_EQ(field({{"type", "mesh"}, {"file", "cube.obj"}, {"shaded", "no"}}), "surfaces[0].shaded");
  EXPECT_EQ(field({{"type", "mesh"}, {"file", "cube.obj"}, {"radius", 1}}), "surfaces[0].radius");

  // An OBJ whose face names a vertex it does not have, and one without faces.
  const std::string bad = testing::TempDir() + "/haze_bad.obj", empty = testing::TempDir() + "/haze_empty.obj";
  std::ofstream(bad) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n";
  std::ofstream(empty) << "v 0 0 0\n";
  for (const std::string& file : {bad, empty}) {
    try {
      TriangleMesh::load_obj(file);
      ADD_FAILURE() << file;
    } catch (const Error& e) {
      EXPECT_EQ(e.field(), "file");
      EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace haze
