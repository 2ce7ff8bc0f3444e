// Scene parsing: a full scene read field by field, the documented defaults, and a table of bad
// scenes, each of which must throw haze::Error naming the right JSON path.
#include <haze/core/error.h>
#include <haze/core/scene.h>

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace haze {
namespace {

using json = nlohmann::json;
namespace fs = std::filesystem;

// One folder per test process: ctest runs each discovered test as its own process, maybe in parallel.
fs::path test_dir() {
  static const fs::path dir = [] {
    return fs::temp_directory_path() / ("haze_scene_test_" + std::to_string(::getpid()));
  }();
  return dir;
}

void write_floats(const fs::path& path, const std::vector<float>& values) {
  std::ofstream out(path, std::ios::binary);
  // The test machines are little-endian, the grid file format's byte order.
  out.write(reinterpret_cast<const char*>(values.data()), static_cast<std::streamsize>(values.size() * sizeof(float)));
}

void write_text(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

void expect_vec(const Vec3& got, const Vec3& want, double tol = 1e-12) {
  EXPECT_NEAR(got.x, want.x, tol);
  EXPECT_NEAR(got.y, want.y, tol);
  EXPECT_NEAR(got.z, want.z, tol);
}

class SceneFiles : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // Each suite's TearDownTestSuite removes the folder; the next suite writes it again.
    fs::create_directories(test_dir());
    // 2 x 2 x 2 cells: the size the bad-grid cases declare.
    write_floats(test_dir() / "cube.raw", {0, 1, 2, 3, 4, 5, 6, 7});
    write_floats(test_dir() / "short.raw", {0, 1, 2, 3, 4, 5, 6});
    write_floats(test_dir() / "negative.raw", {0, 1, 2, 3, 4, -1, 6, 7});
    write_floats(test_dir() / "nan.raw", {0, 1, 2, std::numeric_limits<float>::quiet_NaN(), 4, 5, 6, 7});
    std::vector<float> density(2 * 3 * 4);
    for (std::size_t i = 0; i < density.size(); ++i) density[i] = 0.5f * static_cast<float>(i);
    write_floats(test_dir() / "density.raw", density);
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(test_dir(), ec);
  }
};

const char* const kGoodScene = R"({
  "camera": {"type": "orthographic", "position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 2, 0],
             "height": 3, "width_px": 32, "height_px": 16},
  "medium": {"bounds": [[-1, -2, -3], [1, 2, 3]],
             "density": {"type": "grid", "resolution": [2, 3, 4], "file": "density.raw"},
             "sigma_t": [1, 2, 3], "albedo": 0.5,
             "phase": {"type": "double_hg", "g1": 0.7, "g2": -0.3, "w": 0.8}},
  "lights": [{"type": "point", "position": [1, 2, 3], "intensity": [1, 2, 3]},
             {"type": "spot", "position": [0, 4, 0], "direction": [0, -2, 0], "intensity": 5},
             {"type": "directional", "direction": [1, 1, 0], "irradiance": [0.5, 0.25, 0]},
             {"type": "sky", "radiance": 0.25}],
  "surfaces": [{"type": "plane", "point": [0, -1, 0], "normal": [0, 0, 3], "kd": [0.1, 0.2, 0.3]},
               {"type": "sphere", "center": [1, 0, 0], "radius": 0.5, "ks": 0.25, "shininess": 20}],
  "background": 0.1,
  "method": {"name": "dom", "directions": 64}
})";

TEST_F(SceneFiles, GoodSceneFieldByField) {
  Scene s = Scene::from_json(json::parse(kGoodScene), test_dir());

  EXPECT_EQ(s.camera.type, Camera::Type::orthographic);
  expect_vec(s.camera.position, {0, 0, 5});
  expect_vec(s.camera.look_at, {0, 0, 0});
  expect_vec(s.camera.up, {0, 1, 0});  // normalized
  EXPECT_DOUBLE_EQ(s.camera.height, 3.0);
  EXPECT_EQ(s.camera.width_px, 32);
  EXPECT_EQ(s.camera.height_px, 16);

  ASSERT_TRUE(s.medium.has_value());
  const MediumDesc& m = *s.medium;
  expect_vec(m.bounds.lo, {-1, -2, -3});
  expect_vec(m.bounds.hi, {1, 2, 3});
  const auto* grid = std::get_if<GridDensity>(&m.density);
  ASSERT_NE(grid, nullptr);
  EXPECT_EQ(grid->resolution, (std::array<int, 3>{2, 3, 4}));
  ASSERT_EQ(grid->values.size(), 24u);
  for (std::size_t i = 0; i < 24; ++i) EXPECT_EQ(grid->values[i], 0.5f * static_cast<float>(i));
  expect_vec(m.sigma_t, {1, 2, 3});
  expect_vec(m.albedo, {0.5, 0.5, 0.5});  // one number fills every channel
  EXPECT_EQ(m.phase.type(), PhaseType::double_hg);
  EXPECT_NEAR(m.phase.mean_cosine(), 0.8 * 0.7 + 0.2 * -0.3, 1e-12);

  ASSERT_EQ(s.lights.size(), 4u);
  const auto& point = std::get<PointLight>(s.lights[0]);
  expect_vec(point.position, {1, 2, 3});
  expect_vec(point.intensity, {1, 2, 3});
  const auto& spot = std::get<SpotLight>(s.lights[1]);
  expect_vec(spot.position, {0, 4, 0});
  expect_vec(spot.direction, {0, -1, 0});
  expect_vec(spot.intensity, {5, 5, 5});
  EXPECT_DOUBLE_EQ(spot.exponent, 1.0);  // default
  EXPECT_DOUBLE_EQ(spot.cone_deg, 45.0);  // default
  const auto& sun = std::get<DirectionalLight>(s.lights[2]);
  expect_vec(sun.direction, {std::sqrt(0.5), std::sqrt(0.5), 0});
  expect_vec(sun.irradiance, {0.5, 0.25, 0});
  expect_vec(std::get<SkyLight>(s.lights[3]).radiance, {0.25, 0.25, 0.25});

  ASSERT_EQ(s.surfaces.size(), 2u);
  const auto& plane = std::get<Plane>(s.surfaces[0].shape);
  expect_vec(plane.point, {0, -1, 0});
  expect_vec(plane.normal, {0, 0, 1});
  expect_vec(s.surfaces[0].kd, {0.1, 0.2, 0.3});
  expect_vec(s.surfaces[0].ks, {0, 0, 0});  // default
  EXPECT_DOUBLE_EQ(s.surfaces[0].shininess, 1.0);  // default
  const auto& sphere = std::get<Sphere>(s.surfaces[1].shape);
  expect_vec(sphere.center, {1, 0, 0});
  EXPECT_DOUBLE_EQ(sphere.radius, 0.5);
  expect_vec(s.surfaces[1].kd, {0.5, 0.5, 0.5});  // default
  expect_vec(s.surfaces[1].ks, {0.25, 0.25, 0.25});
  EXPECT_DOUBLE_EQ(s.surfaces[1].shininess, 20.0);

  expect_vec(s.background, {0.1, 0.1, 0.1});
  EXPECT_EQ(s.method_name(), "dom");
  EXPECT_EQ(s.method["directions"], 64);
}

TEST_F(SceneFiles, LoadResolvesGridFileAgainstSceneFolder) {
  fs::path file = test_dir() / "good.json";
  write_text(file, kGoodScene);
  Scene s = Scene::load(file);
  ASSERT_TRUE(s.medium.has_value());
  EXPECT_EQ(std::get<GridDensity>(s.medium->density).values.size(), 24u);
}

TEST(Scene, Defaults) {
  Scene s = Scene::from_json(json::parse(R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]}})"));
  EXPECT_EQ(s.camera.type, Camera::Type::pinhole);
  EXPECT_DOUBLE_EQ(s.camera.fov_y_deg, 40.0);
  expect_vec(s.camera.up, {0, 1, 0});
  EXPECT_EQ(s.camera.width_px, 64);
  EXPECT_EQ(s.camera.height_px, 64);
  EXPECT_FALSE(s.medium.has_value());
  EXPECT_TRUE(s.lights.empty());
  EXPECT_TRUE(s.surfaces.empty());
  expect_vec(s.background, {0, 0, 0});
  EXPECT_EQ(s.method, json::object());
  EXPECT_EQ(s.method_name(), "");

  Scene o = Scene::from_json(json::parse(R"({"camera": {"type": "orthographic", "position": [0, 0, 5],
                                                        "look_at": [0, 0, 0]}})"));
  EXPECT_DOUBLE_EQ(o.camera.height, 2.0);
}

Scene with_medium(const char* medium) {
  json j = json::parse(R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]}})");
  j["medium"] = json::parse(medium);
  return Scene::from_json(j);
}

TEST(Scene, MediumDefaults) {
  Scene s = with_medium(R"({"density": {"type": "constant"}, "sigma_t": 2})");
  const MediumDesc& m = *s.medium;
  EXPECT_FALSE(m.bounds.bounded());
  EXPECT_DOUBLE_EQ(std::get<ConstantDensity>(m.density).value, 1.0);
  expect_vec(m.sigma_t, {2, 2, 2});
  expect_vec(m.albedo, {0.8, 0.8, 0.8});
  EXPECT_EQ(m.phase.type(), PhaseType::isotropic);
}

TEST(Scene, RbfDensity) {
  Scene s = with_medium(R"({"density": {"type": "rbf", "blobs": [
      {"center": [1, 2, 3], "weight": 0.5, "sharpness": 4}, {"center": [0, 0, 0]}]}, "sigma_t": 1})");
  const auto& rbf = std::get<RbfDensity>(s.medium->density);
  ASSERT_EQ(rbf.blobs.size(), 2u);
  expect_vec(rbf.blobs[0].center, {1, 2, 3});
  EXPECT_DOUBLE_EQ(rbf.blobs[0].weight, 0.5);
  EXPECT_DOUBLE_EQ(rbf.blobs[0].sharpness, 4.0);
  EXPECT_DOUBLE_EQ(rbf.blobs[1].weight, 1.0);
  EXPECT_DOUBLE_EQ(rbf.blobs[1].sharpness, 1.0);
}

TEST(Scene, PhaseTypes) {
  auto phase = [](const char* p) {
    return with_medium((std::string(R"({"density": {"type": "constant"}, "sigma_t": 1, "phase": )") + p + "}").c_str())
        .medium->phase;
  };
  // Tabulated [1, 2, 3] over mu = -1, 0, 1 integrates to 2 pi (1.5 + 2.5) = 8 pi before rescaling.
  PhaseFunction tab = phase(R"({"type": "tabulated", "values": [1, 2, 3]})");
  EXPECT_EQ(tab.type(), PhaseType::tabulated);
  EXPECT_NEAR(tab.normalization(), 1.0 / (8.0 * kPi), 1e-12);
  EXPECT_NEAR(tab.eval(1.0), 3.0 / (8.0 * kPi), 1e-12);
  EXPECT_NEAR(tab.eval(-1.0), 1.0 / (8.0 * kPi), 1e-12);

  PhaseFunction dhg = phase(R"({"type": "double_hg", "g1": 0.5, "g2": -0.5, "w": 0.25})");
  EXPECT_EQ(dhg.type(), PhaseType::double_hg);
  EXPECT_NEAR(dhg.eval(0.3), 0.25 * hg_eval(0.5, 0.3) + 0.75 * hg_eval(-0.5, 0.3), 1e-12);

  EXPECT_EQ(phase(R"({"type": "hg", "g": 0.9})").type(), PhaseType::henyey_greenstein);
  EXPECT_NEAR(phase(R"({"type": "hg", "g": 0.9})").mean_cosine(), 0.9, 1e-9);
  EXPECT_EQ(phase(R"({"type": "cornette_shanks", "g": -0.2})").type(), PhaseType::cornette_shanks);
  EXPECT_EQ(phase(R"({"type": "rayleigh"})").type(), PhaseType::rayleigh);
  EXPECT_EQ(phase(R"({"type": "isotropic"})").type(), PhaseType::isotropic);
}

#ifdef HAZE_SOURCE_DIR
// docs/SCENES.md's example must stay a valid scene.
TEST(Scene, DocumentationExampleIsValid) {
  std::ifstream in(fs::path(HAZE_SOURCE_DIR) / "docs" / "SCENES.md");
  std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::size_t begin = doc.find("```json\n");
  ASSERT_NE(begin, std::string::npos);
  begin += 8;
  std::size_t end = doc.find("```", begin);
  ASSERT_NE(end, std::string::npos);
  Scene s = Scene::from_json(json::parse(doc.substr(begin, end - begin)));
  EXPECT_EQ(s.method_name(), "reference");
  EXPECT_EQ(s.lights.size(), 2u);
}
#endif

// ---- Bad scenes --------------------------------------------------------------------------------

// Valid, and touching every object kind, so each bad case below differs from it in one place.
json base_scene() {
  return json::parse(R"({
    "camera": {"type": "pinhole", "position": [0, 0, 5], "look_at": [0, 0, 0], "width_px": 8, "height_px": 8},
    "medium": {"bounds": [[-1, -1, -1], [1, 1, 1]], "density": {"type": "constant", "value": 1},
               "sigma_t": 1, "albedo": 0.8, "phase": {"type": "hg", "g": 0.5}},
    "lights": [{"type": "point", "position": [0, 2, 0], "intensity": 1},
               {"type": "spot", "position": [0, 2, 0], "direction": [0, -1, 0], "intensity": 1,
                "exponent": 2, "cone_deg": 30},
               {"type": "directional", "direction": [0, -1, 0], "irradiance": 1},
               {"type": "sky", "radiance": 0.1}],
    "surfaces": [{"type": "plane", "point": [0, -1, 0], "normal": [0, 1, 0]},
                 {"type": "sphere", "center": [0, 0, 0], "radius": 0.5}],
    "background": [0, 0, 0],
    "method": {"name": "reference", "spp": 4}
  })");
}

// The base scene with values set at JSON pointers ("/medium/albedo").
json edit(std::vector<std::pair<std::string, json>> edits) {
  json j = base_scene();
  for (auto& [pointer, value] : edits) j[json::json_pointer(pointer)] = std::move(value);
  return j;
}

// The base scene without the object member at a JSON pointer.
json drop(const std::string& pointer) {
  json j = base_scene();
  json::json_pointer p(pointer);
  j[p.parent_pointer()].erase(p.back());
  return j;
}

json grid(json resolution, const char* file) {
  return {{"type", "grid"}, {"resolution", std::move(resolution)}, {"file", file}};
}

json grid_without_bounds() {
  json j = drop("/medium/bounds");
  j["medium"]["density"] = grid({2, 2, 2}, "cube.raw");
  return j;
}

struct BadCase {
  std::string name;
  json scene;
  std::string field;    // error.field(), exactly
  std::string message;  // a substring of error.what()
};

std::ostream& operator<<(std::ostream& out, const BadCase& c) { return out << c.name; }

std::vector<BadCase> bad_cases() {
  const double nan = std::nan("");
  const double inf = std::numeric_limits<double>::infinity();
  return {
      // Top level.
      {"NotAnObject", json::array({1, 2}), "(scene)", "a JSON object"},
      {"MissingCamera", drop("/camera"), "camera", "missing"},
      {"UnknownTopLevelField", edit({{"/lihgts", json::array()}}), "lihgts", "a field of the scene: camera, medium"},
      {"LightsNotArray", edit({{"/lights", json::object()}}), "lights", "an array"},
      // Without the particle module, a particles block is a field no registered density type reads.
      {"ParticlesUnregistered", edit({{"/particles", json::object()}}), "particles", "haze::particles::register_methods()"},
      {"BackgroundNegative", edit({{"/background/2", -0.5}}), "background[2]", "[0, 1e15]"},
      {"BackgroundWrongLength", edit({{"/background", {0, 0}}}), "background", "[r, g, b]"},
      {"MethodWithoutName", drop("/method/name"), "method.name", "missing"},
      {"MethodEmptyName", edit({{"/method/name", ""}}), "method.name", "non-empty"},
      {"MethodNameNotString", edit({{"/method/name", 3}}), "method.name", "non-empty method name"},
      // Camera.
      {"CameraUnknownType", edit({{"/camera/type", "fisheye"}}), "camera.type", "\"pinhole\", \"orthographic\""},
      {"CameraMissingPosition", drop("/camera/position"), "camera.position", "missing"},
      {"CameraPositionTooShort", edit({{"/camera/position", {0, 0}}}), "camera.position", "3 finite numbers"},
      {"CameraPositionString", edit({{"/camera/position/1", "0"}}), "camera.position[1]", "a finite number"},
      {"CameraPositionNaN", edit({{"/camera/position/2", nan}}), "camera.position[2]", "got nan"},
      {"CameraLookAtIsPosition", edit({{"/camera/look_at", {0, 0, 5}}}), "camera.look_at", "different from"},
      {"CameraUpParallel", edit({{"/camera/up", {0, 0, -3}}}), "camera.up", "not parallel"},
      {"CameraUpZero", edit({{"/camera/up", {0, 0, 0}}}), "camera.up", "non-zero"},
      {"CameraWidthZero", edit({{"/camera/width_px", 0}}), "camera.width_px", "an integer in [1, 16384]"},
      {"CameraHeightNegative", edit({{"/camera/height_px", -5}}), "camera.height_px", "[1, 16384]"},
      {"CameraWidthTooLarge", edit({{"/camera/width_px", 20000}}), "camera.width_px", "16384"},
      {"CameraWidthHuge", edit({{"/camera/width_px", 18446744073709551615ull}}), "camera.width_px", "16384"},
      {"CameraWidthFraction", edit({{"/camera/width_px", 64.5}}), "camera.width_px", "an integer"},
      {"CameraFovTooWide", edit({{"/camera/fov_y_deg", 180}}), "camera.fov_y_deg", "(0, 180)"},
      {"CameraFovZero", edit({{"/camera/fov_y_deg", 0}}), "camera.fov_y_deg", "(0, 180)"},
      {"OrthoHeightZero", edit({{"/camera/type", "orthographic"}, {"/camera/height", 0}}), "camera.height", "[1e-9, 2e9]"},
      {"PinholeWithHeight", edit({{"/camera/height", 2}}), "camera.height", "unknown field"},
      {"CameraTypo", edit({{"/camera/look_to", {0, 0, 0}}}), "camera.look_to", "look_at"},
      // Medium.
      {"MediumTypo", edit({{"/medium/albdeo", 0.5}}), "medium.albdeo", "bounds, density, sigma_t, albedo, phase"},
      {"MediumMissingDensity", drop("/medium/density"), "medium.density", "missing"},
      {"MediumMissingSigmaT", drop("/medium/sigma_t"), "medium.sigma_t", "missing"},
      {"SigmaTString", edit({{"/medium/sigma_t", "1"}}), "medium.sigma_t", "a finite number"},
      {"SigmaTWrongLength", edit({{"/medium/sigma_t", {1, 2, 3, 4}}}), "medium.sigma_t", "[r, g, b]"},
      {"SigmaTNegative", edit({{"/medium/sigma_t", -1}}), "medium.sigma_t", "[0, 1e9]"},
      {"SigmaTInfinite", edit({{"/medium/sigma_t", {1, inf, 1}}}), "medium.sigma_t[1]", "got inf"},
      {"AlbedoAboveOne", edit({{"/medium/albedo", 1.5}}), "medium.albedo", "[0, 1]"},
      {"AlbedoChannelNegative", edit({{"/medium/albedo", {0.5, -0.1, 0.5}}}), "medium.albedo[1]", "[0, 1]"},
      {"BoundsLoAboveHi", edit({{"/medium/bounds", {{-1, 1, -1}, {1, 1, 1}}}}), "medium.bounds",
       "y0 = 1 is not below y1 = 1"},
      {"BoundsWrongShape", edit({{"/medium/bounds", {-1, 1}}}), "medium.bounds[0]", "3 finite numbers"},
      {"BoundsNotPair", edit({{"/medium/bounds", {{0, 0, 0}}}}), "medium.bounds", "[[x0, y0, z0]"},
      {"DensityUnknownType", edit({{"/medium/density/type", "perlin"}}), "medium.density.type",
       "\"constant\", \"rbf\", \"grid\""},
      {"DensityMissingType", drop("/medium/density/type"), "medium.density.type", "missing"},
      {"ConstantDensityNegative", edit({{"/medium/density/value", -2}}), "medium.density.value", ">= 0"},
      {"ConstantDensityNaN", edit({{"/medium/density/value", nan}}), "medium.density.value", "got nan"},
      {"RbfSharpnessZero",
       edit({{"/medium/density", json::parse(R"({"type": "rbf", "blobs": [{"center": [0, 0, 0]},
           {"center": [1, 0, 0]}, {"center": [0, 1, 0], "sharpness": 0}]})")}}),
       "medium.density.blobs[2].sharpness", "> 0"},
      {"RbfWeightNegative",
       edit({{"/medium/density", json::parse(R"({"type": "rbf", "blobs": [{"center": [0, 0, 0], "weight": -1}]})")}}),
       "medium.density.blobs[0].weight", ">= 0"},
      {"RbfNoBlobs", edit({{"/medium/density", json::parse(R"({"type": "rbf", "blobs": []})")}}),
       "medium.density.blobs", "non-empty"},
      {"RbfBlobTypo",
       edit({{"/medium/density", json::parse(R"({"type": "rbf", "blobs": [{"centre": [0, 0, 0]}]})")}}),
       "medium.density.blobs[0].centre", "center, weight, sharpness"},
      {"GridWithoutBounds", grid_without_bounds(), "medium.bounds", "a grid density needs them"},
      {"GridResolutionZero", edit({{"/medium/density", grid({2, 0, 2}, "cube.raw")}}),
       "medium.density.resolution[1]", "[1, 16384]"},
      {"GridResolutionShort", edit({{"/medium/density", grid({2, 2}, "cube.raw")}}), "medium.density.resolution",
       "[nx, ny, nz]"},
      {"GridMissingFile", edit({{"/medium/density", grid({2, 2, 2}, "nope.raw")}}), "medium.density.file",
       (test_dir() / "nope.raw").string()},
      {"GridFileWrongSize", edit({{"/medium/density", grid({2, 2, 2}, "short.raw")}}), "medium.density.file",
       "got " + (test_dir() / "short.raw").string() + " of 28 bytes, expected 32 bytes"},
      {"GridFileNegative", edit({{"/medium/density", grid({2, 2, 2}, "negative.raw")}}), "medium.density.values[5]",
       "-1 at cell (1, 0, 1)"},
      {"GridFileNaN", edit({{"/medium/density", grid({2, 2, 2}, "nan.raw")}}), "medium.density.values[3]",
       "nan at cell (1, 1, 0)"},
      // Phase functions.
      {"PhaseUnknownType", edit({{"/medium/phase/type", "mie"}}), "medium.phase.type", "\"hg\""},
      {"HgGIsOne", edit({{"/medium/phase/g", 1.0}}), "medium.phase.g", "|g| <= 0.9999"},
      {"HgMissingG", drop("/medium/phase/g"), "medium.phase.g", "missing"},
      {"CornetteShanksGBelowMinusOne", edit({{"/medium/phase", {{"type", "cornette_shanks"}, {"g", -1.5}}}}),
       "medium.phase.g", "|g| <= 0.9999"},
      {"DoubleHgWeightAboveOne",
       edit({{"/medium/phase", {{"type", "double_hg"}, {"g1", 0.5}, {"g2", -0.5}, {"w", 1.5}}}}), "medium.phase.w",
       "[0, 1]"},
      {"DoubleHgG2IsMinusOne",
       edit({{"/medium/phase", {{"type", "double_hg"}, {"g1", 0.5}, {"g2", -1.0}, {"w", 0.5}}}}), "medium.phase.g2",
       "|g| <= 0.9999"},
      {"TabulatedTooShort", edit({{"/medium/phase", {{"type", "tabulated"}, {"values", {1}}}}}),
       "medium.phase.values", "at least 2"},
      {"TabulatedNegative", edit({{"/medium/phase", {{"type", "tabulated"}, {"values", {1, -1, 1}}}}}),
       "medium.phase.values[1]", ">= 0"},
      {"TabulatedAllZero", edit({{"/medium/phase", {{"type", "tabulated"}, {"values", {0, 0, 0}}}}}),
       "medium.phase.values", "positive integral"},
      {"IsotropicWithG", edit({{"/medium/phase/type", "isotropic"}}), "medium.phase.g",
       "a field of medium.phase (type \"isotropic\"): type"},
      // Lights.
      {"LightUnknownType", edit({{"/lights/0/type", "area"}}), "lights[0].type", "\"point\", \"spot\""},
      {"LightMissingType", drop("/lights/0/type"), "lights[0].type", "missing"},
      {"LightIntensityChannelNegative", edit({{"/lights/0/intensity", {1, -1, 1}}}), "lights[0].intensity[1]",
       "[0, 1e15]"},
      {"LightMissingIntensity", drop("/lights/0/intensity"), "lights[0].intensity", "missing"},
      {"SpotConeZero", edit({{"/lights/1/cone_deg", 0}}), "lights[1].cone_deg", "(0, 90]"},
      {"SpotConeTooWide", edit({{"/lights/1/cone_deg", 120}}), "lights[1].cone_deg", "(0, 90]"},
      {"SpotExponentNegative", edit({{"/lights/1/exponent", -1}}), "lights[1].exponent", "[0, 1e5]"},
      {"DirectionalZeroDirection", edit({{"/lights/2/direction", {0, 0, 0}}}), "lights[2].direction", "non-zero"},
      {"SkyRadianceNegative", edit({{"/lights/3/radiance", -0.1}}), "lights[3].radiance", "[0, 1e15]"},
      {"SkyWithPosition", edit({{"/lights/3/position", {0, 0, 0}}}), "lights[3].position", "type, radiance"},
      // Surfaces.
      {"SurfaceUnknownType", edit({{"/surfaces/0/type", "cube"}}), "surfaces[0].type", "\"plane\", \"sphere\""},
      {"PlaneZeroNormal", edit({{"/surfaces/0/normal", {0, 0, 0}}}), "surfaces[0].normal", "non-zero"},
      {"SphereRadiusZero", edit({{"/surfaces/1/radius", 0}}), "surfaces[1].radius", "[1e-9, 1e9]"},
      {"SphereRadiusNegative", edit({{"/surfaces/1/radius", -1}}), "surfaces[1].radius", "[1e-9, 1e9]"},
      {"KdNegative", edit({{"/surfaces/0/kd", -0.5}}), "surfaces[0].kd", "[0, 1]"},
      {"KsAboveOne", edit({{"/surfaces/1/ks", {0.5, 0.5, 2}}}), "surfaces[1].ks[2]", "[0, 1]"},
      {"ShininessNegative", edit({{"/surfaces/0/shininess", -1}}), "surfaces[0].shininess", "[0, 1e5]"},
  };
}

class BadScene : public SceneFiles, public ::testing::WithParamInterface<BadCase> {};

TEST_P(BadScene, ThrowsNamingTheField) {
  const BadCase& c = GetParam();
  try {
    Scene::from_json(c.scene, test_dir());
    FAIL() << "no haze::Error for " << c.scene.dump();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), c.field) << e.what();
    EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos)
        << "message: " << e.what() << "\nwanted: " << c.message;
    EXPECT_FALSE(e.value().empty());
    EXPECT_FALSE(e.expected().empty());
  }
}

INSTANTIATE_TEST_SUITE_P(Scene, BadScene, ::testing::ValuesIn(bad_cases()),
                         [](const ::testing::TestParamInfo<BadCase>& info) { return info.param.name; });

TEST_F(SceneFiles, BaseSceneOfTheBadCasesIsValid) {
  EXPECT_NO_THROW(Scene::from_json(base_scene(), test_dir()));
  json with_grid = base_scene();
  with_grid["medium"]["density"] = grid({2, 2, 2}, "cube.raw");
  EXPECT_NO_THROW(Scene::from_json(with_grid, test_dir()));
}

TEST_F(SceneFiles, LoadMissingFileNamesThePath) {
  fs::path file = test_dir() / "absent.json";
  try {
    Scene::load(file);
    FAIL() << "no haze::Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), file.string());
    EXPECT_NE(std::string(e.what()).find("absent.json"), std::string::npos) << e.what();
  }
}

TEST_F(SceneFiles, LoadSyntaxErrorNamesFileAndLine) {
  fs::path file = test_dir() / "broken.json";
  write_text(file, "{\n  \"camera\": {\n    \"position\": [0, 0, 5],,\n  }\n}\n");
  try {
    Scene::load(file);
    FAIL() << "no haze::Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), file.string());
    std::string what = e.what();
    EXPECT_NE(what.find("broken.json"), std::string::npos) << what;
    EXPECT_NE(what.find("line 3, column 27"), std::string::npos) << what;
  }
}

// Hostile files (issue 26): nesting a million deep, a number past a double, a key given twice and
// values of megabytes each get a haze::Error naming where, and no message floods the terminal.
TEST_F(SceneFiles, HostileJsonGetsClearErrors) {
  auto error_of = [](const fs::path& file) -> Error {
    try {
      Scene::load(file);
    } catch (const Error& e) {
      return e;
    }
    return Error("(no error)");
  };
  const fs::path deep = test_dir() / "deep.json";
  write_text(deep, "{\"medium\": " + std::string(100000, '[') + std::string(100000, ']') + "}");
  Error e = error_of(deep);
  EXPECT_EQ(e.field(), deep.string());
  EXPECT_NE(e.value().find("nested deeper than 256 at medium[0]"), std::string::npos) << e.what();

  const fs::path huge = test_dir() / "huge.json";
  write_text(huge, "{\n  \"camera\": {\"position\": [0, 0, 5],\n    \"look_at\": [0, 1e999, 0]}\n}\n");
  e = error_of(huge);
  EXPECT_EQ(e.field(), huge.string());
  EXPECT_EQ(e.value(), "at line 3, column 20: the number 1e999") << e.what();
  write_text(huge, "{\"background\": 1" + std::string(1000000, '0') + "}");
  e = error_of(huge);
  EXPECT_NE(e.value().find("at line 1, column 16"), std::string::npos) << e.value().substr(0, 300);
  EXPECT_LT(std::string(e.what()).size(), 600u);

  const fs::path twice = test_dir() / "twice.json";
  write_text(twice, R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
    "lights": [{"type": "point", "position": [0, 1, 0], "intensity": 1},
               {"type": "point", "position": [0, 2, 0], "intensity": 1, "position": [0, 3, 0]}]})");
  e = error_of(twice);
  EXPECT_EQ(e.field(), "lights[1].position");
  EXPECT_EQ(e.value(), "given twice");

  const fs::path long_key = test_dir() / "long_key.json";
  write_text(long_key, "{\"camera\": {\"position\": [0, 0, 5], \"look_at\": [0, 0, 0]}, \"" + std::string(50'000'000, 'k') + "\": 1}");
  e = error_of(long_key);
  EXPECT_LT(std::string(e.what()).size(), 1000u);
  EXPECT_NE(e.field().find("(50000000 characters)"), std::string::npos) << e.field().substr(0, 300);

  // A NUL inside a file name would cut it short for the C library ("cube.raw" would be read).
  const fs::path nul = test_dir() / "nul.json";
  write_text(nul, R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
    "medium": {"bounds": [[-1, -1, -1], [1, 1, 1]], "sigma_t": 1,
               "density": {"type": "grid", "resolution": [2, 2, 2], "file": "cube.raw\u0000.vdb"}}})");
  e = error_of(nul);
  EXPECT_EQ(e.field(), "medium.density.file");
  EXPECT_EQ(e.expected(), "a file name without NUL characters");
}

// A value nested 100,000 deep handed over through the API (not a file): its error message shows
// its first levels only.
TEST(Scene, DeepValueThroughTheApiIsShownBriefly) {
  json deep = 1.0;
  for (int i = 0; i < 100000; ++i) {
    json outer = json::array();
    outer.push_back(std::move(deep));
    deep = std::move(outer);
  }
  const json scene = {{"camera", {{"position", {0, 0, 5}}, {"look_at", {0, 0, 0}}}}, {"background", std::move(deep)}};
  try {
    Scene::from_json(scene);
    FAIL() << "no haze::Error";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "background");
    EXPECT_TRUE(e.value().starts_with("[[[[")) << e.value();
    EXPECT_LE(e.value().size(), 80u);
  }
  EXPECT_EQ(json_text(json::array({1, 2, std::nan(""), "x"})), "[1, 2, nan, \"x\"]");
}

}  // namespace
}  // namespace haze
