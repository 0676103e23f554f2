#include "merging/fusion.h"

#include <gtest/gtest.h>

#include "core/error.h"

#include "tests/merging/merging_test_support.h"

namespace fleetmap::merging {
namespace {

using testing::grid_from_text;

TEST(Fusion, AddsLogOddsCellByCell) {
  mapping::OccupancyGrid a(core::GridGeometry(0.05, 3, 1)), b(core::GridGeometry(0.05, 3, 1));
  a.set_log_odds({0, 0}, 0.8f);   // weakly occupied
  b.set_log_odds({0, 0}, 0.9f);   // weakly occupied: together 1.7
  a.set_log_odds({1, 0}, -1.0f);  // free ...
  b.set_log_odds({1, 0}, 1.2f);   // ... against occupied: 0.2, a conflict drifting to unknown
  a.set_log_odds({2, 0}, 3.0f);   // strong agreement is clamped at the bound
  b.set_log_odds({2, 0}, 3.0f);
  const FusedMap f = fuse_pair(a, b, core::Transform2::identity());
  ASSERT_EQ(f.grid.width(), 3);
  ASSERT_EQ(f.grid.height(), 1);
  EXPECT_EQ(f.offset, (core::Cell{0, 0}));
  EXPECT_FLOAT_EQ(f.grid.log_odds({0, 0}), 1.7f);
  EXPECT_FLOAT_EQ(f.grid.log_odds({1, 0}), 0.2f);
  EXPECT_FLOAT_EQ(f.grid.log_odds({2, 0}), a.max_log_odds());
  // Agreeing weak evidence became firm; the conflict shows.
  EXPECT_EQ(a.state({0, 0}), mapping::CellState::Occupied);
  EXPECT_GT(f.grid.log_odds({0, 0}), a.log_odds({0, 0}));
  EXPECT_EQ(f.conflict_cells, 1);
  EXPECT_EQ(f.conflicts[1], 1);
  EXPECT_EQ(f.sources[0], 3u);
}

TEST(Fusion, CoversBothMapsAndKeepsTheFirstFrame) {
  const auto a = grid_from_text({"#..", "..."});
  const auto b = grid_from_text({"..#", "..."});
  // b placed 2 cells left and 1 down of a.
  const FusedMap f = fuse_pair(a, b, core::Transform2(-2.0, -1.0, 0.0));
  EXPECT_EQ(f.offset, (core::Cell{2, 1}));
  EXPECT_EQ(f.grid.width(), 5);
  EXPECT_EQ(f.grid.height(), 3);
  // a's (0, 1) occupied is fused cell (2, 2); b's (2, 1) lands on a's (0, 0): fused (2, 1).
  EXPECT_EQ(f.grid.state({2, 2}), mapping::CellState::Occupied);
  EXPECT_EQ(f.grid.state({2, 1}), mapping::CellState::Occupied);
  EXPECT_EQ(f.sources[std::size_t(1 * 5 + 2)], 3u);  // both know fused (2, 1)
  EXPECT_EQ(f.sources[std::size_t(0 * 5 + 0)], 2u);  // only b knows fused (0, 0)
  EXPECT_EQ(f.sources[std::size_t(2 * 5 + 0)], 0u);  // nobody knows fused (0, 2)
  EXPECT_EQ(f.grid.state({0, 2}), mapping::CellState::Unknown);
  // The fused grid's world frame extends a's: a's cell (0, 0) is at the same place in the world.
  EXPECT_TRUE(f.grid.geometry().cell_center({2, 1}).isApprox(a.geometry().cell_center({0, 0})));
  // One conflict: b's occupied (2, 1) on a's free (0, 0).
  EXPECT_EQ(f.conflict_cells, 1);
}

TEST(Fusion, FuseIntoAddsWithinTheTarget) {
  auto target = grid_from_text({"  ", ".."});
  const auto source = grid_from_text({"##", "##"});
  fuse_into(target, source, core::Transform2(1.0, 0.0, 0.0));
  // Source's column 0 lands on target's column 1; column 1 falls outside.
  EXPECT_EQ(target.state({0, 1}), mapping::CellState::Unknown);
  EXPECT_EQ(target.state({1, 1}), mapping::CellState::Occupied);
  EXPECT_FLOAT_EQ(target.log_odds({1, 0}), target.min_log_odds() + target.max_log_odds());
  EXPECT_FLOAT_EQ(target.log_odds({0, 0}), target.min_log_odds());
}

TEST(Fusion, RejectsMismatchedInputs) {
  const auto a = grid_from_text({".."});
  EXPECT_THROW(fuse_grids({&a, &a}, {core::Transform2::identity()}), Error);
}

}  // namespace
}  // namespace fleetmap::merging
