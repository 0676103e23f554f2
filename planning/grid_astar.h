#pragma once
// The exact baseline: A* (Hart, Nilsson & Raphael 1968) on the 8-connected grid of valid cells,
// and any-angle smoothing of its result by line-of-sight shortcuts.
#include <chrono>
#include <optional>
#include <vector>

#include "planning/free_space.h"
#include "planning/planner.h"

namespace fleetmap::planning {

struct GridPath {
  std::vector<Cell> cells;  // from the start cell to the goal cell, each a neighbour of the last
  double cost_m = 0.0;      // centre to centre: one resolution per side step, sqrt(2) per diagonal
};

struct GridSearch {
  enum class Outcome { Found, NoPath, Stopped } outcome = Outcome::NoPath;
  GridPath path;  // when Found
};

// A shortest path between two valid cells on the 8-connected grid of valid cells of `space`. A
// diagonal step needs both cells beside it valid, so the path never cuts a corner. With the
// octile-distance heuristic (consistent) the path is optimal. Stops (Outcome::Stopped) once
// `deadline` has passed, checked every few thousand expansions.
GridSearch astar_grid(const FreeSpace& space, const Cell& start, const Cell& goal,
                      std::optional<std::chrono::steady_clock::time_point> deadline = std::nullopt);

// The grid path as waypoints in metres: `start`, the centres of the inner cells, `goal`. Valid
// when `start` lies in the first cell and `goal` in the last.
Path grid_path_waypoints(const FreeSpace& space, const GridPath& grid_path, const Eigen::Vector2d& start,
                         const Eigen::Vector2d& goal);

// Any-angle smoothing by string pulling: from each kept waypoint, jump to the farthest later
// waypoint in line of sight (FreeSpace::segment_valid). Keeps the ends; never lengthens a path,
// and the result is valid when the input is.
Path smooth_any_angle(const FreeSpace& space, const Path& path);

}  // namespace fleetmap::planning
