#pragma once
// Hand-made grids and an independent check that a path keeps clear of inflated obstacles.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "mapping/occupancy_grid.h"
#include "planning/planner.h"

namespace fleetmap::planning::testing {

// A grid drawn in text, top line = top row (highest y): '#' occupied, '.' free, '?' unknown.
inline mapping::OccupancyGrid grid_from_ascii(const std::vector<std::string>& rows, double resolution = 0.1) {
  const int h = static_cast<int>(rows.size()), w = static_cast<int>(rows.front().size());
  mapping::OccupancyGrid grid(core::GridGeometry(resolution, w, h));
  for (int r = 0; r < h; ++r) {
    for (int x = 0; x < w; ++x) {
      const char ch = rows[static_cast<std::size_t>(r)][static_cast<std::size_t>(x)];
      const auto state = ch == '#' ? mapping::CellState::Occupied
                                   : (ch == '?' ? mapping::CellState::Unknown : mapping::CellState::Free);
      grid.set_state({x, h - 1 - r}, state);
    }
  }
  return grid;
}

// A w x h free room of `resolution` with a one-cell wall around it.
inline mapping::OccupancyGrid walled_room(int w, int h, double resolution = 0.1) {
  mapping::OccupancyGrid grid(core::GridGeometry(resolution, w, h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      grid.set_state({x, y}, (x == 0 || y == 0 || x == w - 1 || y == h - 1) ? mapping::CellState::Occupied
                                                                           : mapping::CellState::Free);
  return grid;
}

// Brute force, without the distance transform: may the robot's centre be in cell `c`? No obstacle
// cell centre (Occupied, Unknown when `unknown_blocks`, or outside the grid) lies within `radius`
// of the cell's centre.
inline bool clear_by_brute_force(const mapping::OccupancyGrid& grid, const core::Cell& c, double radius,
                                 bool unknown_blocks = true) {
  if (!grid.contains(c)) return false;
  const double res = grid.resolution();
  const int reach = static_cast<int>(std::ceil(radius / res)) + 1;
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      const core::Cell o{c.x + dx, c.y + dy};
      const auto s = grid.state(o);
      const bool obstacle = !grid.contains(o) || s == mapping::CellState::Occupied ||
                            (unknown_blocks && s == mapping::CellState::Unknown);
      if (obstacle && std::hypot(dx, dy) * res <= radius) return false;
    }
  }
  return true;
}

// Every point of every segment, sampled every 1/50 of a cell, lies in a cell clear of inflated
// obstacles (checked by brute force); the ends are the query's.
inline ::testing::AssertionResult path_clear_of_obstacles(const mapping::OccupancyGrid& grid, const Path& path,
                                                          double radius, bool unknown_blocks = true) {
  if (path.size() < 2) return ::testing::AssertionFailure() << "path has " << path.size() << " waypoints";
  const double step = grid.resolution() / 50.0;
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    const Eigen::Vector2d a = path[i], b = path[i + 1];
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int k = 0; k <= n; ++k) {
      const Eigen::Vector2d p = a + (b - a) * (double(k) / n);
      const auto cell = grid.geometry().world_to_cell(p);
      if (!cell || !clear_by_brute_force(grid, *cell, radius, unknown_blocks)) {
        return ::testing::AssertionFailure() << "segment " << i << " (" << a.transpose() << ") -> (" << b.transpose()
                                             << ") passes (" << p.transpose() << "), within " << radius
                                             << " m of an obstacle";
      }
    }
  }
  return ::testing::AssertionSuccess();
}

}  // namespace fleetmap::planning::testing
