#pragma once
// Frontiers (Yamauchi 1997): known-free cells next to unknown cells, grouped into regions, and the
// targets robots drive to: each region split into pieces no wider than a sensor footprint, each
// with a reachable goal cell.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "mapping/occupancy_grid.h"

namespace fleetmap::exploration {

using core::Cell;

// A free cell with a never-observed 4-neighbour inside the map. Cells that were observed but are
// undecided (conflicting evidence, e.g. noisy hits on a wall face) are not frontiers: no robot could
// resolve them by driving there. Cells outside the map are not space to explore.
bool is_frontier(const mapping::OccupancyGrid& map, const Cell& c);

struct FrontierRegion {
  std::vector<Cell> cells;
  Eigen::Vector2d centroid_m = Eigen::Vector2d::Zero();  // mean of the cell centres, metres
  int size() const { return int(cells.size()); }
};

struct FrontierOptions {
  int min_region_cells = 3;  // smaller regions are sensor noise, not worth a trip
};

// Regions of 8-connected frontier cells, in scan order of their first cell.
std::vector<FrontierRegion> find_frontier_regions(const mapping::OccupancyGrid& map, const FrontierOptions& options = {});

struct TargetOptions {
  FrontierOptions frontiers;
  double piece_radius_m = 1.5;     // a region wider than this is split into several targets
  double approach_radius_m = 0.6;  // how far from its frontier cell a target's goal may lie
};

// A place to explore: a piece of a frontier region, and the traversable goal cell to drive to.
struct Target {
  Cell frontier;                   // the piece's representative frontier cell
  Cell goal;                       // traversable, near `frontier`
  Eigen::Vector2d goal_m = Eigen::Vector2d::Zero();
  int cells = 0;                   // frontier cells in the piece
  int region = 0;                  // index into the regions it came from
};

// Targets for every region; pieces whose frontier has no traversable cell within the approach
// radius are left out (no robot could stand there). `traversable` is traversable_cells(map, ...).
std::vector<Target> make_targets(const mapping::OccupancyGrid& map, const std::vector<std::uint8_t>& traversable,
                                 const TargetOptions& options);

// The number of frontier cells within `radius_m` of `c` (is the area around a target still open?).
int frontier_cells_near(const mapping::OccupancyGrid& map, const Cell& c, double radius_m);

}  // namespace fleetmap::exploration
