// The map-alignment paper, §VII's reactive steering: the naive baseline.
#include <gtest/gtest.h>

#include "planning/planner.h"
#include "tests/planning/planning_test_support.h"
#include "tests/test_support.h"

namespace fleetmap::planning {
namespace {

using testing::grid_from_ascii;
using testing::path_clear_of_obstacles;

PlanResult reactive(const mapping::OccupancyGrid& grid, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                    const core::Settings& settings = {}) {
  const FreeSpace space(grid, {0.2, UnknownCells::Obstacle});
  PlannerOptions options;
  options.time_budget_s = 10.0;
  return make_planner("reactive", settings)->plan(space, a, b, options);
}

TEST(ReactivePlanner, HeadsStraightForAVisibleGoal) {
  const auto grid = testing::walled_room(60, 40);
  const PlanResult r = reactive(grid, {0.55, 0.75}, {5.1, 3.2});
  ASSERT_TRUE(r.success()) << r.detail;
  EXPECT_EQ(r.path.size(), 2u);  // the steps toward the goal merge into one segment
  EXPECT_NEAR(r.length_m, (Eigen::Vector2d(5.1, 3.2) - Eigen::Vector2d(0.55, 0.75)).norm(), 1e-9);
}

TEST(ReactivePlanner, TurnsAroundAnObstacleInItsWay) {
  auto grid = testing::walled_room(80, 40);
  for (int y = 12; y < 28; ++y)
    for (int x = 36; x < 44; ++x) grid.set_state({x, y}, mapping::CellState::Occupied);
  const Eigen::Vector2d a(1.0, 2.0), b(7.0, 2.0);
  const PlanResult r = reactive(grid, a, b);
  ASSERT_TRUE(r.success()) << r.detail;
  EXPECT_TRUE(path_clear_of_obstacles(grid, r.path, 0.2));
  EXPECT_GT(r.path.size(), 2u);
  EXPECT_GT(r.length_m, (b - a).norm() + 0.2);
  // With a wider turn per step the robot swerves differently.
  const PlanResult w = reactive(grid, a, b, {{"turn_angle_deg", "30"}});
  ASSERT_TRUE(w.success()) << w.detail;
  EXPECT_TRUE(path_clear_of_obstacles(grid, w.path, 0.2));
  EXPECT_NE(w.path, r.path);
}

TEST(ReactivePlanner, GetsCaughtInADeadEndThatAStarLeaves) {
  // A cup open away from the goal: heading for the goal leads into it.
  const auto grid = grid_from_ascii({
      "########################################",
      "#......................................#",
      "#......................................#",
      "#......................................#",
      "#......................................#",
      "#......................................#",
      "#.........###################..........#",
      "#..........................#...........#",
      "#..........................#...........#",
      "#..........................#...........#",
      "#..........................#...........#",
      "#..........................#...........#",
      "#..........................#...........#",
      "#..........................#...........#",
      "#.........###################..........#",
      "#......................................#",
      "#......................................#",
      "#......................................#",
      "#......................................#",
      "#......................................#",
      "########################################",
  });
  const Eigen::Vector2d a(1.3, 1.05), b(3.3, 1.05);  // the cup's middle row
  const PlanResult r = reactive(grid, a, b);
  EXPECT_EQ(r.status, PlanStatus::NotFound) << r.detail;
  EXPECT_TRUE(r.path.empty());
  const FreeSpace space(grid, {0.2, UnknownCells::Obstacle});
  EXPECT_TRUE(make_planner("astar")->plan(space, a, b).success());
}

TEST(ReactivePlanner, RejectsBadOptions) {
  const auto grid = testing::walled_room(20, 20);
  fleetmap::testing::expect_input_error([&] { reactive(grid, {0.5, 0.5}, {1.5, 1.5}, {{"turn_angle_deg", "0"}}); },
                                        {"planner 'reactive'", "turn_angle_deg"});
  fleetmap::testing::expect_input_error([&] { reactive(grid, {0.5, 0.5}, {1.5, 1.5}, {{"look_ahead", "-1"}}); },
                                        {"look_ahead"});
  fleetmap::testing::expect_input_error([&] { make_planner("astar", {{"look_ahead", "1"}}); },
                                        {"planner 'astar' has no parameter 'look_ahead'"});
}

}  // namespace
}  // namespace fleetmap::planning
