// Cameras, boxes, surfaces and BRDF normalization, lights, media, the random number generator.
#include <haze/core/camera.h>
#include <haze/core/directions.h>
#include <haze/core/error.h>
#include <haze/core/grid_walk.h>
#include <haze/analytic/integrate.h>
#include <haze/core/light.h>
#include <haze/core/medium.h>
#include <haze/core/phase.h>
#include <haze/core/surface.h>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/trigonometric.hpp>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <vector>

namespace haze {
namespace {

TEST(Camera, RowsRunTopToBottomAndCentreLooksAtTarget) {
  Camera cam;
  cam.position = Vec3(0, 0, 5);
  cam.look_at = Vec3(0, 0, 0);
  cam.width_px = 4, cam.height_px = 2;
  Ray centre = cam.generate_ray(2.0, 1.0);
  EXPECT_NEAR(glm::length(centre.direction - Vec3(0, 0, -1)), 0.0, 1e-12);
  EXPECT_GT(cam.pixel_ray(0, 0).direction.y, 0.0);   // top row looks up
  EXPECT_LT(cam.pixel_ray(0, 1).direction.y, 0.0);
  EXPECT_LT(cam.pixel_ray(0, 0).direction.x, 0.0);   // left column looks left
  // Top edge of a pinhole image is fov_y / 2 above the axis.
  Ray top = cam.generate_ray(2.0, 0.0);
  EXPECT_NEAR(std::acos(-top.direction.z), 0.5 * cam.fov_y_deg * kPi / 180.0, 1e-12);

  cam.type = Camera::Type::orthographic;
  cam.height = 2.0;
  Ray ortho_top = cam.generate_ray(2.0, 0.0);
  EXPECT_NEAR(ortho_top.origin.y, 1.0, 1e-12);
  EXPECT_NEAR(glm::length(ortho_top.direction - Vec3(0, 0, -1)), 0.0, 1e-12);
}

// A host's OpenGL matrices (glm::lookAt with glm::perspective or glm::ortho) give the rays of the
// pinhole and orthographic cameras they describe, on and off the pixel centres; per-pixel rays
// come back as given; bad matrices and rays are haze::Errors naming the field.
TEST(Camera, HostMatricesAndRaysGiveTheSameRays) {
  Camera pin;
  pin.position = Vec3(0.3, 1.2, 4.0), pin.look_at = Vec3(-0.2, 0.1, 0.0), pin.up = Vec3(0.1, 1.0, 0.0);
  pin.width_px = 16, pin.height_px = 9, pin.fov_y_deg = 50.0;
  const glm::dmat4 view = glm::lookAt(pin.position, pin.look_at, pin.up);
  const double aspect = 16.0 / 9.0;
  const Camera host = Camera::from_matrices(view, glm::perspective(glm::radians(50.0), aspect, 0.1, 100.0), 16, 9);
  Camera ortho = pin;
  ortho.type = Camera::Type::orthographic, ortho.height = 3.0;
  const Camera host_ortho = Camera::from_matrices(view, glm::ortho(-1.5 * aspect, 1.5 * aspect, -1.5, 1.5, 0.1, 100.0), 16, 9);
  for (const auto& [px, py] : {std::pair{0.5, 0.5}, {15.5, 8.5}, {7.25, 3.0}, {0.0, 9.0}}) {
    for (const auto& [own, matrices] : {std::pair{&pin, &host}, {&ortho, &host_ortho}}) {
      const Ray a = own->generate_ray(px, py), b = matrices->generate_ray(px, py);
      EXPECT_NEAR(glm::length(a.origin - b.origin), 0.0, 1e-9) << px << " " << py;
      EXPECT_NEAR(glm::length(a.direction - b.direction), 0.0, 1e-12) << px << " " << py;
    }
  }
  // A row frame: a row's rays leave the eye along normalize(a + b px), for pinholes and perspective
  // matrices only.
  for (const Camera* camera : {static_cast<const Camera*>(&pin), &host})
    for (double py : {0.5, 4.25, 9.0}) {
      Vec3 a, b;
      ASSERT_TRUE(camera->row_frame(py, a, b));
      for (double px : {0.0, 3.5, 16.0})
        EXPECT_NEAR(glm::length(glm::normalize(a + b * px) - camera->generate_ray(px, py).direction), 0.0, 1e-12) << px << " " << py;
    }
  Vec3 a, b;
  EXPECT_FALSE(ortho.row_frame(0.5, a, b));
  EXPECT_FALSE(host_ortho.row_frame(0.5, a, b));
  auto rays = std::make_shared<std::vector<Ray>>();
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 16; ++x) rays->push_back(pin.pixel_ray(x, y));
  const Camera given = Camera::from_rays(rays, 16, 9);
  EXPECT_FALSE(given.row_frame(0.5, a, b));
  EXPECT_EQ(given.pixel_ray(7, 4).direction, pin.pixel_ray(7, 4).direction);
  EXPECT_EQ(given.generate_ray(7.9, 4.1).origin, pin.pixel_ray(7, 4).origin);
  auto expect_error = [](auto make, const std::string& field) {
    try {
      make();
      ADD_FAILURE() << "no error for " << field;
    } catch (const Error& e) {
      EXPECT_EQ(e.field().rfind(field, 0), 0u) << e.what();
    }
  };
  expect_error([&] { Camera::from_matrices(view, glm::dmat4(0.0), 16, 9); }, "camera.projection");
  expect_error([&] { Camera::from_rays(rays, 16, 8); }, "camera.rays");
  (*rays)[5].direction *= 2.0;
  expect_error([&] { Camera::from_rays(rays, 16, 9); }, "camera.rays[5]");
}

TEST(Aabb, ClipsRays) {
  Aabb box{Vec3(-1), Vec3(1)};
  double t0 = 0.0, t1 = kInfinity;
  ASSERT_TRUE(box.clip({Vec3(0, 0, -5), Vec3(0, 0, 1)}, t0, t1));
  EXPECT_DOUBLE_EQ(t0, 4.0);
  EXPECT_DOUBLE_EQ(t1, 6.0);
  t0 = 0.0, t1 = kInfinity;
  EXPECT_FALSE(box.clip({Vec3(0, 3, -5), Vec3(0, 0, 1)}, t0, t1));
  EXPECT_FALSE(Aabb{}.bounded());
  EXPECT_TRUE(box.bounded());
}

// A field linear in x, y, z on a cell-centred 4 x 3 x 2 grid: trilinear weights reproduce it
// anywhere between the outermost centres; in the half cells beyond them the clamped stencil holds
// the last centre's value and the extrapolating one keeps the slope up to the faces.
TEST(TrilinearStencil, ExtrapolatesALinearFieldToTheFaces) {
  const Aabb box{Vec3(0.0), Vec3(4.0, 3.0, 2.0)};
  const std::array<int, 3> n{4, 3, 2};
  auto field = [](const Vec3& p) { return 2.0 * p.x - 3.0 * p.y + 0.5 * p.z + 1.0; };
  std::vector<double> values;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 4; ++i) values.push_back(field(Vec3(i + 0.5, j + 0.5, k + 0.5)));
  for (const Vec3& p : {Vec3(1.7, 1.2, 0.9), Vec3(0.1, 2.9, 1.8), Vec3(4.0, 0.0, 0.0), Vec3(3.8, 1.5, 1.95)}) {
    EXPECT_NEAR(TrilinearStencil(box, n, p, true).apply(values.data()), field(p), 1e-12) << p.x << " " << p.y << " " << p.z;
    const Vec3 inside = glm::clamp(p, Vec3(0.5), Vec3(3.5, 2.5, 1.5));  // what clamping sees
    EXPECT_NEAR(TrilinearStencil(box, n, p).apply(values.data()), field(inside), 1e-12);
  }
}

TEST(Surface, IntersectsPlanesAndSpheres) {
  Surface plane{Plane{Vec3(0, -1, 0), Vec3(0, 1, 0)}};
  Surface sphere{Sphere{Vec3(0, 0, 0), 0.5}};
  double t;
  Vec3 n;
  ASSERT_TRUE(plane.intersect({Vec3(0, 1, 0), Vec3(0, -1, 0)}, 0.0, kInfinity, t, n));
  EXPECT_DOUBLE_EQ(t, 2.0);
  EXPECT_DOUBLE_EQ(n.y, 1.0);
  ASSERT_TRUE(sphere.intersect({Vec3(0, 0, -3), Vec3(0, 0, 1)}, 0.0, kInfinity, t, n));
  EXPECT_DOUBLE_EQ(t, 2.5);
  EXPECT_DOUBLE_EQ(n.z, -1.0);
  // From inside, the far side faces the origin.
  ASSERT_TRUE(sphere.intersect({Vec3(0), Vec3(1, 0, 0)}, 0.0, kInfinity, t, n));
  EXPECT_DOUBLE_EQ(t, 0.5);
  EXPECT_DOUBLE_EQ(n.x, -1.0);
}

// Energy-normalized BRDFs: at normal incidence, Lambert reflects kd and Phong reflects ks.
TEST(Surface, BrdfsAreEnergyNormalized) {
  Vec3 n(0, 0, 1);
  for (double shininess : {1.0, 10.0, 100.0}) {
    Surface lambert{Plane{}, Rgb(0.6), Rgb(0.0), 1.0};
    Surface phong{Plane{}, Rgb(0.0), Rgb(0.3), shininess};
    std::vector<double> x, w;
    gauss_legendre(2000, x, w);
    Rgb reflected_l(0.0), reflected_p(0.0);
    const int phis = 64;
    for (size_t i = 0; i < x.size(); ++i) {
      double cos_o = 0.5 * (x[i] + 1.0);  // [0, 1]
      for (int k = 0; k < phis; ++k) {
        Vec3 wo = direction_around(n, cos_o, 2.0 * kPi * (k + 0.5) / phis);
        double dw = 0.5 * w[i] * 2.0 * kPi / phis;
        reflected_l += lambert.brdf(n, wo, n) * cos_o * dw;
        reflected_p += phong.brdf(n, wo, n) * cos_o * dw;
      }
    }
    EXPECT_NEAR(reflected_l.r, 0.6, 1e-6);
    EXPECT_NEAR(reflected_p.g, 0.3, 1e-4) << shininess;
  }
}

// A light at (0, 3, 0) over a sphere of radius 0.3 at (0, 1.8, 0): the tangent cone's half-angle
// has sin = 0.3 / 1.2, so the line y = 0 along x is in shadow for |x| < 3 tan(asin(0.25)); a plane
// at y = 1 hides the light from everything below it.
TEST(Surface, LitStretchesEndAtTheShadowsEdges) {
  const Vec3 light(0.0, 3.0, 0.0);
  const std::vector<Surface> sphere{Surface{Sphere{Vec3(0.0, 1.8, 0.0), 0.3}}};
  std::vector<std::pair<double, double>> lit;
  lit_stretches(sphere, Ray{Vec3(-5.0, 0.0, 0.0), Vec3(1.0, 0.0, 0.0)}, 0.0, 10.0, light, lit);
  const double edge = 3.0 * std::tan(std::asin(0.25));
  ASSERT_EQ(lit.size(), 2u);
  EXPECT_NEAR(lit[0].first, 0.0, 1e-12);
  EXPECT_NEAR(lit[0].second, 5.0 - edge, 1e-9);
  EXPECT_NEAR(lit[1].first, 5.0 + edge, 1e-9);
  EXPECT_NEAR(lit[1].second, 10.0, 1e-12);
  // A ray that misses the shadow is lit all along, to infinity.
  lit.clear();
  lit_stretches(sphere, Ray{Vec3(-5.0, 0.0, 2.0), Vec3(1.0, 0.0, 0.0)}, 0.0, kInfinity, light, lit);
  ASSERT_EQ(lit.size(), 1u);
  EXPECT_EQ(lit[0].second, kInfinity);
  // Down through the plane: lit to the plane, dark past it.
  lit.clear();
  const std::vector<Surface> plane{Surface{Plane{Vec3(0.0, 1.0, 0.0), Vec3(0.0, 1.0, 0.0)}}};
  lit_stretches(plane, Ray{Vec3(0.5, 2.0, 0.0), Vec3(0.0, -1.0, 0.0)}, 0.0, 4.0, light, lit);
  ASSERT_EQ(lit.size(), 1u);
  EXPECT_NEAR(lit[0].second, 1.0, 1e-12);
}

// One direction's cone of a set of 64 covers 4 pi / 64 steradians: 2 pi (1 - cos(atan t)).
// LightShadows' lit / dark / partial against lit_stretches over random view stretches past a
// sphere and a plane, with lights outside and inside the sphere: a stretch called lit is lit all
// along, one called dark nowhere (to 1e-6 of its length, the edges' margin); most need no cutting.
TEST(Surface, LightShadowsAgreeWithLitStretches) {
  const std::vector<Surface> surfaces{Surface{Plane{Vec3(0.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0)}}, Surface{Sphere{Vec3(0.4, 0.6, 0.8), 0.6}}};
  Rng rng(23, 2);
  for (const Vec3& light : {Vec3(-1.2, 1.8, 0.0), Vec3(0.3, 2.2, 1.4), Vec3(0.5, 0.7, 0.9)}) {
    const LightShadows shadows(surfaces, light);
    int partial = 0, dark = 0;
    const int n = 4000;
    for (int i = 0; i < n; ++i) {
      const Ray ray{Vec3(8.0 * rng.uniform() - 4.0, 0.1 + 3.0 * rng.uniform(), 8.0 * rng.uniform() - 4.0),
                    direction_around(Vec3(0, 1, 0), 2.0 * rng.uniform() - 1.0, 2.0 * kPi * rng.uniform())};
      double t_hit;
      Vec3 normal;
      nearest_surface(surfaces, ray, 12.0, t_hit, normal);
      const double t0 = 0.5 * rng.uniform() * t_hit, t1 = t_hit;
      std::vector<std::pair<double, double>> lit;
      lit_stretches(surfaces, ray, t0, t1, light, lit);
      double length = 0.0;
      for (const auto& [a, b] : lit) length += b - a;
      switch (shadows.classify(ray, t0, t1)) {
        case LightShadows::Stretch::lit: ASSERT_NEAR(length, t1 - t0, 1e-6 * (t1 - t0)) << "ray " << i; break;
        case LightShadows::Stretch::dark:
          ASSERT_NEAR(length, 0.0, 1e-6 * (t1 - t0)) << "ray " << i;
          ++dark;
          break;
        case LightShadows::Stretch::partial: ++partial; break;
      }
    }
    EXPECT_LT(partial, n / 3) << "light at " << light.x;
    EXPECT_GT(dark, 0) << "light at " << light.x;
  }
}

TEST(Directions, ConeTangentCoversOneDirectionsShare) {
  for (int count : {3, 8, 64, 4096}) {
    const double alpha = std::atan(cone_tangent(count));
    EXPECT_NEAR(2.0 * kPi * (1.0 - std::cos(alpha)), 4.0 * kPi / count, 1e-12) << count;
  }
}

TEST(Light, ArrivalFollowsInverseSquareAndSpotCone) {
  LightArrival a;
  ASSERT_TRUE(arrival(PointLight{Vec3(0, 0, 2), Rgb(8.0)}, Vec3(0), a));
  EXPECT_DOUBLE_EQ(a.distance, 2.0);
  EXPECT_DOUBLE_EQ(a.irradiance.r, 2.0);
  EXPECT_DOUBLE_EQ(a.to_light.z, 1.0);
  SpotLight spot{Vec3(0, 0, 2), Vec3(0, 0, -1), Rgb(4.0), 2.0, 30.0};
  ASSERT_TRUE(arrival(spot, Vec3(0), a));
  EXPECT_DOUBLE_EQ(a.irradiance.g, 1.0);
  ASSERT_TRUE(arrival(spot, Vec3(std::tan(0.4), 0, 1), a));  // 0.4 rad = 22.9 deg, inside
  EXPECT_NEAR(a.irradiance.g, 4.0 * std::pow(std::cos(0.4), 2) / (1.0 + std::pow(std::tan(0.4), 2)), 1e-12);
  ASSERT_TRUE(arrival(spot, Vec3(1, 0, 1), a));  // 45 deg, outside
  EXPECT_EQ(a.irradiance, Rgb(0.0));
  ASSERT_TRUE(arrival(DirectionalLight{Vec3(0, -1, 0), Rgb(3.0)}, Vec3(5), a));
  EXPECT_EQ(a.to_light, Vec3(0, 1, 0));
  EXPECT_TRUE(std::isinf(a.distance));
  EXPECT_FALSE(arrival(SkyLight{}, Vec3(0), a));
}

TEST(Light, EquiangularNodesIntegrateTheInverseSquarePeak) {
  // A ray passing 0.01 from a point: integral of 1 / d^2 over t in [-0.3, 0.5] is
  // (atan(50) + atan(30)) / 0.01 in closed form, exact for any node count.
  const Ray ray{Vec3(0.0, 0.01, -2.0), Vec3(0.0, 0.0, 1.0)};
  const Vec3 centre(0.0);
  std::array<double, 16> t{}, w{};
  const double exact = (std::atan(50.0) + std::atan(30.0)) / 0.01;
  for (double angle : {10.0, 0.5, 0.05}) {
    const int count = equiangular_nodes(ray, centre, 1.7, 2.5, angle, t, w);
    ASSERT_GE(count, 1);
    double sum = 0.0;
    for (int n = 0; n < count; ++n) {
      EXPECT_GE(t[n], 1.7);
      EXPECT_LE(t[n], 2.5);
      const Vec3 d = ray.at(t[n]) - centre;
      sum += w[n] / glm::dot(d, d);
    }
    EXPECT_NEAR(sum, exact, 1e-9 * exact) << angle;
  }
  EXPECT_EQ(equiangular_nodes(ray, centre, 1.7, 2.5, 0.05, t, w), 16);  // at most the room given
  // A smooth factor times the peak, e^(-t) / d^2, against adaptive quadrature: 16 nodes to 1e-3;
  // the midpoint rule (one node at t = 2.1, weight 0.8) is over half off.
  const int count = equiangular_nodes(ray, centre, 1.7, 2.5, 0.2, t, w);
  double sum = 0.0;
  for (int n = 0; n < count; ++n) sum += w[n] * std::exp(-t[n]) / glm::dot(ray.at(t[n]), ray.at(t[n]));
  const double adaptive = analytic::integrate_adaptive([&](double s) { return std::exp(-s) / glm::dot(ray.at(s), ray.at(s)); }, 1.7, 2.5, 1e-12).value;
  EXPECT_NEAR(sum, adaptive, 1e-3 * adaptive);
  EXPECT_GT(std::abs(0.8 * std::exp(-2.1) / glm::dot(ray.at(2.1), ray.at(2.1)) - adaptive), 0.5 * adaptive);
  // A ray through the point and an empty stretch stay finite.
  const Ray through{Vec3(0.0, 0.0, -2.0), Vec3(0.0, 0.0, 1.0)};
  ASSERT_EQ(equiangular_nodes(through, centre, 1.0, 3.0, 0.05, t, w), 16);
  for (int n = 0; n < 16; ++n) EXPECT_TRUE(std::isfinite(w[n]) && std::isfinite(t[n]));
  EXPECT_EQ(equiangular_nodes(ray, centre, 2.0, 2.0, 0.05, t, w), 0);
}

TEST(Medium, DensityIntegralsAreExactOrConverged) {
  MediumDesc constant;
  constant.bounds = {Vec3(-1), Vec3(1)};
  constant.density = ConstantDensity{2.0};
  auto m = make_medium(constant);
  EXPECT_DOUBLE_EQ(m->density_integral(Vec3(0, 0, -5), Vec3(0, 0, 5)), 4.0);
  EXPECT_NEAR(m->transmittance(Vec3(0, 0, -5), Vec3(0, 0, 5)).r, std::exp(-4.0), 1e-15);

  // A Gaussian's line integral through its centre: w sqrt(pi) / a.
  MediumDesc rbf;
  rbf.density = RbfDensity{{RbfBlob{Vec3(0.2, 0.1, 0), 1.5, 2.0}}};
  auto r = make_medium(rbf);
  EXPECT_NEAR(r->density_integral(Vec3(0.2, 0.1, -9), Vec3(0.2, 0.1, 9)), 1.5 * std::sqrt(kPi) / 2.0, 1e-9);
  EXPECT_NEAR(r->density(Vec3(0.2, 0.1, 0.5)), 1.5 * std::exp(-1.0), 1e-15);
  // Off the centre, part of the way, and far out on a tail (where erf(u1) - erf(u0) cancels): the
  // closed form against Simpson's rule (Medium's own, at 1/4 of the sharpest blob's width).
  MediumDesc sharp;
  sharp.density = RbfDensity{{RbfBlob{Vec3(0.0), 2.0, 3.0}, RbfBlob{Vec3(0.3, 0.0, 0.1), 1.0, 40.0}}};
  auto q = make_medium(sharp);
  for (const auto& [a, b] : {std::pair{Vec3(0.05, 0.02, -2.0), Vec3(0.05, 0.02, 0.08)}, std::pair{Vec3(-1.0, 0.1, 0.1), Vec3(0.7, 0.2, 0.0)},
                             std::pair{Vec3(0.0, 0.0, 1.2), Vec3(0.0, 0.0, 2.0)}}) {
    const double exact = q->density_integral(a, b), simpson = q->Medium::density_integral(a, b);
    EXPECT_GT(exact, 0.0);
    EXPECT_NEAR(exact, simpson, 1e-5 * simpson);  // Simpson's own error: 2e-6 on the tail
  }

  // Trilinear grid: a linear ramp in x is reproduced between cell centres.
  MediumDesc grid;
  grid.bounds = {Vec3(0), Vec3(4, 1, 1)};
  grid.density = GridDensity{{4, 1, 1}, {0.0f, 1.0f, 2.0f, 3.0f}};
  auto g = make_medium(grid);
  EXPECT_NEAR(g->density(Vec3(1.5, 0.5, 0.5)), 1.0, 1e-12);
  EXPECT_NEAR(g->density(Vec3(2.0, 0.5, 0.5)), 1.5, 1e-12);
  EXPECT_NEAR(g->density_integral(Vec3(0.5, 0.5, 0.5), Vec3(3.5, 0.5, 0.5)), 4.5, 1e-9);
  MediumDesc unbounded_grid = grid;
  unbounded_grid.bounds = Aabb{};
  EXPECT_THROW(make_medium(unbounded_grid), Error);
}

TEST(Rng, UniformIsUniformAndDeterministic) {
  Rng a(3, 9), b(3, 9), c(3, 10);
  double mean = 0.0, m2 = 0.0;
  const int n = 100000;
  bool differs = false;
  for (int i = 0; i < n; ++i) {
    double u = a.uniform();
    ASSERT_EQ(u, b.uniform());
    differs |= (u != c.uniform());
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    mean += u / n, m2 += u * u / n;
  }
  EXPECT_TRUE(differs);
  EXPECT_NEAR(mean, 0.5, 0.005);
  EXPECT_NEAR(m2 - mean * mean, 1.0 / 12.0, 0.002);
}

}  // namespace
}  // namespace haze
