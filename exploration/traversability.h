#pragma once
// Where a robot fits, and where its centre may go on a map it has built.
#include <cstdint>
#include <vector>

#include "mapping/occupancy_grid.h"

namespace fleetmap::exploration {

struct TraversabilityOptions {
  double robot_radius_m = 0.2;
  // Extra clearance beyond the radius, kept where the map allows: a robot is not always at a cell
  // centre. A place with less (but more than the radius) is still passable, at a higher cost.
  double safety_margin_m = 0.05;
  // A robot's map shows a wall face up to a cell nearer than it is: a range reading that falls short
  // by its noise marks the free cell in front of the face, half the time. Whether a robot fits on
  // its map is tested with the radius less one cell, but no more than this, so that a doorway a
  // little wider than the robot is not closed by that (on real floor plans at 0.05 m per cell),
  // while on coarse cells robots do not plan through places where they barely fit and stall there.
  // Clear cells keep the whole radius and margin.
  double wall_tolerance_m = 0.05;
};

// Where a robot of radius `radius_m` fits: the cells whose centre lies farther than the radius from
// every blocking cell (the nearest point of its square, as World::disc_free measures a move) and
// from the grid's outside. `blocking` has one flag per cell, row-major. This is the one notion of
// "fits" behind both the explorer's passable cells (blocking: its map's occupied cells) and the
// coverage metric's reachable poses (blocking: every cell of the true map that is not free).
std::vector<std::uint8_t> fitting_cells(const core::GridGeometry& geometry, const std::vector<std::uint8_t>& blocking,
                                        double radius_m);

// How a robot's centre may use a cell of its own map.
enum class Passage : std::uint8_t {
  Blocked = 0,  // not known free, or the robot does not fit among the occupied cells
  Fits = 1,     // known free and the robot fits, but unknown cells or walls lie within radius + margin
  Clear = 2,    // known free with radius + margin of known free space around it (traversable_cells)
};

// Per cell, a Passage value. Waves pass Fits and Clear cells and prefer Clear ones: unknown space
// next to a path is often more wall, yet a doorway seen at a slant, or the spokes of a sparse scan,
// can only be entered through cells whose surroundings are not all seen yet.
std::vector<std::uint8_t> passage_cells(const mapping::OccupancyGrid& map, const TraversabilityOptions& options);

// Known-free cells whose centre is farther than radius + margin from the centre of every cell that is
// not known free (an OpenCV distance transform): the Clear cells of passage_cells.
std::vector<std::uint8_t> traversable_cells(const mapping::OccupancyGrid& map, const TraversabilityOptions& options);

// True when every cell within radius + margin of the cell's centre is known free (the local form of
// traversable_cells).
bool cell_clear(const mapping::OccupancyGrid& map, const core::Cell& c, const TraversabilityOptions& options);
// True when the cell is known free and the robot fits there among the occupied cells (the local
// form of a Fits-or-better cell of passage_cells: used to see whether a planned path became blocked).
bool cell_fits(const mapping::OccupancyGrid& map, const core::Cell& c, const TraversabilityOptions& options);

}  // namespace fleetmap::exploration
