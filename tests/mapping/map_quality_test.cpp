#include "mapping/map_quality.h"

#include <gtest/gtest.h>

namespace fleetmap::mapping {
namespace {

// A 4 x 3 m room at 0.1 m: free inside, walls on the border.
OccupancyGrid room() {
  OccupancyGrid g(core::GridGeometry(0.1, 40, 30));
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 40; ++x) {
      const bool border = x == 0 || y == 0 || x == 39 || y == 29;
      g.set_state({x, y}, border ? CellState::Occupied : CellState::Free);
    }
  }
  return g;
}

TEST(MapQuality, TheTruthItselfIsPerfect) {
  const OccupancyGrid truth = room();
  const MapQuality q = map_quality(truth, truth);
  EXPECT_EQ(q.known_cells, 40 * 30);
  EXPECT_EQ(q.wall_cells, 2 * 40 + 2 * 28);
  EXPECT_DOUBLE_EQ(q.wrong_cell_share, 0.0);
  EXPECT_DOUBLE_EQ(q.mean_wall_distance_m, 0.0);
  EXPECT_DOUBLE_EQ(q.misplaced_wall_share, 0.0);
}

TEST(MapQuality, UnknownCellsAreNeitherRightNorWrong) {
  const OccupancyGrid truth = room();
  OccupancyGrid map(truth.geometry());
  for (int x = 1; x < 39; ++x) map.set_state({x, 10}, CellState::Free);
  const MapQuality q = map_quality(map, truth);
  EXPECT_EQ(q.known_cells, 38);
  EXPECT_EQ(q.wall_cells, 0);
  EXPECT_DOUBLE_EQ(q.wrong_cell_share, 0.0);
}

TEST(MapQuality, AWallMappedInTheRoomIsWrongAndFarFromTheTrueWalls) {
  const OccupancyGrid truth = room();
  OccupancyGrid map = truth;
  // A phantom wall across the middle, 1.4 m from the nearest true wall (the top one).
  for (int x = 1; x < 39; ++x) map.set_state({x, 15}, CellState::Occupied);
  const MapQuality q = map_quality(map, truth);
  EXPECT_NEAR(q.wrong_cell_share, 38.0 / (40 * 30), 1e-12);
  // Each phantom cell lies min(1.4 m to the top wall, its distance to a side wall) away.
  double phantom = 0.0;
  for (int x = 1; x < 39; ++x) phantom += std::min({1.4, 0.1 * x, 0.1 * (39 - x)});
  const double walls = 2 * 40 + 2 * 28;
  EXPECT_NEAR(q.mean_wall_distance_m, phantom / (walls + 38), 1e-5);
  // Farther than two cells: all but the two cells at each end.
  EXPECT_NEAR(q.misplaced_wall_share, 34.0 / (walls + 38), 1e-12);
}

TEST(MapQuality, AMapInAnotherFrameIsPlacedByItsTransform) {
  const OccupancyGrid truth = room();
  // The same room in a frame turned by 90 degrees and shifted: identical once placed.
  OccupancyGrid turned(core::GridGeometry(0.1, 30, 40));
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x < 30; ++x) turned.set_state({x, y}, truth.state({y, 29 - x}));
  }
  // Turned cell (x, y) holds truth cell (y, 29 - x); in metres (cell centres at 0.1 k + 0.05) that is
  // p -> (p.y, 3 - p.x): a turn by -90 degrees, then 3 m up.
  const core::Transform2 to_truth(0.0, 3.0, -M_PI / 2);
  const MapQuality placed = map_quality(turned, truth, to_truth);
  EXPECT_EQ(placed.known_cells, 40 * 30);
  EXPECT_DOUBLE_EQ(placed.wrong_cell_share, 0.0);
  EXPECT_NEAR(placed.mean_wall_distance_m, 0.0, 1e-9);
  // Without the transform the room lies wrong.
  EXPECT_GT(map_quality(turned, truth).wrong_cell_share, 0.05);
}

TEST(MapQuality, WallsOutsideTheTruthCountTheirWayBack) {
  const OccupancyGrid truth = room();
  OccupancyGrid map(core::GridGeometry(0.1, 50, 30));
  map.set_state({45, 10}, CellState::Occupied);  // 0.6 m beyond the right wall's cells
  const MapQuality q = map_quality(map, truth);
  EXPECT_EQ(q.known_cells, 0);
  EXPECT_EQ(q.wall_cells, 1);
  EXPECT_NEAR(q.mean_wall_distance_m, 0.6, 1e-9);
  EXPECT_DOUBLE_EQ(q.misplaced_wall_share, 1.0);
}

}  // namespace
}  // namespace fleetmap::mapping
