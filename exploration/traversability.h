#pragma once
// Where a robot's centre may go on a map it has built.
#include <cstdint>
#include <vector>

#include "mapping/occupancy_grid.h"

namespace fleetmap::exploration {

struct TraversabilityOptions {
  double robot_radius_m = 0.2;
  // Extra clearance beyond the radius: a robot is not always at a cell centre.
  double safety_margin_m = 0.05;
};

// Known-free cells whose centre is farther than radius + margin from the centre of every cell that is
// not known free (an OpenCV distance transform): robots keep clear of walls and of unknown space
// alike, since unknown cells next to a wall are usually more wall.
std::vector<std::uint8_t> traversable_cells(const mapping::OccupancyGrid& map, const TraversabilityOptions& options);

// True when every cell within radius + margin of the cell's centre is known free (the local form of
// traversable_cells, used to see whether a planned path became blocked).
bool cell_clear(const mapping::OccupancyGrid& map, const core::Cell& c, const TraversabilityOptions& options);

}  // namespace fleetmap::exploration
