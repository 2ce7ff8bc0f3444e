// Method dom split over the ranks (haze/mpi/methods.h: RenderOptions::ranks) under mpirun -np 1,
// 2 and 4: the ranks' stretches of every camera ray, composed on rank 0, give method dom's
// single-process image and layers (1e-5 relative) for rays going up the planes, down them and
// across, from one solution rendering three cameras; scenes with surfaces, and methods without a
// split form, are refused on every rank.
#include <haze/core/error.h>
#include <haze/core/method.h>
#include <haze/grids/dom.h>
#include <haze/grids/methods.h>
#include <haze/mpi/dom.h>
#include <haze/mpi/methods.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace haze::mpi {
namespace {

int rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

// Three blobs in a box of 12 z planes, a sun and a point light inside, a dim sky.
Scene cloud(const Vec3& camera, const Vec3& look_at) {
  nlohmann::json j = nlohmann::json::parse(R"({
    "camera": {"width_px": 20, "height_px": 16, "fov_y_deg": 50},
    "medium": {"density": {"type": "rbf", "blobs": [
                 {"center": [0, 0, 0], "weight": 1.0, "sharpness": 3.0},
                 {"center": [0.4, 0.2, 0.3], "weight": 0.8, "sharpness": 4.0},
                 {"center": [-0.3, -0.2, -0.4], "weight": 0.9, "sharpness": 4.0}]},
               "bounds": [[-1, -1, -1], [1, 1, 1]],
               "sigma_t": [3.0, 3.3, 3.6], "albedo": 0.9, "phase": {"type": "hg", "g": 0.5}},
    "lights": [{"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": 2},
               {"type": "point", "position": [0.2, 0.1, 0.05], "intensity": 1},
               {"type": "sky", "radiance": 0.05}],
    "method": {"name": "dom", "resolution": 12, "directions": 48, "terms": 16, "tolerance": 1e-5}
  })");
  j["camera"]["position"] = {camera.x, camera.y, camera.z};
  j["camera"]["look_at"] = {look_at.x, look_at.y, look_at.z};
  return Scene::from_json(j, ".");
}

double relative_rms(const Image& a, const Image& b) {
  double diff = 0.0, ref = 0.0;
  for (int y = 0; y < b.height(); ++y)
    for (int x = 0; x < b.width(); ++x) {
      const Rgb d = a.at(x, y) - b.at(x, y);
      diff += glm::dot(d, d), ref += glm::dot(b.at(x, y), b.at(x, y));
    }
  EXPECT_GT(ref, 0.0);
  return std::sqrt(diff / ref);
}

// From above (every ray down the planes), from the side (up and down) and from below.
RenderOptions split_options() {
  grids::register_methods();
  register_methods();
  RenderOptions options;
  options.threads = 1;
  options.ranks = ranks(MPI_COMM_WORLD);
  return options;
}

TEST(MpiRender, MatchesTheSingleProcessRender) {
  const RenderOptions options = split_options();
  const Solution solution = prepare(cloud(Vec3(0.0, 0.0, 3.0), Vec3(0.0)), "", options);
  for (const auto& [camera, look_at] : {std::pair{Vec3(0.3, 0.4, 3.2), Vec3(0.0)}, {Vec3(3.0, 0.4, 0.2), Vec3(0.0, 0.0, 0.1)}, {Vec3(-0.2, 0.3, -3.0), Vec3(0.0)}}) {
    const Scene scene = cloud(camera, look_at);
    const View view{scene.camera, {}, true};
    RenderOptions render_options;
    render_options.threads = 1;
    const RenderResult split = solution.render(view, render_options);
    if (rank() != 0) {
      EXPECT_EQ(split.radiance.width(), 0);
      continue;
    }
    RenderOptions single_options;
    single_options.threads = 1;
    const RenderResult single = haze::render(scene, "dom", single_options, view);
    ASSERT_TRUE(split.inscatter && single.inscatter);
    const double image = relative_rms(split.radiance, single.radiance), inscatter = relative_rms(*split.inscatter, *single.inscatter),
                 transmittance = relative_rms(*split.transmittance, *single.transmittance);
    std::printf("%d ranks, camera (%g, %g, %g): image %.2e, in-scatter %.2e, transmittance %.2e from the single process's; %d sweeps\n",
                split.stats["ranks"].get<int>(), camera.x, camera.y, camera.z, image, inscatter, transmittance, split.stats["iterations"].get<int>());
    EXPECT_LT(image, 1e-5);
    EXPECT_LT(inscatter, 1e-5);
    EXPECT_LT(transmittance, 1e-6);
    EXPECT_EQ(split.stats["iterations"], single.stats["iterations"]);
    long long cells = 0;
    for (const auto& c : split.stats["rank_cells"]) cells += c.get<long long>();
    const auto n = split.stats["cells"].get<std::array<int, 3>>();
    EXPECT_EQ(cells, static_cast<long long>(n[0]) * n[1] * n[2]);
    EXPECT_EQ(split.stats["rank_wait_seconds"].size(), split.stats["ranks"].get<size_t>());
  }
}

TEST(MpiRender, RefusesSurfacesOnEveryRank) {
  Scene scene = cloud(Vec3(0.3, 0.4, 3.2), Vec3(0.0));
  scene.surfaces.push_back(Surface{Plane{Vec3(0.0, -1.0, 0.0), Vec3(0.0, 1.0, 0.0)}});
  try {
    render(scene, "dom", split_options());
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("surfaces: got 1 surfaces, expected none with the DOM split over MPI ranks"), std::string::npos) << e.what();
  }
}

TEST(MpiRender, RefusesMethodsWithoutASplitFormUnderManyRanks) {
  Scene scene = cloud(Vec3(0.3, 0.4, 3.2), Vec3(0.0));
  scene.lights.pop_back();  // the sky, which propagation does not take
  const int ranks = split_options().ranks->size();
  if (ranks == 1) {  // one rank: the method's own form, for want of a split one
    RenderOptions options = split_options();
    options.settings = {{"resolution", 12}};
    EXPECT_NO_THROW(render(scene, "propagation", options));
    return;
  }
  try {
    render(scene, "propagation", split_options());
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "method.name: got propagation, expected a method split over processes under " + std::to_string(ranks) +
                                         " ranks (dom), or one process");
  }
}

}  // namespace
}  // namespace haze::mpi
