#pragma once
// Maps of two resolutions: robots of one team mapping at different cell sizes (0.025, 0.05, 0.1 m).
#include "mapping/occupancy_grid.h"
#include "merging/merge.h"

namespace fleetmap::merging {

// Aligns b to a when their cells differ in size. Both are first seen through the coarser map's
// cells (mapping::resample) and aligned; a finer map pooled on a lattice of its own lies up to half
// a cell off the coarser map's cells, so a wall fills one cell in one map and two in the other and
// the cells beside walls disagree (the acceptance index of right answers falls to 0.90-0.95) and
// the walls fit less tightly. So when the answer is refused although its walls agree (wall
// agreement at least ConfidenceOptions::full_agreement), or because the cells disagree
// (Refusal::CellsDisagree), the finer map is pooled again through the coarser map's own cells where
// that answer places it (mapping::pool) and the pair aligned once more, as two maps of one
// resolution; that second answer is the result. Otherwise (merged, or refused for walls on the
// other map's free space) the first answer is. The result is between resample(a, r) and
// resample(b, r), r the coarser resolution (`transform` takes the cells of the one into the cells
// of the other, `quality` in the first's cells). Maps of one resolution: align_maps.
MergeResult align_across_resolutions(const mapping::OccupancyGrid& a, const mapping::OccupancyGrid& b,
                                     const MergeOptions& options = {});

// A placement between maps seen through cells of `from` metres turned into the same placement
// between them seen through cells of `to` metres (same origins: a cell's centre is (c + 1/2) cells
// from the origin corner).
core::Transform2 rescale_cells(const core::Transform2& t, double from, double to);

}  // namespace fleetmap::merging
