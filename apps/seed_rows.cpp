// The source papers' own settings (bench/seeds/rows.json): their scenes and what moves frame to
// frame, for `haze bench seeds` and `haze demo`.
#include "seed_rows.h"

#include <haze/core/error.h>
#include <haze/core/rng.h>
#include <haze/core/stopwatch.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

namespace haze::app {
namespace {

nlohmann::json camera_json(int width, int height, double fov) {
  return {{"position", {0.0, 0.5, 4.0}}, {"look_at", {0.0, 0.0, 0.0}}, {"fov_y_deg", fov}, {"width_px", width}, {"height_px", height}};
}

// The scenes rows.json's rows build. Seed 001, section 4: a cloud of N particles (albedo 0.9, g 0, 2 R tau = 20: sigma_t 10 over the
// unit ball's density 1), two suns (left-up and bottom-right) and a sky, 512 x 512.
nlohmann::json network_cloud(int count) {
  Rng rng(3);
  nlohmann::json positions = nlohmann::json::array();
  while (static_cast<int>(positions.size()) < count) {
    const Vec3 x(2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0, 2.0 * rng.uniform() - 1.0);
    if (glm::dot(x, x) < 1.0) positions.push_back({x.x, x.y, x.z});
  }
  return {{"camera", camera_json(512, 512, 40.0)},
          {"particles", {{"positions", positions}, {"sigma_t", 10.0}, {"albedo", 0.9}, {"phase", {{"type", "hg"}, {"g", 0.0}}}}},
          {"lights",
           {{{"type", "directional"}, {"direction", {0.6, -0.7, -0.3}}, {"irradiance", 1.0}},
            {{"type", "directional"}, {"direction", {-0.5, 0.6, -0.4}}, {"irradiance", 0.6}},
            {{"type", "sky"}, {"radiance", {0.1, 0.15, 0.25}}}}},
          {"background", {0.0, 0.0, 0.0}}};
}

// Seed 002, section 5.2: lamps in homogeneous fog over a Lambert floor with a sphere (Lambert or
// Phong), 640 x 480: the trade suite's fog_lamps (bench/trade), its spot replaced by point lights.
nlohmann::json analytic_fog(int lights, double g, bool phong) {
  const nlohmann::json positions[4] = {{-1.2, 1.8, 0.0}, {1.6, 0.9, -1.5}, {0.3, 2.2, 1.4}, {-1.5, 0.7, -1.2}};
  const nlohmann::json colours[4] = {{14, 11, 7}, {3, 5, 10}, {8, 8, 8}, {6, 9, 5}};
  nlohmann::json l = nlohmann::json::array();
  for (int i = 0; i < lights; ++i) l.push_back({{"type", "point"}, {"position", positions[i]}, {"intensity", colours[i]}});
  nlohmann::json sphere = {{"type", "sphere"}, {"center", {0.4, 0.6, 0.8}}, {"radius", 0.6}, {"kd", {0.6, 0.25, 0.2}}};
  if (phong) sphere["ks"] = 0.4, sphere["shininess"] = 24;
  return {{"camera", camera_json(640, 480, 45.0)},
          {"medium", {{"density", {{"type", "constant"}, {"value", 1.0}}}, {"sigma_t", {0.22, 0.26, 0.32}}, {"albedo", 0.8},
                      {"phase", {{"type", "hg"}, {"g", g}}}, {"bounds", {{-4, 0, -4}, {4, 3.5, 4}}}}},
          {"lights", l},
          {"surfaces", {{{"type", "plane"}, {"point", {0, 0, 0}}, {"normal", {0, 1, 0}}, {"kd", 0.5}}, sphere}},
          {"background", {0.0, 0.0, 0.0}}};
}

// Seed 003, section 5: RBF fog (`blobs` Gaussians filling a unit box, sharpness from their spacing)
// in a box of side 2, point lights, 800 x 600.
nlohmann::json rbf_fog(int blobs, int lights) {
  Rng rng(5);
  const double spacing = 2.0 / std::cbrt(static_cast<double>(blobs));
  nlohmann::json b = nlohmann::json::array();
  for (int i = 0; i < blobs; ++i)
    b.push_back({{"center", {1.6 * rng.uniform() - 0.8, 1.6 * rng.uniform() - 0.8, 1.6 * rng.uniform() - 0.8}},
                 {"weight", 0.5 + 0.5 * rng.uniform()},
                 {"sharpness", std::min(8.0, 1.0 / spacing)}});
  const nlohmann::json positions[8] = {{1.4, 1.2, 1.0}, {-1.3, 0.9, 1.2}, {0.2, 1.5, -1.3}, {-1.2, -1.1, -0.9},
                                       {1.3, -1.0, -1.1}, {0.0, -1.4, 1.3}, {1.5, 0.1, -0.2}, {-1.5, 0.2, 0.1}};
  nlohmann::json l = nlohmann::json::array();
  for (int i = 0; i < lights; ++i) l.push_back({{"type", "point"}, {"position", positions[i]}, {"intensity", 6.0 / lights}});
  return {{"camera", camera_json(800, 600, 40.0)},
          {"medium", {{"bounds", {{-1.0, -1.0, -1.0}, {1.0, 1.0, 1.0}}},
                      {"density", {{"type", "rbf"}, {"blobs", b}}},
                      {"sigma_t", 2.0},
                      {"albedo", 0.9},
                      {"phase", {{"type", "isotropic"}}}}},
          {"lights", l},
          {"background", {0.0, 0.0, 0.0}}};
}

// Seed 000, section 5: a 64^3 grid lit from above (figure 1: uniform fog under a sun through a
// window, its density changing; figure 7: a cloud), albedo 0.9.
nlohmann::json dom_medium(bool cloud) {
  nlohmann::json density = {{"type", "constant"}, {"value", 1.0}};
  if (cloud) {
    Rng rng(9);
    nlohmann::json b = nlohmann::json::array();
    for (int i = 0; i < 40; ++i)
      b.push_back({{"center", {1.6 * rng.uniform() - 0.8, 0.8 * rng.uniform() - 0.4, 1.6 * rng.uniform() - 0.8}}, {"weight", 1.0}, {"sharpness", 2.4}});
    density = {{"type", "rbf"}, {"blobs", b}};
  }
  return {{"camera", camera_json(512, 512, 40.0)},
          {"medium", {{"bounds", {{-1.0, -1.0, -1.0}, {1.0, 1.0, 1.0}}}, {"density", density}, {"sigma_t", cloud ? 4.0 : 1.5}, {"albedo", 0.9},
                      {"phase", {{"type", "hg"}, {"g", cloud ? 0.3 : 0.0}}}}},
          {"lights", {{{"type", "directional"}, {"direction", {0.2, -1.0, 0.1}}, {"irradiance", 3.0}}}},
          {"background", {0.0, 0.0, 0.0}}};
}

// The scene a row's `scene` object names, built.
nlohmann::json build_scene(const nlohmann::json& spec) {
  const std::string build = spec.at("build").get<std::string>();
  if (build == "particle_cloud") return network_cloud(spec.at("particles").get<int>());
  if (build == "fog_lamps") return analytic_fog(spec.at("lights").get<int>(), spec.at("g").get<double>(), spec.at("phong").get<bool>());
  if (build == "rbf_fog") return rbf_fog(spec.at("blobs").get<int>(), spec.at("lights").get<int>());
  if (build == "lit_box") return dom_medium(spec.at("cloud").get<bool>());
  throw Error("scene.build", build, "particle_cloud, fog_lamps, rbf_fog or lit_box");
}

}  // namespace

std::vector<SeedRow> seed_rows(const std::string& path) {
  std::vector<SeedRow> rows;
  std::ifstream in(path);
  if (!in) throw Error("--rows", path, "a readable JSON file (bench/seeds/rows.json)");
  for (const nlohmann::json& r : nlohmann::json::parse(in)) {
    SeedRow row;
    row.paper = r.at("paper").get<std::string>(), row.row = r.at("row").get<std::string>(), row.hardware = r.at("hardware").get<std::string>();
    row.paper_fps = r.at("paper_fps").is_null() ? std::numeric_limits<double>::quiet_NaN() : r.at("paper_fps").get<double>();
    row.settings = r.at("method");
    row.method = row.settings.at("name").get<std::string>();
    row.settings.erase("name");
    row.scene = build_scene(r.at("scene"));
    for (const auto& m : r.at("moves")) (m == "lights" ? row.lights_move : row.density_moves) = true;
    const auto at = r.at("look_at").get<std::vector<double>>();
    row.look_at = Vec3(at[0], at[1], at[2]);
    row.orbit_radius = r.at("orbit")[0].get<double>(), row.orbit_height = r.at("orbit")[1].get<double>();
    row.reference_spp = r.value("reference_spp", -1LL);
    rows.push_back(std::move(row));
  }
  return rows;
}

Scene frame_scene(const SeedRow& row, const Scene& base, int f) {
  Scene s = base;
  const double a = 0.02 * f;
  s.camera.position = row.look_at + Vec3(row.orbit_radius * std::sin(a), row.orbit_height, row.orbit_radius * std::cos(a));
  s.camera.look_at = row.look_at;
  if (row.lights_move) {
    const double b = f * kPi / 180.0, c = std::cos(b), sn = std::sin(b);
    const auto turn = [&](const Vec3& v) { return Vec3(c * v.x + sn * v.z, v.y, -sn * v.x + c * v.z); };
    for (Light& l : s.lights) {
      if (auto* d = std::get_if<DirectionalLight>(&l)) d->direction = turn(d->direction);
      if (auto* p = std::get_if<PointLight>(&l)) p->position = row.look_at + turn(p->position - row.look_at);
    }
  }
  if (row.density_moves && s.medium) {
    if (auto* rbf = std::get_if<RbfDensity>(&s.medium->density))
      for (size_t i = 0; i < rbf->blobs.size(); ++i) rbf->blobs[i].center.x += 0.05 * std::sin(0.1 * f + static_cast<double>(i));
    if (auto* constant = std::get_if<ConstantDensity>(&s.medium->density)) constant->value *= 1.0 + 0.2 * std::sin(0.2 * f);
  }
  return s;
}

FrameTime play_frame(const SeedRow& row, Solution& solution, const Scene& scene, const LayerSpans& out, const RenderOptions& options) {
  const Stopwatch watch;
  if (row.lights_move || row.density_moves) {
    SceneChange change;
    if (row.lights_move) change.lights = scene.lights;
    if (row.density_moves) change.medium = scene.medium;
    solution.update(change, options);
  }
  const double updated = watch.seconds();
  solution.render_layers(View{scene.camera}, out, options);
  return {1e3 * watch.seconds(), 1e3 * updated};
}

}  // namespace haze::app
