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

struct FrontierOptions {
  int min_region_cells = 3;  // smaller regions are sensor noise, not worth a trip
  // Unknown space narrower than this is not space to explore (the inside of a wall, a rack or a
  // pillar seen through a gap that a grazing beam left in its outline): a frontier must border
  // never-observed cells that survive a morphological opening by a square of this width.
  double min_unknown_width_m = 0.5;
};

// Frontier cells of a window of the map: free cells with a 4-neighbour in never-observed space at
// least min_unknown_width_m wide. Cells that were observed but are undecided (conflicting evidence,
// e.g. noisy hits on a wall face) are not unexplored: no robot could resolve them by driving there.
// Cells outside the map are not space to explore. The window gives the same answers as the whole map.
class FrontierMask {
 public:
  FrontierMask(const mapping::OccupancyGrid& map, const FrontierOptions& options);
  // The window [lo, hi) of cells, clipped to the map.
  FrontierMask(const mapping::OccupancyGrid& map, const FrontierOptions& options, const Cell& lo, const Cell& hi);
  bool operator()(const Cell& c) const;  // false outside the window
  const Cell& lo() const { return lo_; }
  const Cell& hi() const { return hi_; }

 private:
  Cell lo_, hi_;
  std::vector<std::uint8_t> frontier_;  // (hi - lo) cells, row-major from lo
};

bool is_frontier(const mapping::OccupancyGrid& map, const Cell& c, const FrontierOptions& options = {});

struct FrontierRegion {
  std::vector<Cell> cells;
  Eigen::Vector2d centroid_m = Eigen::Vector2d::Zero();  // mean of the cell centres, metres
  int size() const { return int(cells.size()); }
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
int frontier_cells_near(const mapping::OccupancyGrid& map, const Cell& c, double radius_m,
                        const FrontierOptions& options = {});

}  // namespace fleetmap::exploration
