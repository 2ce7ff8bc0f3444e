// The extremes matrix (issue 26; docs/METHODS.md, "Extremes"): every method on a fog box (the
// network on a ball of particles) at g = +-0.999, sigma_t 0 and 1e6, albedo 0 and 1, density 0,
// a light on a pixel's ray, the camera inside the medium and 3e-9 from a light, and the whole
// scene 1e6 times larger and smaller. Every image is finite and non-negative (or the scene is
// refused with a field named); an empty or black medium gives the background exactly; a scaled
// scene gives the image of the unscaled one; the rest agree with the reference (single scattering
// for the single-scattering methods) within the method's bound below plus three of the
// reference's standard errors, or the method says in its stats' "warnings" why not.
#include <haze/core/error.h>
#include <haze/core/method.h>
#include <haze/core/scene.h>
#include <haze/grids/methods.h>
#include <haze/particles/methods.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace haze {
namespace {

using nlohmann::json;

// Fog in [-1, 1]^3 lit by a point light inside it, just above the view (a light in view makes a
// glow that the reference's jittered samples average over each pixel and the other methods sample
// at its centre); 8 x 8 pixels.
json fog_box_json() {
  return {{"camera", {{"position", {0.0, 0.3, 4.0}}, {"look_at", {0.0, 0.0, 0.0}}, {"fov_y_deg", 16.0}, {"width_px", 8}, {"height_px", 8}}},
          {"medium", {{"bounds", {{-1.0, -1.0, -1.0}, {1.0, 1.0, 1.0}}}, {"density", {{"type", "constant"}, {"value", 1.0}}},
                      {"sigma_t", {1.0, 1.2, 1.4}}, {"albedo", 0.9}, {"phase", {{"type", "hg"}, {"g", 0.5}}}}},
          {"lights", {{{"type", "point"}, {"position", {0.3, 0.95, 0.2}}, {"intensity", 5.0}}}},
          {"background", {0.0, 0.0, 0.0}}};
}

// 64 particles on a lattice in [-0.75, 0.75]^3 (each 0.5 across), the same light and camera.
json particle_ball() {
  json positions = json::array();
  for (int i = 0; i < 64; ++i) positions.push_back({-0.75 + 0.5 * (i % 4), -0.75 + 0.5 * (i / 4 % 4), -0.75 + 0.5 * (i / 16)});
  json j = fog_box_json();
  j.erase("medium");
  j["particles"] = {{"positions", positions}, {"diameter", 0.5}, {"sigma_t", 4.0}, {"albedo", 0.9}, {"phase", {{"type", "hg"}, {"g", 0.5}}}};
  return j;
}

json& medium_of(json& j) { return j.contains("medium") ? j["medium"] : j["particles"]; }

// Every length times s: positions, bounds and diameters; sigma_t over s, intensity times s^2 (the
// irradiance at the scaled distances is the same). Radiance is unchanged.
void scale(json& j, double s) {
  auto times = [s](json& v) {
    for (auto& x : v) x = x.get<double>() * s;
  };
  times(j["camera"]["position"]);
  times(j["camera"]["look_at"]);
  for (auto& light : j["lights"]) {
    times(light["position"]);
    light["intensity"] = light["intensity"].get<double>() * s * s;
  }
  json& m = medium_of(j);
  if (m.contains("bounds"))
    for (auto& corner : m["bounds"]) times(corner);
  if (m.contains("positions"))
    for (auto& p : m["positions"]) times(p);
  if (m.contains("diameter")) m["diameter"] = m["diameter"].get<double>() * s;
  json& sigma_t = m["sigma_t"];
  if (sigma_t.is_array())
    for (auto& x : sigma_t) x = x.get<double>() / s;
  else
    sigma_t = sigma_t.get<double>() / s;
}

// What a case expects of every method's image.
enum class Expect { Reference, Background, Unscaled, Finite };

struct Case {
  const char* name;
  Expect expect;
  std::function<void(json&)> change;
};

const std::vector<Case>& cases() {
  static const std::vector<Case> all = {
      {"base", Expect::Reference, [](json&) {}},
      {"g +0.999", Expect::Reference, [](json& j) { medium_of(j)["phase"]["g"] = 0.999; }},
      {"g -0.999", Expect::Reference, [](json& j) { medium_of(j)["phase"]["g"] = -0.999; }},
      {"sigma_t 0", Expect::Background, [](json& j) { medium_of(j)["sigma_t"] = 0.0; }},
      // None of the light gets out (exp(-1e6) is 0 in double).
      {"sigma_t 1e6", Expect::Background, [](json& j) { medium_of(j)["sigma_t"] = 1e6; }},
      {"albedo 0", Expect::Background, [](json& j) { medium_of(j)["albedo"] = 0.0; }},
      {"albedo 1", Expect::Reference, [](json& j) { medium_of(j)["albedo"] = 1.0; }},
      {"density 0", Expect::Background,
       [](json& j) {
         json& m = medium_of(j);
         if (m.contains("positions")) m["density"] = 0.0;
         else m["density"]["value"] = 0.0;
       }},
      // The pixel's radiance is infinite there (the in-scattered 1/r^2 integrates to 1/0).
      {"light on a pixel's ray", Expect::Finite,
       [](json& j) {
         const Camera camera = Scene::from_json(j).camera;
         const Vec3 p = camera.pixel_ray(5, 3).at(4.0);
         j["lights"][0]["position"] = {p.x, p.y, p.z};
       }},
      {"camera inside", Expect::Reference,
       [](json& j) {
         j["camera"]["position"] = {0.0, 0.0, 0.5};
         j["camera"]["look_at"] = {0.0, 0.0, -1.0};
       }},
      {"camera 3e-9 from the light", Expect::Finite,
       [](json& j) {
         j["camera"]["position"] = {0.0, 0.0, 0.5};
         j["camera"]["look_at"] = {0.0, 0.0, -1.0};
         j["lights"][0]["position"] = {3e-9, 0.0, 0.5};
       }},
      {"scale 1e6", Expect::Unscaled, [](json& j) { scale(j, 1e6); }},
      {"scale 1e-6", Expect::Unscaled, [](json& j) { scale(j, 1e-6); }},
  };
  return all;
}

// A method's bound on |mean / reference mean - 1| over the matrix's compared cases (measured:
// docs/METHODS.md, "Extremes").
// Largest measured: analytic, quadrature and propagation 1.1% (g +0.999, noise 0.6%); the DOM at 16
// cells 10.4% (the camera inside); the network 55% (the light inside a particle, the camera among
// them). The DOM at g = +-0.999 and the network from |g| = 0.9 say so in their warnings instead.
const std::map<std::string, double> kBound = {
    {"analytic", 0.02}, {"quadrature", 0.02}, {"propagation", 0.02}, {"dom", 0.15}, {"network", 0.6}};

RenderOptions options_for(const std::string& method) {
  RenderOptions options;
  if (method == "propagation" || method == "dom") options.settings = {{"resolution", 16}};
  if (method == "reference") options.settings = {{"spp", 64}};
  return options;
}

bool single_scattering(const std::string& method) { return method != "dom" && method != "network"; }

// The yardstick: the light paths the method computes (single scattering, or all).
RenderOptions reference_for(const std::string& method) {
  RenderOptions options;
  options.settings = {{"spp", 1024}};
  if (single_scattering(method)) options.settings["max_scattering"] = 1;
  return options;
}

struct Mean {
  double value = 0.0, error = 0.0;  // mean over pixels and channels, and its standard error
};

Mean mean_of(const RenderResult& r) {
  const Image& image = r.radiance;
  Mean m;
  double variance = 0.0;
  const double n = 3.0 * image.width() * image.height();
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      const Rgb c = image.at(x, y);
      m.value += (c.r + c.g + c.b) / n;
      if (r.std_error) {
        const Rgb e = r.std_error->at(x, y);
        variance += (e.r * e.r + e.g * e.g + e.b * e.b) / (n * n);
      }
    }
  m.error = std::sqrt(variance);
  return m;
}

int non_finite_pixels(const Image& image) {
  int bad = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      const Rgb c = image.at(x, y);
      bad += !(std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b) && std::min({c.r, c.g, c.b}) >= 0.0);
    }
  return bad;
}

TEST(ExtremesMatrix, EveryMethodFiniteAndWithinItsBound) {
  particles::register_methods();
  struct Family {
    json scene;
    std::vector<std::string> methods;
  };
  const std::vector<Family> families = {{fog_box_json(), {"analytic", "quadrature", "propagation", "dom", "reference"}},
                                        {particle_ball(), {"network", "reference"}}};
  for (const Family& family : families)
    for (const std::string& method : family.methods) {
      double unscaled = 0.0;
      for (const Case& c : cases()) {
        json j = family.scene;
        c.change(j);
        const Scene scene = Scene::from_json(j);
        const bool compared = c.expect == Expect::Reference && method != "reference";
        RenderResult result;
        try {
          result = render(scene, method, options_for(method));
        } catch (const Error& e) {
          EXPECT_FALSE(e.field().empty()) << method << ", " << c.name << ": " << e.what();
          std::printf("%-12s %-28s refused: %s\n", method.c_str(), c.name, e.what());
          continue;
        }
        EXPECT_EQ(non_finite_pixels(result.radiance), 0) << method << ", " << c.name;
        const Mean m = mean_of(result);
        const bool warned = result.stats.contains("warnings") && !result.stats["warnings"].empty();
        if (c.expect == Expect::Background) {
          EXPECT_EQ(m.value, 0.0) << method << ", " << c.name;
        } else if (c.expect == Expect::Unscaled) {
          EXPECT_NEAR(m.value / unscaled, 1.0, std::max(1e-3, 3.0 * m.error / m.value)) << method << ", " << c.name;
          std::printf("%-12s %-28s %.6f of the unscaled image's mean\n", method.c_str(), c.name, m.value / unscaled);
        } else if (compared) {
          const Mean r = mean_of(render(scene, "reference", reference_for(method)));
          const double ratio = m.value / r.value, noise = r.error / r.value;
          std::printf("%-12s %-28s %.4f of the reference (noise %.4f)%s\n", method.c_str(), c.name, ratio, noise, warned ? ", warned" : "");
          if (!warned) {
            EXPECT_LE(std::abs(ratio - 1.0), kBound.at(method) + 3.0 * noise) << method << ", " << c.name;
          }
        }
        if (std::string(c.name) == "base") unscaled = m.value;
      }
    }
}

}  // namespace
}  // namespace haze
