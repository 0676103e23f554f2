#include "core/grid_geometry.h"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "core/error.h"

namespace fleetmap::core {
namespace {

TEST(GridGeometry, WorldToCellAndBack) {
  const GridGeometry g(0.1, 200, 100, Pose2(-5.0, -2.0, 0.0));
  EXPECT_EQ(g.world_to_cell({-5.0, -2.0}), (Cell{0, 0}));
  EXPECT_EQ(g.world_to_cell({-4.95, -1.85}), (Cell{0, 1}));
  EXPECT_EQ(g.world_to_cell({14.99, 7.99}), (Cell{199, 99}));
  EXPECT_FALSE(g.world_to_cell({15.0, 0.0}).has_value());
  EXPECT_FALSE(g.world_to_cell({-5.01, 0.0}).has_value());
  EXPECT_FALSE(g.world_to_cell({0.0, 8.0}).has_value());
  EXPECT_EQ(g.world_to_cell_unbounded({-5.05, -2.05}), (Cell{-1, -1}));
  EXPECT_TRUE(g.cell_center({3, 4}).isApprox(Eigen::Vector2d(-4.65, -1.55), 1e-12));
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> cx(0, 199), cy(0, 99);
  for (int i = 0; i < 500; ++i) {
    const Cell c{cx(rng), cy(rng)};
    EXPECT_EQ(g.world_to_cell(g.cell_center(c)), c);
    EXPECT_EQ(g.cell_of_index(g.index(c)), c);
  }
}

TEST(GridGeometry, RotatedOrigin) {
  // A map whose origin is turned by 90 degrees: grid x runs along world +y.
  const GridGeometry g(0.5, 10, 10, Pose2(1.0, 1.0, std::numbers::pi / 2.0));
  EXPECT_EQ(g.world_to_cell({0.9, 1.1}), (Cell{0, 0}));
  EXPECT_EQ(g.world_to_cell({0.9, 2.1}), (Cell{2, 0}));
  EXPECT_FALSE(g.world_to_cell({1.1, 1.1}).has_value());
}

TEST(GridGeometry, RejectsBadResolution) {
  EXPECT_THROW(GridGeometry(0.0, 10, 10), Error);
  EXPECT_THROW(GridGeometry(-0.1, 10, 10), Error);
  EXPECT_THROW(GridGeometry(0.1, -1, 10), Error);
}

}  // namespace
}  // namespace fleetmap::core
