#include "exploration/frontiers.h"

#include <gtest/gtest.h>

#include "exploration/traversability.h"

namespace fleetmap::exploration {
namespace {

using mapping::CellState;
using mapping::OccupancyGrid;

// A 20 x 12 map: a walled, known room (x 1..6, y 1..10) with a 6-cell opening at x = 7, y 3..8
// onto never-observed space (x >= 7, wide enough to explore).
OccupancyGrid room_with_opening() {
  OccupancyGrid g(core::GridGeometry(0.1, 20, 12));
  for (int y = 0; y <= 11; ++y)
    for (int x = 0; x <= 7; ++x) {
      const bool wall = x == 0 || y == 0 || x == 7 || y == 11;
      if (wall && x == 7 && y >= 3 && y <= 8) continue;  // the opening stays unobserved
      g.set_state({x, y}, wall ? CellState::Occupied : CellState::Free);
    }
  return g;
}

TEST(Frontiers, CellsBesideNeverObservedSpace) {
  const auto g = room_with_opening();
  for (int y = 0; y < 12; ++y) {
    for (int x = 0; x < 20; ++x) {
      const bool expected = x == 6 && y >= 3 && y <= 8;
      EXPECT_EQ(is_frontier(g, {x, y}), expected) << x << "," << y;
    }
  }
}

TEST(Frontiers, RegionsHaveSizeAndCentroid) {
  const auto g = room_with_opening();
  const auto regions = find_frontier_regions(g, {6});
  ASSERT_EQ(regions.size(), 1u);
  EXPECT_EQ(regions[0].size(), 6);
  EXPECT_TRUE(regions[0].centroid_m.isApprox(g.geometry().grid_to_world({6.5, 6.0}), 1e-12));
  EXPECT_TRUE(find_frontier_regions(g, {7}).empty());  // smaller than the minimum
}

TEST(Frontiers, UndecidedCellsAndTheMapEdgeAreNotFrontiers) {
  auto g = room_with_opening();
  // Observed with conflicting evidence: Unknown by state, but seen.
  for (int y = 0; y < 12; ++y)
    for (int x = 7; x < 20; ++x) g.set_log_odds({x, y}, 0.25f);
  ASSERT_EQ(g.state({7, 4}), CellState::Unknown);
  EXPECT_TRUE(find_frontier_regions(g, {1}).empty());
  // A free cell on the map's edge does not face unexplored space.
  OccupancyGrid edge(core::GridGeometry(0.1, 3, 3));
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x) edge.set_state({x, y}, CellState::Free);
  EXPECT_TRUE(find_frontier_regions(edge, {1}).empty());
}

TEST(Frontiers, ThinUnknownInsideObstaclesIsOnlyANarrowFrontier) {
  // A free room with a 3-cell-thick block whose inside was never observed, seen through a gap in
  // its outline (what a grazing beam leaves): not wide unknown space, only a narrow strip, which is
  // explored after every wide frontier and gap (it looks like the shadow of a door jamb). Without
  // narrow strips it is no frontier; with the opening width set below the block's thickness it
  // would be a wide one.
  OccupancyGrid g(core::GridGeometry(0.1, 30, 30));
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 30; ++x) g.set_state({x, y}, CellState::Free);
  for (int y = 10; y < 15; ++y)
    for (int x = 5; x < 25; ++x) g.set_state({x, y}, (y == 10 || y == 14 || x == 5 || x == 24) ? CellState::Occupied
                                                                                              : CellState::Unknown);
  for (int y = 11; y < 14; ++y)
    for (int x = 6; x < 24; ++x) g.set_log_odds({x, y}, 0.0f);
  g.set_state({12, 10}, CellState::Free);  // the gap
  EXPECT_EQ(FrontierMask(g, {}).kind({12, 10}), FrontierMask::kNarrow);
  FrontierOptions no_narrow;
  no_narrow.min_narrow_width_m = 0.0;
  EXPECT_TRUE(find_frontier_regions(g, no_narrow).empty());
  EXPECT_FALSE(is_frontier(g, {12, 10}, no_narrow));
  FrontierOptions narrow;
  narrow.min_region_cells = 1;
  narrow.min_unknown_width_m = 0.3;
  EXPECT_EQ(FrontierMask(g, narrow).kind({12, 10}), FrontierMask::kWide);
}

TEST(Frontiers, WindowsAgreeWithTheWholeMap) {
  auto g = room_with_opening();
  const FrontierMask whole(g, {});
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 20; ++x) {
      const FrontierMask local(g, {}, {x - 1, y - 1}, {x + 2, y + 2});
      EXPECT_EQ(local({x, y}), whole({x, y})) << x << "," << y;
    }
}

TEST(Frontiers, SeparateOpeningsAreSeparateRegions) {
  OccupancyGrid g(core::GridGeometry(0.1, 20, 10));
  for (int x = 0; x < 20; ++x)
    for (int y = 0; y < 3; ++y) g.set_state({x, y}, CellState::Free);
  for (int x = 8; x < 12; ++x)
    for (int y = 3; y < 10; ++y) g.set_state({x, y}, CellState::Occupied);  // splits the space above
  const auto regions = find_frontier_regions(g, {1});
  ASSERT_EQ(regions.size(), 2u);
  EXPECT_EQ(regions[0].size() + regions[1].size(), 16);
}

TEST(Targets, LongFrontiersAreSplitAndGoalsAreTraversable) {
  // A 60 m long open row of free cells under unknown space: one long frontier region.
  OccupancyGrid g(core::GridGeometry(0.1, 600, 20));
  for (int x = 0; x < 600; ++x)
    for (int y = 0; y < 8; ++y) g.set_state({x, y}, CellState::Free);
  TraversabilityOptions t;
  t.robot_radius_m = 0.1;
  t.safety_margin_m = 0.0;
  const auto passage = passage_cells(g, t);
  TargetOptions o;
  o.piece_radius_m = 1.5;
  o.approach_radius_m = 0.6;
  const auto targets = find_targets(g, passage, [](const Cell&, const Cell&) { return true; }, o).targets;
  // 60 m of frontier in pieces at most 2 x 1.5 m wide.
  EXPECT_GE(targets.size(), 20u);
  int cells = 0;
  for (const auto& target : targets) {
    // A goal with room to spare near the frontier, in sight of the unseen cell beside it.
    EXPECT_EQ(Passage(passage[std::size_t(g.geometry().index(target.goal))]), Passage::Clear);
    EXPECT_TRUE(is_frontier(g, target.frontier));
    EXPECT_FALSE(g.observed(target.unknown));
    EXPECT_TRUE(sees_over_free(g, target.goal, target.unknown));
    EXPECT_LE((g.geometry().cell_center(target.goal) - g.geometry().cell_center(target.frontier)).norm(), 0.6 + 1e-9);
    cells += target.cells;
  }
  EXPECT_EQ(cells, 600);
}

// Kinds are tried in order, and a kind whose frontiers have no usable goal does not hide the next:
// a room's wide frontier first; when no robot may go there, the narrow strip along a far wall.
TEST(Targets, AKindWithNoUsableGoalLeavesTheNextKindItsTurn) {
  OccupancyGrid g(core::GridGeometry(0.1, 40, 20));
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 40; ++x) {
      const bool unknown = x < 8 || (x >= 36 && x < 39);
      g.set_state({x, y}, x == 39 ? CellState::Occupied : unknown ? CellState::Unknown : CellState::Free);
      if (unknown) g.set_log_odds({x, y}, 0.0f);
    }
  TraversabilityOptions t;
  t.robot_radius_m = 0.1;
  const auto passage = passage_cells(g, t);
  const auto all = find_targets(g, passage, [](const Cell&, const Cell&) { return true; }, {}).targets;
  ASSERT_FALSE(all.empty());
  for (const auto& target : all) EXPECT_EQ(target.kind, FrontierMask::kWide);
  const auto right = find_targets(g, passage, [](const Cell& frontier, const Cell&) { return frontier.x >= 20; }, {}).targets;
  ASSERT_FALSE(right.empty());
  for (const auto& target : right) {
    EXPECT_EQ(target.kind, FrontierMask::kNarrow);
    EXPECT_EQ(target.frontier.x, 35);
  }
}

TEST(Targets, FrontiersWithNoRoomForARobotGiveNoTarget) {
  // A one-cell-wide free corridor: nowhere is there room for a robot of radius 0.2 m.
  OccupancyGrid g(core::GridGeometry(0.1, 30, 5));
  for (int x = 0; x < 30; ++x) {
    g.set_state({x, 1}, CellState::Occupied);
    g.set_state({x, 2}, CellState::Free);
    g.set_state({x, 3}, CellState::Occupied);
  }
  g.set_state({29, 2}, CellState::Unknown);
  g.set_log_odds({29, 2}, 0.0f);
  const auto passage = passage_cells(g, {});
  FrontierOptions any_unknown;
  any_unknown.min_region_cells = 1;
  any_unknown.min_unknown_width_m = 0.0;
  EXPECT_EQ(find_frontier_regions(g, any_unknown).size(), 1u);
  TargetOptions o;
  o.frontiers = any_unknown;
  const auto found = find_targets(g, passage, [](const Cell&, const Cell&) { return true; }, o);
  EXPECT_TRUE(found.targets.empty());
  EXPECT_EQ(found.without_goal.size(), 1u);
}

TEST(Traversability, KeepsTheRobotRadiusAndMarginFromWhatIsNotFree) {
  OccupancyGrid g(core::GridGeometry(0.1, 20, 20));
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 20; ++x) g.set_state({x, y}, x == 0 ? CellState::Occupied : CellState::Free);
  TraversabilityOptions o;
  o.robot_radius_m = 0.2;
  o.safety_margin_m = 0.05;
  const auto p = traversable_cells(g, o);
  // Centre distance to the wall's centres must exceed 2.5 cells: x >= 3.
  EXPECT_FALSE(p[std::size_t(g.geometry().index({2, 10}))]);
  EXPECT_TRUE(p[std::size_t(g.geometry().index({3, 10}))]);
  EXPECT_EQ(cell_clear(g, {2, 10}, o), false);
  EXPECT_EQ(cell_clear(g, {3, 10}, o), true);
}

}  // namespace
}  // namespace fleetmap::exploration
