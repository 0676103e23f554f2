#pragma once
// Synthetic rooms and laser scans for the grid-SLAM and MCL tests, written independently of
// localization/ (scans come from mapping::cast_ray on the true grid, with Gaussian range noise).
#include <Eigen/Core>

#include <cmath>
#include <numbers>
#include <vector>

#include "core/random.h"
#include "localization/localizer.h"
#include "mapping/occupancy_grid.h"
#include "mapping/ray_cast.h"

namespace fleetmap::localization::testing {

// A 10 m x 7 m room at 0.05 m (origin at the lower-left corner) with an L-shaped notch in the
// upper-right corner and a 0.6 m square pillar: no symmetry maps it onto itself.
inline mapping::OccupancyGrid asymmetric_room(double resolution = 0.05) {
  const int w = int(std::lround(10.0 / resolution)), h = int(std::lround(7.0 / resolution));
  mapping::OccupancyGrid g(core::GridGeometry(resolution, w, h));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector2d p = g.geometry().cell_center({x, y});
      const bool border = p.x() < 0.2 || p.y() < 0.2 || p.x() > 9.8 || p.y() > 6.8;
      const bool notch = p.x() > 7.0 && p.y() > 4.5;
      const bool pillar = std::abs(p.x() - 3.0) < 0.3 && std::abs(p.y() - 2.5) < 0.3;
      const bool ledge = p.x() < 1.5 && std::abs(p.y() - 5.0) < 0.1;  // a short wall off the left side
      g.set_state({x, y}, border || notch || pillar || ledge ? mapping::CellState::Occupied : mapping::CellState::Free);
    }
  }
  return g;
}

// A 360-beam scan from `pose` on the true grid, range noise N(0, noise^2).
inline RangeScan scan_at(const mapping::OccupancyGrid& truth, const core::Pose2& pose, double noise,
                         core::Random& rng, int beams = 360, double max_range = 8.0) {
  RangeScan s;
  s.max_range = max_range;
  for (int b = 0; b < beams; ++b) {
    const double a = -std::numbers::pi + 2.0 * std::numbers::pi * b / beams;
    s.angles.push_back(a);
    auto r = mapping::cast_ray(truth, pose.position(), pose.theta + a, max_range);
    if (r) r = std::clamp(*r + rng.normal(0.0, noise), 0.0, max_range);
    s.ranges.push_back(r);
  }
  return s;
}

}  // namespace fleetmap::localization::testing
