#include "planning/grid_astar.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <queue>
#include <random>

#include "tests/planning/planning_test_support.h"

namespace fleetmap::planning {
namespace {

using testing::grid_from_ascii;
using testing::path_clear_of_obstacles;

const double kSqrt2 = std::sqrt(2.0);

double astar_cost(const mapping::OccupancyGrid& grid, Cell a, Cell b, double radius = 0.0) {
  const FreeSpace space(grid, {radius, UnknownCells::Obstacle});
  const GridSearch s = astar_grid(space, a, b);
  EXPECT_EQ(s.outcome, GridSearch::Outcome::Found);
  return s.path.cost_m;
}

TEST(GridAStar, OptimalOnAnEmptyGrid) {
  const auto grid = grid_from_ascii(std::vector<std::string>(10, std::string(10, '.')), 1.0);
  EXPECT_NEAR(astar_cost(grid, {0, 0}, {9, 9}), 9 * kSqrt2, 1e-9);
  EXPECT_NEAR(astar_cost(grid, {0, 0}, {9, 3}), 3 * kSqrt2 + 6, 1e-9);
  EXPECT_NEAR(astar_cost(grid, {4, 4}, {4, 4}), 0.0, 1e-12);
  // Costs are metres.
  const auto fine = grid_from_ascii(std::vector<std::string>(10, std::string(10, '.')), 0.05);
  EXPECT_NEAR(astar_cost(fine, {0, 0}, {9, 3}), 0.05 * (3 * kSqrt2 + 6), 1e-9);
}

TEST(GridAStar, OptimalThroughAGapWithoutCuttingItsCorners) {
  const auto grid = grid_from_ascii({
                                        "..........",
                                        "..........",
                                        "#########.",
                                        "..........",
                                        "..........",
                                    },
                                    1.0);
  // Into the gap (9, 2) only from (9, 1) and out only to (9, 3): a diagonal past the wall's end
  // would cut its corner. (0,0) -> (9,1): 8 + sqrt2; through the gap: 2; (9,3) -> (0,4): 8 + sqrt2.
  EXPECT_NEAR(astar_cost(grid, {0, 0}, {0, 4}), 18 + 2 * kSqrt2, 1e-9);
}

TEST(GridAStar, DiagonalStepsNeedBothSideCellsFree) {
  EXPECT_NEAR(astar_cost(grid_from_ascii({"...", "#..", "..."}, 1.0), {0, 0}, {1, 1}), 2.0, 1e-9);
  const auto pinched = grid_from_ascii({"#.", ".#"}, 1.0);
  const FreeSpace space(pinched, {0.0, UnknownCells::Obstacle});
  EXPECT_EQ(astar_grid(space, {0, 0}, {1, 1}).outcome, GridSearch::Outcome::NoPath);
}

TEST(GridAStar, TheRadiusClosesNarrowPassages) {
  const auto grid = grid_from_ascii({
      "#############",
      "#.....#.....#",
      "#...........#",
      "#...........#",
      "#...........#",
      "#.....#.....#",
      "#############",
  });
  const FreeSpace thin(grid, {0.05, UnknownCells::Obstacle}), wide(grid, {0.2, UnknownCells::Obstacle});
  EXPECT_EQ(astar_grid(thin, {2, 3}, {10, 3}).outcome, GridSearch::Outcome::Found);
  EXPECT_EQ(astar_grid(wide, {3, 3}, {9, 3}).outcome, GridSearch::Outcome::NoPath);
}

// Plain Dijkstra over the same graph, to check A*'s costs against.
double dijkstra_cost(const FreeSpace& space, Cell a, Cell b) {
  const GridGeometry& g = space.geometry();
  std::vector<double> dist(static_cast<std::size_t>(g.cell_count()), std::numeric_limits<double>::infinity());
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  dist[static_cast<std::size_t>(g.index(a))] = 0;
  open.emplace(0.0, g.index(a));
  while (!open.empty()) {
    const auto [d, i] = open.top();
    open.pop();
    if (d > dist[static_cast<std::size_t>(i)]) continue;
    const Cell c = g.cell_of_index(i);
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const Cell n{c.x + dx, c.y + dy};
        if ((dx == 0 && dy == 0) || !space.valid(n)) continue;
        if (dx != 0 && dy != 0 && (!space.valid(Cell{c.x + dx, c.y}) || !space.valid(Cell{c.x, c.y + dy}))) continue;
        const double nd = d + g.resolution() * std::hypot(dx, dy);
        if (nd < dist[static_cast<std::size_t>(g.index(n))]) {
          dist[static_cast<std::size_t>(g.index(n))] = nd;
          open.emplace(nd, g.index(n));
        }
      }
    }
  }
  return dist[static_cast<std::size_t>(g.index(b))];
}

TEST(GridAStar, MatchesDijkstraOnRandomGrids) {
  std::mt19937 rng(2024);
  int found = 0;
  for (int trial = 0; trial < 40; ++trial) {
    std::bernoulli_distribution wall(0.25);
    mapping::OccupancyGrid grid(core::GridGeometry(0.1, 30, 20));
    for (int y = 0; y < 20; ++y)
      for (int x = 0; x < 30; ++x) grid.set_state({x, y}, wall(rng) ? mapping::CellState::Occupied : mapping::CellState::Free);
    const FreeSpace space(grid, {0.0, UnknownCells::Obstacle});
    std::uniform_int_distribution<int> px(0, 29), py(0, 19);
    const Cell a{px(rng), py(rng)}, b{px(rng), py(rng)};
    if (!space.valid(a) || !space.valid(b)) continue;
    const double expected = dijkstra_cost(space, a, b);
    const GridSearch s = astar_grid(space, a, b);
    ASSERT_EQ(s.outcome == GridSearch::Outcome::Found, std::isfinite(expected)) << "trial " << trial;
    EXPECT_EQ(std::isfinite(expected), space.connected(a, b)) << "trial " << trial;
    if (!std::isfinite(expected)) continue;
    ++found;
    EXPECT_NEAR(s.path.cost_m, expected, 1e-9) << "trial " << trial;
    // The cells form a chain of valid neighbours whose cost is the reported one.
    ASSERT_EQ(s.path.cells.front(), a);
    ASSERT_EQ(s.path.cells.back(), b);
    double cost = 0;
    for (std::size_t i = 0; i + 1 < s.path.cells.size(); ++i) {
      const Cell d = s.path.cells[i + 1] - s.path.cells[i];
      ASSERT_LE(std::max(std::abs(d.x), std::abs(d.y)), 1);
      ASSERT_TRUE(space.valid(s.path.cells[i + 1]));
      cost += 0.1 * std::hypot(d.x, d.y);
    }
    EXPECT_NEAR(cost, s.path.cost_m, 1e-9);
  }
  EXPECT_GE(found, 10);  // the trials exercised the search, not only the trivial outcomes
}

TEST(GridAStar, SmoothingShortensAndKeepsClear) {
  const auto grid = grid_from_ascii({
      "##############################",
      "#............................#",
      "#............................#",
      "#............................#",
      "#..........#####.............#",
      "#..........#####.............#",
      "#..........#####.............#",
      "#..........#####.............#",
      "#..........#####.............#",
      "#............................#",
      "#............................#",
      "#............................#",
      "#............................#",
      "##############################",
  });
  const double radius = 0.1;
  const FreeSpace space(grid, {radius, UnknownCells::Obstacle});
  const Eigen::Vector2d start(0.33, 0.72), goal(2.71, 0.67);
  const GridSearch s = astar_grid(space, *grid.geometry().world_to_cell(start), *grid.geometry().world_to_cell(goal));
  ASSERT_EQ(s.outcome, GridSearch::Outcome::Found);
  const Path raw = grid_path_waypoints(space, s.path, start, goal);
  EXPECT_TRUE(path_clear_of_obstacles(grid, raw, radius));
  const Path smooth = smooth_any_angle(space, raw);
  EXPECT_TRUE(path_clear_of_obstacles(grid, smooth, radius));
  EXPECT_EQ(smooth.front(), start);
  EXPECT_EQ(smooth.back(), goal);
  EXPECT_LT(smooth.size(), raw.size());
  EXPECT_LT(path_length(smooth), path_length(raw) - 1e-6);
  EXPECT_GE(path_length(smooth), (goal - start).norm());

  // In open space the smoothed path is the straight segment.
  const Eigen::Vector2d a(0.25, 0.25), b(0.95, 0.75);
  const GridSearch open = astar_grid(space, *grid.geometry().world_to_cell(a), *grid.geometry().world_to_cell(b));
  const Path straight = smooth_any_angle(space, grid_path_waypoints(space, open.path, a, b));
  ASSERT_EQ(straight.size(), 2u);
  EXPECT_NEAR(path_length(straight), (b - a).norm(), 1e-12);
}

TEST(GridAStar, StopsAtAPassedDeadline) {
  // A wall with its only gap far away makes the search expand most of the grid.
  std::vector<std::string> rows(200, std::string(200, '.'));
  for (int r = 1; r < 200; ++r) rows[static_cast<std::size_t>(r)][100] = '#';
  const auto grid = grid_from_ascii(rows, 0.1);
  const FreeSpace space(grid, {0.0, UnknownCells::Obstacle});
  const auto past = std::chrono::steady_clock::now() - std::chrono::seconds(1);
  EXPECT_EQ(astar_grid(space, {50, 0}, {150, 0}, past).outcome, GridSearch::Outcome::Stopped);
  EXPECT_EQ(astar_grid(space, {50, 0}, {150, 0}).outcome, GridSearch::Outcome::Found);
}

}  // namespace
}  // namespace fleetmap::planning
