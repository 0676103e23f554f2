#include "mapping/state_mask.h"

#include <algorithm>
#include <cstdint>

namespace fleetmap::mapping {

cv::Mat state_mask(const OccupancyGrid& grid, std::initializer_list<CellState> states) {
  if (grid.width() <= 0 || grid.height() <= 0) return {};
  const auto wanted = [&](CellState s) { return std::find(states.begin(), states.end(), s) != states.end(); };
  // Locals: the stores below might alias grid's members, which would keep the loop from vectorizing.
  const bool occupied = wanted(CellState::Occupied), free = wanted(CellState::Free), unknown = wanted(CellState::Unknown);
  const float occupied_above = grid.occupied_log_odds(), free_below = grid.free_log_odds();
  const int width = grid.width();
  cv::Mat mask(grid.height(), width, CV_8U);
  for (int y = 0; y < grid.height(); ++y) {
    auto* m = mask.ptr<std::uint8_t>(y);
    const float* l = grid.log_odds_data().data() + std::size_t(y) * std::size_t(width);
    for (int x = 0; x < width; ++x) {
      const bool is_occupied = l[x] > occupied_above, is_free = l[x] < free_below;
      const bool in = (is_occupied & occupied) | (is_free & free) | (!(is_occupied | is_free) & unknown);
      m[x] = in ? 255 : 0;
    }
  }
  return mask;
}

}  // namespace fleetmap::mapping
