#pragma once
// The unknown area each frontier target would reveal: the never-observed cells behind it, split
// among the targets (each cell counted for the target nearest to it through never-observed space,
// and only within a given reach, e.g. the sensor range). The information gain that Zhou et al.
// 2023 (RACER) balance among the robots' tours, here per frontier target.
#include <vector>

#include "exploration/frontiers.h"
#include "mapping/occupancy_grid.h"

namespace fleetmap::exploration {

// Per target, square metres of never-observed cells reached from its `unknown` cell by a
// multi-source 8-connected flood through never-observed cells, no farther than `reach_m` from it
// (straight line), each cell counted once, for the target whose flood arrives first (in steps; a
// tie goes to the earlier target). A target whose unknown cell has been observed gets 0.
std::vector<double> unknown_area_behind(const mapping::OccupancyGrid& map, const std::vector<Target>& targets,
                                        double reach_m);

}  // namespace fleetmap::exploration
