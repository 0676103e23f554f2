#pragma once
// How far a built map is from the true map: the share of wrongly labelled cells among those it
// knows, and how far its walls lie from the true walls. One measure for exploration runs and the
// papers' experiments.
#include <cstdint>

#include "core/transform2.h"
#include "mapping/occupancy_grid.h"

namespace fleetmap::mapping {

struct MapQuality {
  std::int64_t known_cells = 0;       // cells the map labels free or occupied, inside the truth
  double wrong_cell_share = 0.0;      // of those, the share the truth labels otherwise (free vs occupied)
  std::int64_t wall_cells = 0;        // the map's occupied cells
  double mean_wall_distance_m = 0.0;  // from each of them to the nearest true wall
  double misplaced_wall_share = 0.0;  // of them, the share farther than `wall_tolerance_m` from a true wall
};

struct MapQualityOptions {
  // A wall cell farther than this from every true wall is misplaced (default: two cells of the truth).
  double wall_tolerance_m = -1.0;
};

// Compares `map`, placed in the truth's world frame by `map_to_truth` (metres to metres), with
// `truth`, cell by cell at the map's cell centres. Map cells outside the truth count for the walls
// (at their distance to the nearest true wall inside) but not among the known cells.
MapQuality map_quality(const OccupancyGrid& map, const OccupancyGrid& truth,
                       const core::Transform2& map_to_truth = core::Transform2(), const MapQualityOptions& options = {});

}  // namespace fleetmap::mapping
