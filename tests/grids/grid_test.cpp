// Dense grid layout and the brick-blocked round trip.
#include <haze/core/error.h>
#include <haze/grids/grid.h>

#include <gtest/gtest.h>

namespace haze::grids {
namespace {

TEST(DenseGrid, XFastestCellCentred) {
  DenseGrid g({3, 2, 2}, {Vec3(0), Vec3(3, 2, 2)});
  EXPECT_EQ(g.index(1, 0, 0), 1u);
  EXPECT_EQ(g.index(0, 1, 0), 3u);
  EXPECT_EQ(g.index(0, 0, 1), 6u);
  EXPECT_EQ(g.cell_center(0, 0, 0), Vec3(0.5));
  EXPECT_EQ(g.cell_center(2, 1, 1), Vec3(2.5, 1.5, 1.5));
  EXPECT_THROW(DenseGrid({0, 1, 1}, {Vec3(0), Vec3(1)}), Error);
  EXPECT_THROW(DenseGrid({1, 1, 1}, Aabb{}), Error);
}

TEST(BrickGrid, RoundTripsEveryCellAndPadsWithZero) {
  DenseGrid g({13, 9, 17}, {Vec3(-1), Vec3(1)});
  for (size_t n = 0; n < g.cell_count(); ++n) g.values()[n] = static_cast<float>(n) + 0.5f;
  for (int brick : {1, 4, 8}) {
    BrickGrid b = BrickGrid::from_dense(g, brick);
    EXPECT_EQ(b.to_dense().values(), g.values()) << brick;
    EXPECT_EQ(b.at(12, 8, 16), g.at(12, 8, 16));
    size_t nonzero = 0;
    for (float v : b.values()) nonzero += v != 0.0f;
    EXPECT_EQ(nonzero, g.cell_count());
  }
  // Cells of one brick are contiguous.
  BrickGrid b = BrickGrid::from_dense(g, 8);
  EXPECT_EQ(b.values()[1], g.at(1, 0, 0));
  EXPECT_EQ(b.values()[8], g.at(0, 1, 0));
  EXPECT_EQ(b.values()[64], g.at(0, 0, 1));
  EXPECT_EQ(b.values()[512], g.at(8, 0, 0));
}

}  // namespace
}  // namespace haze::grids
