// Extreme inputs (issue 26): values past haze::kMax* (limits.h) get a haze::Error naming their
// field, whichever way the scene was made; values at the edge of what is allowed render finitely
// with every method that takes the scene.
#include <haze/core/error.h>
#include <haze/core/limits.h>
#include <haze/core/mesh.h>
#include <haze/core/method.h>
#include <haze/core/scene.h>
#include <haze/grids/methods.h>

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "scenes/fog_box.h"

namespace haze {
namespace {

// Fog in [-1, 1]^3 over a floor at y = -1, a point light inside and the sun; 8 x 8 pixels.
Scene fog_box() {
  Scene scene = testing::unit_fog({4.0, Rgb(1.0, 1.2, 1.4), Rgb(0.9), 0.5, PointLight{Vec3(0.3, 0.5, 0.2), Rgb(5.0)}});
  scene.lights.push_back(DirectionalLight{glm::normalize(Vec3(0.3, -1.0, -0.2)), Rgb(1.0)});
  scene.surfaces.push_back(Surface{Plane{Vec3(0.0, -1.0, 0.0), Vec3(0.0, 1.0, 0.0)}, Rgb(0.5), Rgb(0.0), 1.0});
  scene.background = Rgb(0.01);
  return scene;
}

// The methods that take fog_box-like scenes, with cheap settings each.
const char* const kMethods[] = {"quadrature", "propagation", "dom", "reference"};

RenderOptions cheap_for(const std::string& method) {
  RenderOptions options;
  if (method == "reference") options.settings = {{"spp", 8}};
  if (method == "propagation" || method == "dom") options.settings = {{"resolution", 16}};
  return options;
}

// The field of the haze::Error rendering `scene` with quadrature throws, or "no error".
std::string refused_field(const Scene& scene) {
  try {
    render(scene, "quadrature", cheap_for("quadrature"));
  } catch (const Error& e) {
    return e.field();
  }
  return "no error";
}

void expect_finite(const Scene& scene, const std::string& method, const char* what) {
  const Image image = render(scene, method, cheap_for(method)).radiance;
  int bad = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      const Rgb c = image.at(x, y);
      bad += !(std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b) && std::min({c.r, c.g, c.b}) >= 0.0);
    }
  EXPECT_EQ(bad, 0) << method << ", " << what;
}

TEST(Extremes, ValuesPastTheLimitsNameTheirField) {
  struct Case {
    const char* field;
    std::function<void(Scene&)> change;
  };
  const std::vector<Case> cases = {
      // A light 1e155 away crashed the analytic method (an index from NaN), 1e20 away gave NaN.
      {"lights[0].position", [](Scene& s) { s.lights[0] = PointLight{Vec3(1e155, 0.0, 0.0), Rgb(1.0)}; }},
      {"lights[0].position", [](Scene& s) { s.lights[0] = PointLight{Vec3(0.0, 2e9, 0.0), Rgb(1.0)}; }},
      // Intensity 1e20 crashed the DOM (NaN in GMRES), colours past the float maximum gave Inf.
      {"lights[0].intensity[0]", [](Scene& s) { s.lights[0] = PointLight{Vec3(0.0), Rgb(1e20, 1.0, 1.0)}; }},
      {"lights[1].irradiance", [](Scene& s) { s.lights[1] = DirectionalLight{Vec3(0.0, -1.0, 0.0), Rgb(1e155)}; }},
      {"background[0]", [](Scene& s) { s.background = Rgb(3.5e38, 0.0, 0.0); }},
      {"surfaces[0].kd", [](Scene& s) { s.surfaces[0].kd = Rgb(1e16); }},
      {"surfaces[0].shininess", [](Scene& s) { s.surfaces[0].shininess = 1e6; }},
      // The camera 1e36 away hung the DOM; look_at at -1.7e308 gave NaN in quadrature.
      {"camera.position", [](Scene& s) { s.camera.position = Vec3(0.0, 0.0, -1e36); }},
      {"camera.look_at", [](Scene& s) { s.camera.look_at = Vec3(-1.7e308, 0.0, 0.0); }},
      {"camera.look_at", [](Scene& s) { s.camera.look_at = s.camera.position; }},
      // The camera at a point light: analytic and quadrature NaN (the radiance there is infinite).
      {"lights[0].position", [](Scene& s) { s.lights[0] = PointLight{s.camera.position + Vec3(1e-100), Rgb(1.0)}; }},
      // sigma_t 1e39 crashed the DOM; a blob of weight 1e19 hung the reference.
      {"medium.sigma_t", [](Scene& s) { s.medium->sigma_t = Rgb(1e39); }},
      {"medium.density.value", [](Scene& s) { s.medium->density = ConstantDensity{2e9}; }},
      {"medium.density.blobs[1].weight",
       [](Scene& s) { s.medium->density = RbfDensity{{{Vec3(0.0), 1.0, 2.0}, {Vec3(0.5), 1e19, 3.0}}}; }},
      {"medium.density.blobs[0].center", [](Scene& s) { s.medium->density = RbfDensity{{{Vec3(1e10, 0.0, 0.0), 1.0, 2.0}}}; }},
      // Unbounded, a blob of sharpness 1e-300 reached 6e300 away: quadrature's image was NaN
      // (the campaign's case 53948).
      {"medium.density.blobs[0].sharpness",
       [](Scene& s) {
         s.medium->density = RbfDensity{{{Vec3(0.0), 1.0, 1e-300}}};
         s.medium->bounds = Aabb{Vec3(-kInfinity), Vec3(kInfinity)};
       }},
      {"medium.bounds", [](Scene& s) { s.medium->bounds.hi.y = 1e19; }},
      {"medium.emission.strength", [](Scene& s) { s.medium->emission.strength = 1e300; }},
  };
  for (const Case& c : cases) {
    Scene scene = fog_box();
    c.change(scene);
    EXPECT_EQ(refused_field(scene), c.field);
  }
  // A lobe narrower than 1e-4 rad (the analytic method's tables took a minute at g = 0.9999999).
  EXPECT_THROW(PhaseFunction::henyey_greenstein(0.9999999), Error);
  EXPECT_NO_THROW(PhaseFunction::henyey_greenstein(-kMaxAsymmetry));
  // At the limits themselves, accepted.
  Scene edge = fog_box();
  edge.lights[0] = PointLight{Vec3(0.0, kMaxCoordinate, 0.0), Rgb(kMaxRadiometric)};
  edge.medium->sigma_t = Rgb(kMaxExtinction);
  EXPECT_EQ(refused_field(edge), "no error");
}

TEST(Extremes, EdgesOfTheAllowedRenderFinitely) {
  // The camera 1e-300 from look_at (NaN in quadrature: its frame was normalized by its length).
  Scene close = fog_box();
  close.camera.position = Vec3(0.0);
  close.camera.look_at = Vec3(0.0, 0.0, -1e-300);
  // Extinction at the limit, and a light as bright as allowed (the DOM crashed in GMRES at 1e9
  // extinction and at intensity 1e20).
  Scene thick = fog_box();
  thick.medium->sigma_t = Rgb(kMaxExtinction);
  Scene bright = fog_box();
  bright.lights[0] = PointLight{Vec3(0.3, 0.5, 0.2), Rgb(kMaxRadiometric)};
  // The light 1e9 away.
  Scene far = fog_box();
  far.lights[0] = PointLight{Vec3(0.0, kMaxCoordinate, 0.0), Rgb(1e15)};
  for (const char* method : kMethods) {
    expect_finite(close, method, "camera 1e-300 from look_at");
    expect_finite(thick, method, "sigma_t 1e9");
    expect_finite(bright, method, "intensity 1e15");
    expect_finite(far, method, "light 1e9 away");
  }
  // The analytic method (homogeneous fog, point lights) with the light 1e9 away and with the camera
  // at the light (NaN from 0 / 0 in the airlight's geometry).
  far.lights.resize(1);
  expect_finite(far, "analytic", "light 1e9 away");
  Scene near_light = fog_box();
  near_light.camera.position = Vec3(0.0, 0.0, 0.5);
  near_light.lights = {PointLight{near_light.camera.position + Vec3(2e-9, 0.0, 0.0), Rgb(kMaxRadiometric)}};
  near_light.medium->sigma_t = Rgb(kMaxExtinction);
  for (const char* method : {"analytic", "quadrature"}) expect_finite(near_light, method, "camera 2e-9 from the light");
}

// Channels of sigma_t a million apart make nearly every tentative collision of the thin channels a
// null one (the reference ran for hours): it stops at 1e6 per path with an error naming sigma_t.
TEST(Extremes, ReferenceStopsARunawayTracking) {
  Scene scene = fog_box();
  scene.medium->density = RbfDensity{{{Vec3(0.0), 1.2, 2.2}, {Vec3(0.4, 0.2, 0.0), 0.8, 3.0}}};
  scene.medium->sigma_t = Rgb(1e6, 2.5, 2.9);
  try {
    render(scene, "reference", cheap_for("reference"));
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "medium.sigma_t");
  }
}

// Many copies of a surface the host shades ("shaded": false, kd = ks = 0): they only block light,
// so 31 copies render as one does (the DOM made irradiance texels for each: 31 room meshes 50 s).
TEST(Extremes, ManyUnshadedMeshesBlockAsOne) {
  Scene one = fog_box();
  Surface cube{Mesh{TriangleMesh::load_obj(std::string(HAZE_SOURCE_DIR) + "/tests/data/cube.obj")}, Rgb(0.0), Rgb(0.0), 1.0};
  one.surfaces = {cube};
  Scene many = one;
  many.surfaces.assign(31, cube);
  for (const char* method : {"dom", "propagation"}) {
    const Image a = render(one, method, cheap_for(method)).radiance, b = render(many, method, cheap_for(method)).radiance;
    for (int y = 0; y < a.height(); ++y)
      for (int x = 0; x < a.width(); ++x) EXPECT_EQ(a.at(x, y), b.at(x, y)) << method << " " << x << ", " << y;
  }
}

// A blob 1e9 outside a bounded medium (propagation and dom looped over 2^31 cells: the blob's first
// cell overflowed int) adds nothing; unbounded, blobs that far apart would make cells wider than
// any blob (the medium vanished, the image was the floor's alone): a clear error instead.
TEST(Extremes, FarBlobsAreCulledOrRefused) {
  Scene near = fog_box();
  near.medium->density = RbfDensity{{{Vec3(0.0), 1.0, 2.0}, {Vec3(0.4, 0.2, 0.0), 0.8, 3.0}}};
  Scene far = near;
  std::get<RbfDensity>(far.medium->density).blobs.push_back({Vec3(kMaxCoordinate, 0.0, 0.0), 1.0, 2.0});
  for (const char* method : {"propagation", "dom"}) {
    const Image a = render(near, method, cheap_for(method)).radiance, b = render(far, method, cheap_for(method)).radiance;
    for (int y = 0; y < a.height(); ++y)
      for (int x = 0; x < a.width(); ++x) EXPECT_EQ(a.at(x, y), b.at(x, y)) << method;
  }
  far.medium->bounds = Aabb{};
  try {
    render(far, "propagation", cheap_for("propagation"));
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "medium.bounds");
    EXPECT_NE(std::string(e.what()).find("wider than the widest blob"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace haze
