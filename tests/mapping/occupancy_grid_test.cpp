#include "mapping/occupancy_grid.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "core/random.h"

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

TEST(Coarsen, WallsStayHalfSeenFreeSpaceStaysFreeTheRestIsUnknown) {
  // 10 x 7 cells of 0.1 m seen through 4 x 4 blocks: 3 x 2 coarse cells of 0.4 m (the right and
  // top blocks are partial).
  OccupancyGrid fine(GridGeometry(0.1, 10, 7, core::Pose2(1.0, 2.0, 0.0)));
  // Block (0, 0): all free but one occupied cell.
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) fine.set_state({x, y}, CellState::Free);
  fine.set_state({2, 1}, CellState::Occupied);
  // Block (1, 0): 8 of 16 free, the rest never seen (the gaps between far beams).
  for (int y = 0; y < 4; y += 2)
    for (int x = 4; x < 8; ++x) fine.set_state({x, y}, CellState::Free);
  // Block (2, 0): 2 x 4 cells (partial); 3 of 8 free: less than half.
  fine.set_state({8, 0}, CellState::Free);
  fine.set_state({9, 0}, CellState::Free);
  fine.set_state({8, 1}, CellState::Free);
  // Block (0, 1): 4 x 3 cells (partial), all free.
  for (int y = 4; y < 7; ++y)
    for (int x = 0; x < 4; ++x) fine.set_state({x, y}, CellState::Free);

  const OccupancyGrid coarse = coarsen(fine, 4);
  EXPECT_EQ(coarse.width(), 3);
  EXPECT_EQ(coarse.height(), 2);
  EXPECT_DOUBLE_EQ(coarse.resolution(), 0.4);
  EXPECT_EQ(coarse.geometry().origin(), fine.geometry().origin());
  EXPECT_EQ(coarse.state({0, 0}), CellState::Occupied);
  EXPECT_EQ(coarse.state({1, 0}), CellState::Free);
  EXPECT_EQ(coarse.state({2, 0}), CellState::Unknown);
  EXPECT_EQ(coarse.state({0, 1}), CellState::Free);
  EXPECT_EQ(coarse.state({1, 1}), CellState::Unknown);
  EXPECT_EQ(coarse.state({2, 1}), CellState::Unknown);
  EXPECT_EQ(coarse.observed_count(), 3);
  // The same place in metres holds the same thing.
  EXPECT_EQ(coarse.geometry().world_to_cell(fine.geometry().cell_center({2, 1})), (Cell{0, 0}));
}

TEST(Coarsen, FactorOneIsACopyAndBelowOneIsRefused) {
  OccupancyGrid fine(GridGeometry(0.1, 5, 5));
  fine.integrate_ray({0.05, 0.05}, {0.45, 0.35}, true);
  EXPECT_TRUE(coarsen(fine, 1).same_states(fine));
  EXPECT_THROW(coarsen(fine, 0), Error);
}

// A room of 0.05 m cells with walls, free inside and unknown beyond, seen by a seeded fan of beams
// from its middle (as a robot's map is: speckled free space, walls of one or two cells).
OccupancyGrid scanned_room(double resolution) {
  OccupancyGrid g(GridGeometry(resolution, int(std::lround(6.0 / resolution)), int(std::lround(4.0 / resolution)),
                               core::Pose2(1.0, -2.0, 0.0)));
  core::Random random(3);
  for (int k = 0; k < 2000; ++k) {
    const double a = random.uniform(0.0, 2.0 * M_PI);
    const Eigen::Vector2d from(3.9, -0.1);
    // The room is [1.5, 6.5] x [-1.6, 1.6]: a beam ends on its wall.
    const Eigen::Vector2d d(std::cos(a), std::sin(a));
    const double tx = d.x() > 0 ? (6.5 - from.x()) / d.x() : (1.5 - from.x()) / d.x();
    const double ty = d.y() > 0 ? (1.6 - from.y()) / d.y() : (-1.6 - from.y()) / d.y();
    g.integrate_ray(from, from + std::min(tx, ty) * d, true);
  }
  return g;
}

TEST(Resample, AWholeNumberOfTimesCoarserTakesWholeBlocks) {
  const OccupancyGrid fine = scanned_room(0.05);
  for (int factor : {2, 3, 4}) {
    const OccupancyGrid coarse = resample(fine, 0.05 * factor);
    ASSERT_EQ(coarse.width(), (fine.width() + factor - 1) / factor);
    ASSERT_EQ(coarse.height(), (fine.height() + factor - 1) / factor);
    for (int cy = 0; cy < coarse.height(); ++cy) {
      for (int cx = 0; cx < coarse.width(); ++cx) {
        int cells = 0, free = 0, occupied = 0;
        for (int y = cy * factor; y < std::min(fine.height(), (cy + 1) * factor); ++y)
          for (int x = cx * factor; x < std::min(fine.width(), (cx + 1) * factor); ++x) {
            ++cells;
            free += fine.state({x, y}) == CellState::Free;
            occupied += fine.state({x, y}) == CellState::Occupied;
          }
        const CellState want = occupied > 0 ? CellState::Occupied
                                            : (2 * free >= cells ? CellState::Free : CellState::Unknown);
        EXPECT_EQ(coarse.state({cx, cy}), want) << factor << " at " << cx << ", " << cy;
      }
    }
    EXPECT_TRUE(coarse.same_states(coarsen(fine, factor))) << factor;
  }
}

TEST(Resample, TheSamePlaceInMetresHoldsTheSameThing) {
  const OccupancyGrid g = scanned_room(0.05);
  // Finer (each cell split in two), a little coarser than 0.05 m (stata's 0.0504 m), 0.03 m and
  // 0.07 m (no whole ratio): the extent is kept, and a cell's state is the state at its centre
  // wherever the old map is the same all around it.
  for (double r : {0.025, 0.0504, 0.03, 0.07}) {
    const OccupancyGrid out = resample(g, r);
    EXPECT_DOUBLE_EQ(out.resolution(), r);
    EXPECT_EQ(out.geometry().origin(), g.geometry().origin());
    EXPECT_NEAR(out.width() * r, g.geometry().width_m(), r) << r;
    EXPECT_GE(out.width() * r, g.geometry().width_m() - 1e-9) << r;
    EXPECT_NEAR(out.height() * r, g.geometry().height_m(), r) << r;
    int checked = 0, same = 0;
    for (int y = 0; y < out.height(); ++y) {
      for (int x = 0; x < out.width(); ++x) {
        const Eigen::Vector2d p = out.geometry().cell_center({x, y});
        const auto c = g.geometry().world_to_cell(p);
        if (!c) continue;
        const CellState s = g.state(*c);
        bool uniform = true;  // the old cells within a new cell and a half of p: all one state
        for (int dy = -2; dy <= 2 && uniform; ++dy)
          for (int dx = -2; dx <= 2 && uniform; ++dx) uniform = g.state(*c + Cell{dx, dy}) == s;
        if (!uniform) continue;
        ++checked;
        same += out.state({x, y}) == s;
      }
    }
    EXPECT_GT(checked, out.width() * out.height() / 4) << r;
    EXPECT_EQ(same, checked) << r;
    // Walls stay walls, and none is made up: every old wall cell's centre lies in a new wall cell,
    // and every new wall cell lies within an old cell of an old wall.
    for (int y = 0; y < g.height(); ++y) {
      for (int x = 0; x < g.width(); ++x) {
        if (g.state({x, y}) != CellState::Occupied) continue;
        const auto c = out.geometry().world_to_cell(g.geometry().cell_center({x, y}));
        ASSERT_TRUE(c);
        EXPECT_EQ(out.state(*c), CellState::Occupied) << r << " at " << x << ", " << y;
      }
    }
    for (int y = 0; y < out.height(); ++y) {
      for (int x = 0; x < out.width(); ++x) {
        if (out.state({x, y}) != CellState::Occupied) continue;
        const Eigen::Vector2d p = out.geometry().cell_center({x, y});
        bool near = false;
        for (double dy : {-1.0, 0.0, 1.0})
          for (double dx : {-1.0, 0.0, 1.0}) {
            const auto c = g.geometry().world_to_cell(p + 0.5 * r * Eigen::Vector2d(dx, dy));
            near = near || (c && g.state(*c) == CellState::Occupied);
          }
        EXPECT_TRUE(near) << r << " at " << x << ", " << y;
      }
    }
  }
}

TEST(Resample, ThereAndBackAgainLosesNoWall) {
  const OccupancyGrid g = scanned_room(0.05);
  const OccupancyGrid back = resample(resample(g, 0.025), 0.05);
  EXPECT_TRUE(back.same_states(g));
}

TEST(Pool, InPlaceItIsResampleAndAPlacementMovesTheCells) {
  const OccupancyGrid g = scanned_room(0.05);
  const OccupancyGrid coarse = resample(g, 0.1);
  const OccupancyGrid same = pool(g, 0.1, core::Transform2::identity(), coarse.width(), coarse.height(),
                                  g.geometry().origin());
  EXPECT_TRUE(same.same_states(coarse));
  // Placed one cell right and two up: cell (x, y) of `coarse` is cell (x + 1, y + 2) of the new grid.
  const OccupancyGrid moved = pool(g, 0.1, core::Transform2(1.0, 2.0, 0.0), coarse.width() + 1, coarse.height() + 2);
  for (int y = 0; y < coarse.height(); ++y)
    for (int x = 0; x < coarse.width(); ++x) ASSERT_EQ(moved.state({x + 1, y + 2}), coarse.state({x, y})) << x << ", " << y;
  EXPECT_EQ(moved.state({0, 0}), CellState::Unknown);
  // Turned a quarter about the origin into a grid wide enough: the walls are still there, turned.
  const OccupancyGrid turned = pool(g, 0.1, core::Transform2(coarse.height() - 1.0, 0.0, M_PI / 2), coarse.height(), coarse.width());
  EXPECT_EQ(turned.count(CellState::Occupied), coarse.count(CellState::Occupied));
  EXPECT_EQ(turned.state({coarse.height() - 1 - 10, 20}), coarse.state({20, 10}));
  // Cells finer than the grid's would leave holes between its cells: refused.
  EXPECT_THROW(pool(g, 0.025, core::Transform2::identity(), 10, 10), Error);
}

TEST(Resample, ANonPositiveResolutionIsRefused) {
  const OccupancyGrid g = scanned_room(0.05);
  EXPECT_THROW(resample(g, 0.0), Error);
  EXPECT_THROW(resample(g, -0.05), Error);
  EXPECT_THROW(resample(g, std::nan("")), Error);
}

TEST(CropToKnown, KeepsTheKnownCellsAndTheMarginAtTheirPlaceInTheWorld) {
  // A turned origin: the cut's origin must move along the grid's own axes.
  OccupancyGrid g(GridGeometry(0.1, 100, 80, core::Pose2(-2.0, 3.0, 0.5)));
  g.set_state({30, 20}, CellState::Free);
  g.set_state({60, 25}, CellState::Occupied);
  g.set_state({45, 50}, CellState::Free);
  g.set_state({97, 50}, CellState::Free);  // 2 cells from the right edge: the margin stops there
  const OccupancyGrid cut = crop_to_known(g, 5);
  EXPECT_EQ(cut.width(), 99 - 25 + 1);
  EXPECT_EQ(cut.height(), 55 - 15 + 1);
  EXPECT_EQ(cut.known_count(), g.known_count());
  for (const Cell c : {Cell{30, 20}, Cell{60, 25}, Cell{45, 50}, Cell{97, 50}}) {
    const Eigen::Vector2d world = g.geometry().cell_center(c);
    const auto in_cut = cut.geometry().world_to_cell(world);
    ASSERT_TRUE(in_cut.has_value());
    EXPECT_LT((cut.geometry().cell_center(*in_cut) - world).norm(), 1e-9);
    EXPECT_EQ(cut.state(*in_cut), g.state(c));
  }
  // Nothing known: nothing to cut to.
  const OccupancyGrid unknown(GridGeometry(0.1, 20, 10));
  EXPECT_EQ(crop_to_known(unknown, 5).geometry(), unknown.geometry());
}

}  // namespace
}  // namespace fleetmap::mapping
