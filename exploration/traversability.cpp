#include "exploration/traversability.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace fleetmap::exploration {

using mapping::CellState;

namespace {

// Squared distance, in cells, from a cell's centre to the square of the cell (dx, dy) cells away.
double square_distance2(int dx, int dy) {
  const double ex = std::max(std::abs(dx) - 0.5, 0.0), ey = std::max(std::abs(dy) - 0.5, 0.0);
  return ex * ex + ey * ey;
}

// Distance transform of a mask (non-zero: open) with a ring of closed cells around it: beyond the
// grid's edge is no place for a robot. Distances in cells between centres, exact (Felzenszwalb).
cv::Mat distance_to_closed(int w, int h, const auto& open) {
  cv::Mat mask(h + 2, w + 2, CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < h; ++y) {
    auto* row = mask.ptr<std::uint8_t>(y + 1);
    for (int x = 0; x < w; ++x) row[x + 1] = open(y * w + x) ? 255 : 0;
  }
  cv::Mat dist;
  cv::distanceTransform(mask, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  return dist;
}

}  // namespace

std::vector<std::uint8_t> fitting_cells(const core::GridGeometry& geometry, std::span<const std::uint8_t> blocking,
                                        double radius_m) {
  const int w = geometry.width(), h = geometry.height();
  if (blocking.size() != std::size_t(geometry.cell_count())) throw Error("fitting_cells: one flag per cell expected");
  std::vector<std::uint8_t> out(blocking.size(), 0);
  if (w == 0 || h == 0) return out;
  const double rho = radius_m / geometry.resolution();
  const cv::Mat dist = distance_to_closed(w, h, [&](int i) { return blocking[std::size_t(i)] == 0; });
  const int reach = int(std::ceil(rho)) + 1;
  const auto closed = [&](int x, int y) { return x < 0 || y < 0 || x >= w || y >= h || blocking[std::size_t(y * w + x)] != 0; };
  for (int y = 0; y < h; ++y) {
    const float* d = dist.ptr<float>(y + 1);
    for (int x = 0; x < w; ++x) {
      if (closed(x, y)) continue;
      // The nearest blocking centre is dc away; its square is between dc - sqrt(1/2) and dc - 1/2 away,
      // and no other square is nearer than dc - sqrt(1/2). Only the band in between needs a look.
      const double dc = d[x + 1];
      if (dc - 0.5 < rho - 1e-4) continue;
      if (dc - 0.7072 > rho) {
        out[std::size_t(y * w + x)] = 1;
        continue;
      }
      bool fits = true;
      for (int dy = -reach; dy <= reach && fits; ++dy)
        for (int dx = -reach; dx <= reach && fits; ++dx)
          if (square_distance2(dx, dy) <= rho * rho && closed(x + dx, y + dy)) fits = false;
      out[std::size_t(y * w + x)] = fits;
    }
  }
  return out;
}

std::vector<std::uint8_t> traversable_cells(const mapping::OccupancyGrid& map, const TraversabilityOptions& options) {
  const int w = map.width(), h = map.height();
  std::vector<std::uint8_t> out(std::size_t(w) * std::size_t(h), 0);
  if (w == 0 || h == 0) return out;
  // 0 at cells that are not known free. Rows are in grid order (row 0 at the bottom); the transform
  // does not care.
  const cv::Mat dist = distance_to_closed(w, h, [&](int i) { return map.state_at(i) == CellState::Free; });
  const double need_cells = (options.robot_radius_m + options.safety_margin_m) / map.resolution();
  for (int y = 0; y < h; ++y) {
    const float* d = dist.ptr<float>(y + 1);
    for (int x = 0; x < w; ++x) out[std::size_t(y * w + x)] = d[x + 1] > need_cells;
  }
  return out;
}

std::vector<std::uint8_t> passage_cells(const mapping::OccupancyGrid& map, const TraversabilityOptions& options) {
  const std::size_t n = std::size_t(map.geometry().cell_count());
  std::vector<std::uint8_t> occupied(n);
  for (std::size_t i = 0; i < n; ++i) occupied[i] = map.state_at(int(i)) == CellState::Occupied;
  std::vector<std::uint8_t> out = fitting_cells(map.geometry(), occupied, options.robot_radius_m);
  const std::vector<std::uint8_t> clear = traversable_cells(map, options);
  for (std::size_t i = 0; i < n; ++i) {
    if (!out[i] || map.state_at(int(i)) != CellState::Free) out[i] = std::uint8_t(Passage::Blocked);
    else out[i] = std::uint8_t(clear[i] ? Passage::Clear : Passage::Fits);
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

bool cell_fits(const mapping::OccupancyGrid& map, const core::Cell& c, const TraversabilityOptions& options) {
  if (map.state(c) != CellState::Free) return false;
  const double rho = options.robot_radius_m / map.resolution();
  const int reach = int(std::ceil(rho)) + 1;
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      if (square_distance2(dx, dy) > rho * rho) continue;
      const core::Cell n{c.x + dx, c.y + dy};
      if (!map.contains(n) || map.state(n) == CellState::Occupied) return false;
    }
  }
  return true;
}

}  // namespace fleetmap::exploration
