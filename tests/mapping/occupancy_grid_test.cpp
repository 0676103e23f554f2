#include "mapping/occupancy_grid.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace fleetmap::mapping {
namespace {

OccupancyGrid small_grid() { return OccupancyGrid(GridGeometry(1.0, 10, 10)); }

TEST(OccupancyGrid, StartsUnknownAndOutsideIsUnknown) {
  const auto g = small_grid();
  EXPECT_EQ(g.count(CellState::Unknown), 100);
  EXPECT_EQ(g.state({-1, 0}), CellState::Unknown);
  EXPECT_EQ(g.state({10, 3}), CellState::Unknown);
}

TEST(OccupancyGrid, BeamMarksRayFreeAndEndOccupied) {
  auto g = small_grid();
  const int updated = g.integrate_ray({0.5, 0.5}, {5.5, 0.5}, true);
  EXPECT_EQ(updated, 6);
  for (int x = 0; x < 5; ++x) EXPECT_EQ(g.state({x, 0}), CellState::Free) << x;
  EXPECT_EQ(g.state({5, 0}), CellState::Occupied);
  EXPECT_EQ(g.state({6, 0}), CellState::Unknown);
  EXPECT_EQ(g.state({0, 1}), CellState::Unknown);
  EXPECT_EQ(g.known_count(), 6);
}

TEST(OccupancyGrid, MaxRangeBeamClearsWithoutHit) {
  auto g = small_grid();
  g.integrate_ray({0.5, 0.5}, {5.5, 0.5}, false);
  for (int x = 0; x <= 5; ++x) EXPECT_EQ(g.state({x, 0}), CellState::Free) << x;
  EXPECT_EQ(g.count(CellState::Occupied), 0);
}

TEST(OccupancyGrid, DiagonalBeamVisitsEachCellOnce) {
  auto g = small_grid();
  // From (0.5, 0.2) to (6.5, 3.3): a shallow diagonal; every crossed cell is updated once.
  g.integrate_ray({0.5, 0.2}, {6.5, 3.3}, true);
  const float miss = g.miss_log_odds();
  int free_cells = 0;
  for (int y = 0; y < 10; ++y) {
    for (int x = 0; x < 10; ++x) {
      if (g.state({x, y}) == CellState::Free) {
        ++free_cells;
        EXPECT_FLOAT_EQ(g.log_odds({x, y}), miss);
      }
    }
  }
  EXPECT_EQ(g.state({6, 3}), CellState::Occupied);
  // A 4-connected walk from (0,0) to (6,3) crosses 6 + 3 + 1 cells, the last one the hit.
  EXPECT_EQ(free_cells, 9);
}

TEST(OccupancyGrid, BeamOutsideTheGridIsClipped) {
  auto g = small_grid();
  g.integrate_ray({-5.5, 2.5}, {3.5, 2.5}, true);
  for (int x = 0; x < 3; ++x) EXPECT_EQ(g.state({x, 2}), CellState::Free);
  EXPECT_EQ(g.state({3, 2}), CellState::Occupied);
  g.integrate_ray({5.5, 5.5}, {25.5, 5.5}, true);  // end outside: no hit recorded
  for (int x = 5; x < 10; ++x) EXPECT_EQ(g.state({x, 5}), CellState::Free);
}

TEST(OccupancyGrid, LogOddsAreClampedAndConflictsShow) {
  auto g = small_grid();
  for (int i = 0; i < 100; ++i) g.update_hit({2, 2});
  EXPECT_FLOAT_EQ(g.log_odds({2, 2}), g.max_log_odds());
  for (int i = 0; i < 100; ++i) g.update_miss({3, 3});
  EXPECT_FLOAT_EQ(g.log_odds({3, 3}), g.min_log_odds());
  // One hit and one miss leave the cell undecided.
  g.update_hit({4, 4});
  g.update_miss({4, 4});
  EXPECT_EQ(g.state({4, 4}), CellState::Unknown);
  // Clamping lets a long-occupied cell become free after a few misses.
  for (int i = 0; i < 10; ++i) g.update_miss({2, 2});
  EXPECT_EQ(g.state({2, 2}), CellState::Free);
}

TEST(OccupancyGrid, RejectsInconsistentOptions) {
  OccupancyGridOptions o;
  o.hit_probability = 0.4;
  EXPECT_THROW(OccupancyGrid(GridGeometry(1.0, 2, 2), o), Error);
  o = {};
  o.free_threshold = 0.7;
  EXPECT_THROW(OccupancyGrid(GridGeometry(1.0, 2, 2), o), Error);
}

}  // namespace
}  // namespace fleetmap::mapping
