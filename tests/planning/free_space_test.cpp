#include "planning/free_space.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tests/planning/planning_test_support.h"
#include "tests/test_support.h"

namespace fleetmap::planning {
namespace {

using testing::clear_by_brute_force;
using testing::grid_from_ascii;

TEST(FreeSpace, ClearanceIsTheExactDistanceToTheNearestObstacleCentre) {
  std::mt19937 rng(42);
  std::bernoulli_distribution wall(0.08);
  mapping::OccupancyGrid grid(core::GridGeometry(0.1, 37, 23));
  for (int y = 0; y < grid.height(); ++y)
    for (int x = 0; x < grid.width(); ++x) grid.set_state({x, y}, wall(rng) ? mapping::CellState::Occupied : mapping::CellState::Free);
  const FreeSpace space(grid, {0.0, UnknownCells::Obstacle});
  for (int y = 0; y < grid.height(); ++y) {
    for (int x = 0; x < grid.width(); ++x) {
      // Brute force over every obstacle cell and the frame of cells just outside the map.
      double best = INFINITY;
      for (int oy = -1; oy <= grid.height(); ++oy)
        for (int ox = -1; ox <= grid.width(); ++ox)
          if (!grid.contains({ox, oy}) || grid.state({ox, oy}) == mapping::CellState::Occupied)
            best = std::min(best, std::hypot(ox - x, oy - y) * 0.1);
      ASSERT_NEAR(space.clearance({x, y}), best, 1e-4) << "cell " << x << "," << y;
    }
  }
  EXPECT_EQ(space.clearance({-1, 0}), 0.0);
}

TEST(FreeSpace, ValidExactlyWhenClearanceExceedsTheRadius) {
  std::mt19937 rng(7);
  std::bernoulli_distribution wall(0.05), unknown(0.05);
  mapping::OccupancyGrid grid(core::GridGeometry(0.1, 50, 40));
  for (int y = 0; y < grid.height(); ++y)
    for (int x = 0; x < grid.width(); ++x)
      grid.set_state({x, y}, wall(rng) ? mapping::CellState::Occupied
                                       : (unknown(rng) ? mapping::CellState::Unknown : mapping::CellState::Free));
  for (const double radius : {0.0, 0.1, 0.15, 0.2, 0.35}) {
    for (const auto unknown_cells : {UnknownCells::Obstacle, UnknownCells::Free}) {
      const FreeSpace space(grid, {radius, unknown_cells});
      for (int y = 0; y < grid.height(); ++y)
        for (int x = 0; x < grid.width(); ++x)
          ASSERT_EQ(space.valid(core::Cell{x, y}),
                    clear_by_brute_force(grid, {x, y}, radius, unknown_cells == UnknownCells::Obstacle))
              << "cell " << x << "," << y << " radius " << radius;
    }
  }
}

TEST(FreeSpace, UnknownCellsAreObstaclesOrFreeByOption) {
  const auto grid = grid_from_ascii({
      "..........",
      "....??....",
      "....??....",
      "..........",
  });
  const FreeSpace blocked(grid, {0.0, UnknownCells::Obstacle}), open(grid, {0.0, UnknownCells::Free});
  EXPECT_TRUE(blocked.is_obstacle({4, 1}));
  EXPECT_EQ(blocked.cell_state({4, 1}), mapping::CellState::Unknown);
  EXPECT_FALSE(blocked.valid(core::Cell{4, 1}));
  EXPECT_TRUE(open.valid(core::Cell{4, 1}));
  EXPECT_FALSE(blocked.segment_valid({0.05, 0.15}, {0.95, 0.15}));
  EXPECT_TRUE(open.segment_valid({0.05, 0.15}, {0.95, 0.15}));
}

TEST(FreeSpace, SegmentsMayNotClipTheCornerOfAnInvalidCell) {
  // Resolution 1: the obstacle cell (5, 5) is the square [5, 6] x [5, 6].
  std::vector<std::string> rows(10, std::string(10, '.'));
  rows[9 - 5][5] = '#';
  const auto grid = grid_from_ascii(rows, 1.0);
  const FreeSpace space(grid, {0.0, UnknownCells::Obstacle});
  // Crosses x = 5 at y = 5.95: a sliver of the obstacle's corner that samples every 0.35 m miss.
  EXPECT_FALSE(space.segment_valid({4.5, 5.45}, {5.5, 6.45}));
  EXPECT_NEAR(*space.first_invalid_distance({4.5, 5.45}, {5.5, 6.45}), 0.5 * std::sqrt(2.0), 1e-9);
  EXPECT_TRUE(space.segment_valid({4.5, 5.55}, {5.5, 6.55}));  // passes above the corner
  EXPECT_FALSE(space.first_invalid_distance({4.5, 5.55}, {5.5, 6.55}).has_value());

  // Exactly through the corner between two diagonal obstacle cells: blocked.
  rows[9 - 6][4] = '#';
  const FreeSpace gap(grid_from_ascii(rows, 1.0), {0.0, UnknownCells::Obstacle});
  EXPECT_FALSE(gap.segment_valid({4.5, 5.5}, {5.5, 6.5}));
  EXPECT_FALSE(gap.segment_valid({5.5, 6.5}, {4.5, 5.5}));
}

TEST(FreeSpace, SegmentsLeavingTheMapAreInvalid) {
  const auto grid = grid_from_ascii({"....", "....", "...."}, 1.0);
  const FreeSpace space(grid, {0.0, UnknownCells::Obstacle});
  EXPECT_TRUE(space.segment_valid({0.5, 0.5}, {3.5, 2.5}));
  EXPECT_FALSE(space.segment_valid({0.5, 0.5}, {5.0, 0.5}));
  EXPECT_NEAR(*space.first_invalid_distance({0.5, 0.5}, {5.0, 0.5}), 3.5, 1e-6);
  EXPECT_FALSE(space.valid(Eigen::Vector2d(-0.1, 0.5)));
  EXPECT_FALSE(space.path_valid({}));
}

TEST(FreeSpace, RegionsFollowTheRobotRadius) {
  // Two rooms joined by a door 5 cells (0.5 m) wide.
  const auto grid = grid_from_ascii({
      "#####################",
      "#.........#.........#",
      "#.........#.........#",
      "#.........#.........#",
      "#...................#",
      "#...................#",
      "#...................#",
      "#...................#",
      "#...................#",
      "#.........#.........#",
      "#.........#.........#",
      "#.........#.........#",
      "#####################",
  });
  const core::Cell left{4, 6}, right{16, 6};
  // Door cells are 3 cells (0.3 m) from the door posts at most.
  EXPECT_TRUE(FreeSpace(grid, {0.2, UnknownCells::Obstacle}).connected(left, right));
  EXPECT_TRUE(FreeSpace(grid, {0.29, UnknownCells::Obstacle}).connected(left, right));
  EXPECT_FALSE(FreeSpace(grid, {0.3, UnknownCells::Obstacle}).connected(left, right));
  const FreeSpace space(grid, {0.2, UnknownCells::Obstacle});
  EXPECT_FALSE(space.connected(left, {0, 0}));  // a wall cell
  EXPECT_GT(space.region(left), 0);
  EXPECT_EQ(space.region({0, 0}), 0);
}

TEST(FreeSpace, RejectsANegativeRadius) {
  const auto grid = grid_from_ascii({"..", ".."});
  fleetmap::testing::expect_input_error([&] { FreeSpace(grid, {-0.1, UnknownCells::Obstacle}); }, {"radius", "-0.1"});
  fleetmap::testing::expect_input_error([&] { FreeSpace(grid, {NAN, UnknownCells::Obstacle}); }, {"radius"});
}

}  // namespace
}  // namespace fleetmap::planning
