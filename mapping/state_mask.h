#pragma once
// A grid's cells in given states as an image for OpenCV.
#include <initializer_list>
#include <opencv2/core.hpp>

#include "mapping/occupancy_grid.h"

namespace fleetmap::mapping {

// 255 where a cell's state (OccupancyGrid::state_at) is one of `states`, else 0: height() x width(),
// CV_8U (empty for an empty grid). Read from the log-odds in a loop the compiler vectorizes: merging
// reads a million cells per map this way, where state_at cell by cell cost a tenth of a merge.
cv::Mat state_mask(const OccupancyGrid& grid, std::initializer_list<CellState> states);

}  // namespace fleetmap::mapping
