#include "sim/communication.h"

#include <gtest/gtest.h>

#include <limits>

#include "tests/sim/sim_test_maps.h"

namespace fleetmap::sim {
namespace {

TEST(Communication, RangeAndLineOfSightAreRespected) {
  auto grid = testing::walled_room(100, 40);
  for (int y = 0; y < 39; ++y) grid.set_state({50, y}, mapping::CellState::Occupied);  // wall at x = 5 m
  const World world(grid, {});
  const std::vector<core::Pose2> robots = {{1.0, 1.0, 0}, {3.0, 1.0, 0}, {7.0, 1.0, 0}};
  const std::vector<std::vector<Detection>> none(3);
  CommunicationOptions o;
  o.range_m = 2.5;
  auto l = communication_links(world, robots, none, o);
  EXPECT_TRUE(l[0][1]);
  EXPECT_TRUE(l[1][0]);
  EXPECT_FALSE(l[0][2]);
  EXPECT_FALSE(l[1][2]);  // 4 m apart
  o.range_m = 4.5;
  l = communication_links(world, robots, none, o);
  EXPECT_TRUE(l[1][2]);
  o.line_of_sight = true;
  l = communication_links(world, robots, none, o);
  EXPECT_FALSE(l[1][2]) << "the wall at x = 5 m cuts the link";
  o.range_m = std::numeric_limits<double>::infinity();
  o.line_of_sight = false;
  l = communication_links(world, robots, none, o);
  EXPECT_TRUE(l[0][2]);
  // Range 0: only robots that detect each other (here robot 2 sees robot 1).
  o.range_m = 0.0;
  std::vector<std::vector<Detection>> seen(3);
  seen[2].push_back({1, 4.0, 3.14});
  l = communication_links(world, robots, seen, o);
  EXPECT_TRUE(l[1][2]);
  EXPECT_TRUE(l[2][1]);
  EXPECT_FALSE(l[0][1]);
}

TEST(MapExchange, SendsOnlyWhatChangedAndNeverOverwritesOwnEvidence) {
  const core::GridGeometry g(0.1, 64, 64);
  std::vector<mapping::OccupancyGrid> maps = {mapping::OccupancyGrid(g), mapping::OccupancyGrid(g)};
  MapExchange ex(2, g);
  // Robot 0 sees two cells in one tile; robot 1 has its own view of one of them.
  maps[0].set_state({3, 3}, mapping::CellState::Occupied);
  ex.touched(0, g.index({3, 3}));
  maps[0].set_state({4, 3}, mapping::CellState::Free);
  ex.touched(0, g.index({4, 3}));
  maps[1].set_state({3, 3}, mapping::CellState::Free);
  ex.touched(1, g.index({3, 3}));
  const std::int64_t bytes = ex.exchange(0, maps[0], 1, maps[1]);
  // One 16 x 16 tile each way: 2 x (4 + 256) bytes.
  EXPECT_EQ(bytes, 2 * (MapExchange::kTileHeaderBytes + 16 * 16));
  EXPECT_EQ(maps[1].state({4, 3}), mapping::CellState::Free);   // filled in
  EXPECT_EQ(maps[1].state({3, 3}), mapping::CellState::Free);   // its own evidence kept
  EXPECT_EQ(maps[0].state({3, 3}), mapping::CellState::Occupied);
  // Nothing new: nothing sent.
  EXPECT_EQ(ex.exchange(0, maps[0], 1, maps[1]), 0);
  // A change in another tile: only that tile travels.
  maps[1].set_state({40, 40}, mapping::CellState::Occupied);
  ex.touched(1, g.index({40, 40}));
  EXPECT_EQ(ex.exchange(1, maps[1], 0, maps[0]), MapExchange::kTileHeaderBytes + 16 * 16);
  EXPECT_EQ(maps[0].state({40, 40}), mapping::CellState::Occupied);
}

TEST(MapExchange, WhatWasReceivedIsRelayed) {
  const core::GridGeometry g(0.1, 32, 32);
  std::vector<mapping::OccupancyGrid> maps(3, mapping::OccupancyGrid(g));
  MapExchange ex(3, g);
  maps[0].set_state({1, 1}, mapping::CellState::Occupied);
  ex.touched(0, g.index({1, 1}));
  ex.exchange(0, maps[0], 1, maps[1]);
  ex.exchange(1, maps[1], 2, maps[2]);  // robot 2 never met robot 0
  EXPECT_EQ(maps[2].state({1, 1}), mapping::CellState::Occupied);
}

}  // namespace
}  // namespace fleetmap::sim
