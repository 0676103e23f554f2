#pragma once
// Ray casting on a ground-truth grid: what an ideal range sensor would measure.
#include <Eigen/Core>
#include <optional>

#include "mapping/occupancy_grid.h"

namespace fleetmap::mapping {

struct RayCastOptions {
  // Ground-truth maps may hold unknown cells (grey in a map image); by default they stop rays
  // like walls, since nothing is known to be passable there.
  bool unknown_blocks = true;
};

// Distance in metres from `from` along `angle` (radians, world frame) to the boundary of the first
// blocking cell, or nullopt when nothing blocks within `max_range`. A ray that starts inside a
// blocking cell measures 0. Leaving the grid counts as no return.
std::optional<double> cast_ray(const OccupancyGrid& grid, const Eigen::Vector2d& from, double angle,
                               double max_range, const RayCastOptions& options = {});

// True when no blocking cell lies on the segment between the two points.
bool line_of_sight(const OccupancyGrid& grid, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                   const RayCastOptions& options = {});

}  // namespace fleetmap::mapping
