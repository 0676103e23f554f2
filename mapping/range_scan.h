#pragma once
// A range scan and putting it into a grid: written once, used by the simulator, the scan-matching
// and particle-filter localizers and the experiments.
#include <Eigen/Core>

#include <cmath>
#include <optional>
#include <vector>

#include "core/transform2.h"

namespace fleetmap::mapping {

struct RangeScan {
  std::vector<double> angles;                // rad, robot frame
  std::vector<std::optional<double>> ranges;  // nullopt: no return within max_range
  double max_range = 0.0;
};

// Calls ray(from, to, hit) for every beam of `scan` taken at `pose`: from the sensor to the return,
// or to the maximum range when there was none (hit false).
template <typename Ray>
void for_each_beam(const core::Pose2& pose, const RangeScan& scan, Ray&& ray) {
  for (std::size_t b = 0; b < scan.angles.size(); ++b) {
    const double a = pose.theta + scan.angles[b];
    const double range = scan.ranges[b].value_or(scan.max_range);
    const Eigen::Vector2d end = pose.position() + range * Eigen::Vector2d(std::cos(a), std::sin(a));
    ray(pose.position(), end, scan.ranges[b].has_value());
  }
}

// Integrates `scan` taken at `pose` into `grid` (anything with integrate_ray(from, to, hit)):
// the cells a beam crosses become more likely free, the cell of its return more likely occupied.
template <typename Grid>
void insert_scan(Grid& grid, const core::Pose2& pose, const RangeScan& scan) {
  for_each_beam(pose, scan, [&](const Eigen::Vector2d& from, const Eigen::Vector2d& to, bool hit) {
    grid.integrate_ray(from, to, hit);
  });
}

}  // namespace fleetmap::mapping
