#include "exploration/tour_gain.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace fleetmap::exploration {
namespace {

using mapping::CellState;
using mapping::OccupancyGrid;

// A 100 x 60 map at 0.1 m: the left 20 columns known free, the rest never observed.
OccupancyGrid half_known() {
  OccupancyGrid g(core::GridGeometry(0.1, 100, 60));
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 20; ++x) g.set_state({x, y}, CellState::Free);
  return g;
}

Target looking_at(const Cell& unknown) {
  Target t;
  t.unknown = unknown;
  t.frontier = {unknown.x - 1, unknown.y};
  t.goal = t.frontier;
  return t;
}

TEST(TourGain, AHalfDiscOfUnknownBehindALoneFrontier) {
  const OccupancyGrid g = half_known();
  // Reach 2 m from (20, 30): the unknown half of a disc of radius 20 cells, pi r^2 / 2, and the
  // cells on its diameter (x = 20, 41 cells of 0.01 m^2, half of them beyond pi r^2 / 2).
  const auto area = unknown_area_behind(g, {looking_at({20, 30})}, 2.0);
  ASSERT_EQ(area.size(), 1u);
  EXPECT_NEAR(area[0], M_PI * 2.0 * 2.0 / 2.0 + 0.2, 0.05);
}

TEST(TourGain, NeighboursShareTheAreaAndNothingCountsTwice) {
  const OccupancyGrid g = half_known();
  const double alone = unknown_area_behind(g, {looking_at({20, 30})}, 2.0)[0];
  // Two frontiers 1 m apart: their discs overlap, and the overlap counts once, for the one whose
  // flood (in 8-connected steps) arrives first: together less than twice one alone, each its own
  // side at least.
  const auto area = unknown_area_behind(g, {looking_at({20, 25}), looking_at({20, 35})}, 2.0);
  EXPECT_LT(area[0] + area[1], 2.0 * alone - 1.0);
  EXPECT_GT(area[0] + area[1], alone + 1.0);
  EXPECT_GT(std::min(area[0], area[1]), 0.4 * alone);
}

TEST(TourGain, NothingBehindAnObservedCellOrAWall) {
  OccupancyGrid g = half_known();
  // The target's unknown cell was seen meanwhile: no area.
  g.set_state({20, 10}, CellState::Free);
  // A target looking into a pocket closed by a wall: only the pocket counts.
  for (int y = 40; y <= 50; ++y) g.set_state({23, y}, CellState::Occupied);
  for (int x = 20; x <= 23; ++x) g.set_state({x, 40}, CellState::Occupied), g.set_state({x, 50}, CellState::Occupied);
  const auto area = unknown_area_behind(g, {looking_at({20, 10}), looking_at({21, 45})}, 2.0);
  EXPECT_EQ(area[0], 0.0);
  EXPECT_NEAR(area[1], 3 * 9 * 0.01, 1e-9);  // x 20..22, y 41..49
}

}  // namespace
}  // namespace fleetmap::exploration
