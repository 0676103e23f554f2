#include "exploration/traversability.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace fleetmap::exploration {

using mapping::CellState;

std::vector<std::uint8_t> traversable_cells(const mapping::OccupancyGrid& map, const TraversabilityOptions& options) {
  const int w = map.width(), h = map.height();
  std::vector<std::uint8_t> out(std::size_t(w) * std::size_t(h), 0);
  if (w == 0 || h == 0) return out;
  // Distance transform input: 0 at cells that are not known free. Rows are in grid order (row 0 at
  // the bottom); the transform does not care. A ring of zeros around the map: beyond the map's
  // edge is no place for a robot either.
  cv::Mat not_occupied(h + 2, w + 2, CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < h; ++y) {
    auto* row = not_occupied.ptr<std::uint8_t>(y + 1);
    for (int x = 0; x < w; ++x) row[x + 1] = map.state_at(y * w + x) != CellState::Free ? 0 : 255;
  }
  const double need_cells = (options.robot_radius_m + options.safety_margin_m) / map.resolution();
  cv::Mat dist;
  cv::distanceTransform(not_occupied, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  for (int y = 0; y < h; ++y) {
    const float* d = dist.ptr<float>(y + 1);
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      out[std::size_t(i)] = map.state_at(i) == CellState::Free && d[x + 1] > need_cells;
    }
  }
  return out;
}

bool cell_clear(const mapping::OccupancyGrid& map, const core::Cell& c, const TraversabilityOptions& options) {
  const double need_cells = (options.robot_radius_m + options.safety_margin_m) / map.resolution();
  const int r = int(std::ceil(need_cells));
  const double need2 = need_cells * need_cells;
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      if (double(dx * dx + dy * dy) > need2) continue;
      if (map.state({c.x + dx, c.y + dy}) != CellState::Free) return false;
    }
  }
  return true;
}

}  // namespace fleetmap::exploration
