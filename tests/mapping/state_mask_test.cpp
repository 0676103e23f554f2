#include "mapping/state_mask.h"

#include <gtest/gtest.h>

namespace fleetmap::mapping {
namespace {

// Log-odds from below the clamp to above it, the state thresholds themselves among them (a cell
// exactly at a threshold is Unknown), on a grid whose width is no multiple of a vector register's.
OccupancyGrid grid_of_every_log_odds() {
  OccupancyGrid g(GridGeometry(0.05, 37, 5));
  const float values[] = {g.min_log_odds() - 1.0f, g.free_log_odds() - 1e-6f, g.free_log_odds(), 0.0f,
                          g.occupied_log_odds(), g.occupied_log_odds() + 1e-6f, g.max_log_odds() + 1.0f};
  int k = 0;
  for (int y = 0; y < g.height(); ++y) {
    for (int x = 0; x < g.width(); ++x) g.set_log_odds({x, y}, values[k++ % 7]);
  }
  return g;
}

TEST(StateMask, MarksTheCellsWhoseStateIsAsked) {
  const OccupancyGrid g = grid_of_every_log_odds();
  const cv::Mat occupied = state_mask(g, {CellState::Occupied}), free = state_mask(g, {CellState::Free});
  const cv::Mat unknown = state_mask(g, {CellState::Unknown}), known = state_mask(g, {CellState::Free, CellState::Occupied});
  const cv::Mat none = state_mask(g, {});
  ASSERT_EQ(occupied.size(), cv::Size(g.width(), g.height()));
  ASSERT_EQ(occupied.type(), CV_8U);
  int seen[3] = {0, 0, 0};
  for (int y = 0; y < g.height(); ++y) {
    for (int x = 0; x < g.width(); ++x) {
      const CellState s = g.state({x, y});
      ++seen[int(s)];
      EXPECT_EQ(occupied.at<std::uint8_t>(y, x), s == CellState::Occupied ? 255 : 0) << x << "," << y;
      EXPECT_EQ(free.at<std::uint8_t>(y, x), s == CellState::Free ? 255 : 0) << x << "," << y;
      EXPECT_EQ(unknown.at<std::uint8_t>(y, x), s == CellState::Unknown ? 255 : 0) << x << "," << y;
      EXPECT_EQ(known.at<std::uint8_t>(y, x), s != CellState::Unknown ? 255 : 0) << x << "," << y;
      EXPECT_EQ(none.at<std::uint8_t>(y, x), 0);
    }
  }
  // Every state occurs: 2 of 7 values are Free, 3 Unknown, 2 Occupied.
  EXPECT_GT(seen[int(CellState::Free)], 0);
  EXPECT_GT(seen[int(CellState::Unknown)], 0);
  EXPECT_GT(seen[int(CellState::Occupied)], 0);
}

TEST(StateMask, AnEmptyGridGivesAnEmptyImage) {
  EXPECT_TRUE(state_mask(OccupancyGrid(), {CellState::Occupied}).empty());
}

}  // namespace
}  // namespace fleetmap::mapping
