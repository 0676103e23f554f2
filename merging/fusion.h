#pragma once
// Fusing aligned occupancy grids cell by cell in log-odds: evidence adds up (independent
// observations), so agreeing maps strengthen each other and a free-against-occupied conflict
// drifts toward unknown and shows, instead of one map silently winning (as a max would do).
#include <cstdint>
#include <vector>

#include "core/grid_geometry.h"
#include "core/transform2.h"
#include "mapping/occupancy_grid.h"

namespace fleetmap::merging {

// The union of several grids in the first one's frame.
struct FusedMap {
  mapping::OccupancyGrid grid;         // covers every input; same resolution as the first
  core::Cell offset;                   // the first input's cell (x, y) is grid cell (x + offset.x, y + offset.y)
  std::vector<std::uint32_t> sources;  // per grid cell: bit k set when input k (k < 32) knows the cell
  std::vector<int> inputs;             // bit k stands for this input (fuse_merged leaves unplaced ones out)
  std::vector<std::uint8_t> conflicts; // per grid cell: 1 when one input says free and another occupied
  std::int64_t conflict_cells = 0;
};

// Fuses `grids[k]` placed by `to_first[k]` (its cells into the first grid's cells; the first's is
// the identity). Each output cell takes, from every input, the input cell nearest to it and adds
// their log-odds, clamped to the first grid's bounds. Inputs need not share a size; they are
// taken to share a cell size. Throws fleetmap::Error when the sizes of the two vectors differ.
FusedMap fuse_grids(const std::vector<const mapping::OccupancyGrid*>& grids,
                    const std::vector<core::Transform2>& to_first);

// Two grids: b placed in a's frame by b_to_a.
FusedMap fuse_pair(const mapping::OccupancyGrid& a, const mapping::OccupancyGrid& b, const core::Transform2& b_to_a);

// Adds `source`'s evidence into `target` in place, within target's extent (the simulator's way:
// a robot keeps its own map's frame and size). A cell's log-odds become target + source, clamped.
// Fusing the same map twice counts its evidence twice: fuse what is new since the last meeting.
void fuse_into(mapping::OccupancyGrid& target, const mapping::OccupancyGrid& source,
               const core::Transform2& source_to_target);

}  // namespace fleetmap::merging
