#include "planning/free_space.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <string>

#include "core/error.h"
#include "mapping/distance_field.h"
#include "mapping/grid_traversal.h"

namespace fleetmap::planning {

FreeSpace::FreeSpace(const mapping::OccupancyGrid& grid, const FreeSpaceOptions& options)
    : geometry_(grid.geometry()), options_(options) {
  if (!std::isfinite(options.robot_radius_m) || options.robot_radius_m < 0.0) {
    throw InputError("robot radius must be a non-negative number of metres, got " +
                     std::to_string(options.robot_radius_m));
  }
  axis_aligned_ = geometry_.origin().theta == 0.0;
  const int w = geometry_.width(), h = geometry_.height();
  const auto n = static_cast<std::size_t>(geometry_.cell_count());
  state_.assign(n, 0);
  obstacle_.assign(n, 0);
  clearance_.assign(n, 0.0f);
  valid_.assign(n, 0);
  region_.assign(n, 0);
  if (n == 0) return;

  // Where the robot's centre may not be; outside the map counts as an obstacle.
  const bool unknown_blocks = options_.unknown == UnknownCells::Obstacle;
  for (int i = 0; i < int(n); ++i) {
    const mapping::CellState s = grid.state_at(i);
    const bool blocked = s == mapping::CellState::Occupied || (unknown_blocks && s == mapping::CellState::Unknown);
    state_[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(s);
    obstacle_[static_cast<std::size_t>(i)] = blocked ? 1 : 0;
  }
  const std::vector<float> distance = mapping::distance_to_blocked(w, h, obstacle_);

  cv::Mat valid_mask(h, w, CV_8UC1, cv::Scalar(0));
  const double res = geometry_.resolution();
  for (int y = 0; y < h; ++y) {
    auto* v = valid_mask.ptr<std::uint8_t>(y);
    for (int x = 0; x < w; ++x) {
      const auto i = static_cast<std::size_t>(geometry_.index({x, y}));
      const double clearance_m = double(distance[i]) * res;
      clearance_[i] = static_cast<float>(clearance_m);
      // A clearance equal to the radius (up to rounding) does not exceed it.
      if (clearance_m > options_.robot_radius_m + 1e-9) {
        valid_[i] = 1;
        v[x] = 1;
        ++valid_count_;
      }
    }
  }
  cv::Mat labels;
  cv::connectedComponents(valid_mask, labels, 4, CV_32S);
  for (int y = 0; y < h; ++y) {
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < w; ++x) region_[static_cast<std::size_t>(geometry_.index({x, y}))] = l[x];
  }
}

std::optional<Cell> FreeSpace::locate(const Eigen::Vector2d& p) const {
  if (!axis_aligned_) return geometry_.world_to_cell(p);
  // The same arithmetic as world_to_cell for a zero rotation, so both agree on every point.
  const double res = geometry_.resolution();
  const double gx = (p.x() - geometry_.origin().x) / res, gy = (p.y() - geometry_.origin().y) / res;
  if (!(gx >= 0.0 && gy >= 0.0 && gx < geometry_.width() && gy < geometry_.height())) return std::nullopt;
  const Cell c{static_cast<int>(std::floor(gx)), static_cast<int>(std::floor(gy))};
  if (!contains(c)) return std::nullopt;
  return c;
}

bool FreeSpace::is_obstacle(const Cell& c) const { return !contains(c) || obstacle_[index(c)] != 0; }

double FreeSpace::clearance(const Cell& c) const { return contains(c) ? double(clearance_[index(c)]) : 0.0; }

double FreeSpace::clearance_at(const Eigen::Vector2d& p) const {
  const auto c = locate(p);
  return c ? clearance(*c) : 0.0;
}

bool FreeSpace::valid(const Eigen::Vector2d& p) const {
  const auto c = locate(p);
  return c && valid(*c);
}

std::optional<double> FreeSpace::first_invalid_distance(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const {
  if (!valid(a)) return 0.0;
  std::optional<double> hit;
  mapping::traverse_segment(geometry_, a, b, [&](const Cell& c, double t_enter) {
    if (valid(c)) return true;
    hit = t_enter;
    return false;
  });
  if (hit || valid(b)) return hit;
  // Every crossed cell inside the grid is valid but `b` lies outside: the segment leaves the map
  // (possible only for radii under one cell). Find the exit by bisection.
  double lo = 0.0, hi = (b - a).norm();
  const Eigen::Vector2d dir = (b - a) / hi;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (locate(a + mid * dir) ? lo : hi) = mid;
  }
  return hi;
}

bool FreeSpace::segment_valid(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const {
  if (!valid(a) || !valid(b)) return false;
  return mapping::traverse_segment(geometry_, a, b, [&](const Cell& c, double) { return valid(c); });
}

bool FreeSpace::path_valid(const std::vector<Eigen::Vector2d>& path) const {
  if (path.empty()) return false;
  if (path.size() == 1) return valid(path.front());
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    if (!segment_valid(path[i], path[i + 1])) return false;
  }
  return true;
}

bool FreeSpace::connected(const Cell& a, const Cell& b) const {
  const int ra = region(a);
  return ra != 0 && ra == region(b);
}

}  // namespace fleetmap::planning
