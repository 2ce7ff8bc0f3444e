// haze::mpi::solve_dom under mpirun -np 1, 2 and 4 (tests/CMakeLists.txt): the parts gathered on
// rank 0 give the single-process solver's moments and image (1e-5 relative) in as many
// iterations; a memory cap one process cannot meet is met by the parts; bad calls fail on every
// rank alike.
#include <haze/core/error.h>
#include <haze/grids/dom.h>
#include <haze/mpi/dom.h>

#include "scenes/small_cloud.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace haze::mpi {
namespace {

using grids::DenseGrid;
using grids::DomSettings;
using grids::DomSolution;
using grids::relative_difference;

int rank_of(MPI_Comm c = MPI_COMM_WORLD) {
  int r = 0;
  MPI_Comm_rank(c, &r);
  return r;
}
int ranks_of(MPI_Comm c = MPI_COMM_WORLD) {
  int r = 1;
  MPI_Comm_size(c, &r);
  return r;
}

// The DOM tests' small cloud (10 z planes), coloured: three channels, the second and third
// started from the one before.
struct Cloud : grids::SmallCloud {
  Cloud() : SmallCloud(Rgb(3.0, 3.3, 3.6)) {}
};

DomSettings small_settings() {
  DomSettings s;
  s.directions = 48;
  s.terms = 16;
  s.tolerance = 1e-5;
  s.threads = 1;
  return s;
}

TEST(MpiDom, SplitPlanes) {
  EXPECT_EQ(split_planes(10, 4, 0), (std::array<int, 2>{0, 3}));
  EXPECT_EQ(split_planes(10, 4, 1), (std::array<int, 2>{3, 6}));
  EXPECT_EQ(split_planes(10, 4, 3), (std::array<int, 2>{8, 10}));
  try {
    split_planes(3, 4, 0);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("ranks: got 4, expected at most as many ranks as the grid's 3 z planes"), std::string::npos) << e.what();
  }
}

// The parts' moments, gathered, are the single-process moments to 1e-5 (the dot products are
// summed in another order), after the same number of sweeps; so is render_dom's image.
TEST(MpiDom, MatchesTheSingleProcessSolver) {
  const Cloud s;
  const DomSettings settings = small_settings();
  const DomSolution single = grids::solve_dom(s.volume, s.lights, s.depths, settings);
  DomPartStats stats;
  const DomSolution part = solve_dom(MPI_COMM_WORLD, s.volume, s.lights, s.depths, settings, nullptr, &stats);
  EXPECT_EQ(stats.ranks, ranks_of());
  EXPECT_EQ(stats.planes, split_planes(10, ranks_of(), rank_of()));
  EXPECT_EQ(stats.cells, size_t{16 * 12} * static_cast<size_t>(stats.planes[1] - stats.planes[0]));
  EXPECT_EQ(part.iterations, single.iterations);
  EXPECT_EQ(part.converged, single.converged);
  const DomSolution whole = gather(MPI_COMM_WORLD, part);
  if (rank_of() != 0) return;
  ASSERT_EQ(single.channels, 3);
  ASSERT_EQ(whole.resolution, single.resolution);
  for (int c = 0; c < 3; ++c) {
    ASSERT_EQ(whole.moments[static_cast<size_t>(c)].size(), single.moments[static_cast<size_t>(c)].size());
    const double d = relative_difference(whole.moments[static_cast<size_t>(c)], single.moments[static_cast<size_t>(c)]);
    std::printf("%d ranks, channel %d: %d sweeps, moments %.2e from the single process's\n", ranks_of(), c, part.iterations, d);
    EXPECT_LT(d, 1e-5) << "channel " << c;
  }
  Scene scene;
  scene.camera.position = Vec3(0.3, 0.4, 3.2);
  scene.camera.width_px = scene.camera.height_px = 24;
  scene.lights = s.lights;
  const Image a = grids::render_dom(scene, s.volume, s.depths, single, 0.5, {}, View{scene.camera}).radiance,
              b = grids::render_dom(scene, s.volume, s.depths, whole, 0.5, {}, View{scene.camera}).radiance;
  double diff = 0.0, ref = 0.0;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x) {
      const Rgb d = a.at(x, y) - b.at(x, y);
      diff += glm::dot(d, d), ref += glm::dot(a.at(x, y), a.at(x, y));
    }
  EXPECT_GT(ref, 0.0);
  EXPECT_LT(std::sqrt(diff / ref), 1e-5);
}

// Planes given by the caller, one a rank but the last, which takes the rest: the same moments as
// the single process; planes that do not follow each other are refused on every rank.
TEST(MpiDom, PlanesGivenByTheCaller) {
  const Cloud s;
  const DomSettings settings = small_settings();
  const int r = rank_of(), n = ranks_of();
  const std::array<int, 2> planes{r, r == n - 1 ? 10 : r + 1};
  DomPartStats stats;
  const DomSolution part = solve_dom(MPI_COMM_WORLD, s.volume, s.lights, s.depths, settings, nullptr, &stats, planes);
  EXPECT_EQ(stats.planes, planes);
  const DomSolution whole = gather(MPI_COMM_WORLD, part);
  if (r == 0) {
    const DomSolution single = grids::solve_dom(s.volume, s.lights, s.depths, settings);
    EXPECT_EQ(part.iterations, single.iterations);
    for (int c = 0; c < 3; ++c) EXPECT_LT(relative_difference(whole.moments[static_cast<size_t>(c)], single.moments[static_cast<size_t>(c)]), 1e-5);
  }
  if (n < 2) return;
  try {
    solve_dom(MPI_COMM_WORLD, s.volume, s.lights, s.depths, settings, nullptr, nullptr, {0, 10});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("planes: got [0, 10) on rank 1 of " + std::to_string(n) + ", expected planes following each other in rank order"),
              std::string::npos)
        << e.what();
  }
}

// Warm starts work per rank: each rank's part of a converged solve starts the same solve again,
// which stops at once, as the single-process warm start does.
TEST(MpiDom, WarmStartPerRank) {
  const Cloud s;
  const DomSettings settings = small_settings();
  const DomSolution single = grids::solve_dom(s.volume, s.lights, s.depths, settings);
  const DomSolution single_warm = grids::solve_dom(s.volume, s.lights, s.depths, settings, &single);
  const DomSolution part = solve_dom(MPI_COMM_WORLD, s.volume, s.lights, s.depths, settings);
  const DomSolution again = solve_dom(MPI_COMM_WORLD, s.volume, s.lights, s.depths, settings, &part);
  EXPECT_EQ(again.iterations, single_warm.iterations);
  EXPECT_LT(again.iterations, part.iterations);
}

// A cap one process's solve exceeds but each part meets: refused whole, solved split (with two
// ranks or more); the refusal names the field and what would fit.
TEST(MpiDom, MemoryCapPerRank) {
  if (ranks_of() < 2) GTEST_SKIP() << "needs 2 ranks or more";
  const Cloud s;
  DomSettings settings = small_settings();
  const size_t whole = grids::dom_memory_bytes({16, 12, 10}, 3, settings);
  const size_t largest_part = grids::dom_memory_bytes({16, 12, split_planes(10, ranks_of(), 0)[1]}, 3, settings);
  ASSERT_LT(largest_part, whole);
  settings.max_memory = (whole + largest_part) / 2;
  try {
    grids::solve_dom(s.volume, s.lights, s.depths, settings);
    FAIL() << "the whole grid fitted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("dom grid"), std::string::npos) << e.what();
  }
  const DomSolution part = solve_dom(MPI_COMM_WORLD, s.volume, s.lights, s.depths, settings);
  EXPECT_TRUE(part.converged);
}

// A cap the first rank's part (the largest) cannot meet fails the call on every rank, each with a
// haze::Error: rank 0 its own, the others naming it.
TEST(MpiDom, OneRankRefusingStopsAll) {
  if (ranks_of() < 2) GTEST_SKIP() << "needs 2 ranks or more";
  const Cloud s;
  DomSettings settings = small_settings();
  const size_t first = grids::dom_memory_bytes({16, 12, split_planes(10, ranks_of(), 0)[1] - split_planes(10, ranks_of(), 0)[0]}, 3, settings);
  const size_t last = grids::dom_memory_bytes({16, 12, split_planes(10, ranks_of(), ranks_of() - 1)[1] - split_planes(10, ranks_of(), ranks_of() - 1)[0]}, 3, settings);
  if (first == last) GTEST_SKIP() << "equal parts";
  settings.max_memory = (first + last) / 2;
  try {
    solve_dom(MPI_COMM_WORLD, s.volume, s.lights, s.depths, settings);
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string what = e.what();
    const bool own = what.find("dom grid") != std::string::npos, named = what.find("ranks: got rank 0 of") != std::string::npos;
    EXPECT_TRUE(own || named) << what;
    if (rank_of() == 0) {
      EXPECT_TRUE(own) << what;
    }
  }
}

// Different settings on different ranks: a haze::Error on every rank, not a hang.
TEST(MpiDom, MismatchedSettingsAreAnError) {
  if (ranks_of() < 2) GTEST_SKIP() << "needs 2 ranks or more";
  const Cloud s;
  DomSettings settings = small_settings();
  if (rank_of() == 1) settings.directions = 64;
  try {
    solve_dom(MPI_COMM_WORLD, s.volume, s.lights, s.depths, settings);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("ranks: got rank 1 with another volume, lights or settings than rank 0"), std::string::npos) << e.what();
  }
}

// A split solve refuses what it does not do yet, on every rank alike.
TEST(MpiDom, RefusesSourceIteration) {
  const Cloud s;
  DomSettings settings = small_settings();
  settings.accelerator = grids::DomAccelerator::none;
  try {
    solve_dom(MPI_COMM_WORLD, s.volume, s.lights, s.depths, settings);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("accelerator: got none, expected \"gmres\" in a solve split over processes"), std::string::npos)
        << e.what();
  }
}

// Cancelling on one rank cancels every rank at the same iteration.
TEST(MpiDom, CancellingIsCollective) {
  const Cloud s;
  DomSettings settings = small_settings();
  int calls = 0;
  settings.progress = [&](double) { return !(rank_of() == ranks_of() - 1 && ++calls == 3); };
  EXPECT_THROW(solve_dom(MPI_COMM_WORLD, s.volume, s.lights, s.depths, settings), Cancelled);
}

}  // namespace
}  // namespace haze::mpi

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  ::testing::InitGoogleTest(&argc, argv);
  // Only rank 0 prints (the others' failures still fail the run through their exit status).
  if (haze::mpi::rank_of() != 0) delete ::testing::UnitTest::GetInstance()->listeners().Release(
      ::testing::UnitTest::GetInstance()->listeners().default_result_printer());
  const int result = RUN_ALL_TESTS();
  MPI_Finalize();
  return result;
}
