#pragma once
// Exact traversal of the cells a segment crosses (Amanatides & Woo 1987), the one line walker
// behind beam integration, sensor ray casting and line-of-sight tests.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/grid_geometry.h"

namespace fleetmap::mapping {

// Calls `visit(cell, t_enter)` for each cell of `geometry` that the segment from `from` to `to`
// (world metres) crosses, in order from `from`; `t_enter` is the distance in metres from `from`
// at which the segment enters the cell (0 for the first). Only cells inside the grid are visited:
// the segment is clipped to the grid first. `visit` returns false to stop.
// Returns false when stopped by `visit`, true otherwise.
template <typename Visit>
bool traverse_segment(const core::GridGeometry& geometry, const Eigen::Vector2d& from,
                      const Eigen::Vector2d& to, Visit&& visit) {
  const Eigen::Vector2d a = geometry.world_to_grid(from);
  const Eigen::Vector2d b = geometry.world_to_grid(to);
  const Eigen::Vector2d d = b - a;
  const double length_cells = d.norm();
  const double res = geometry.resolution();

  // Clip the parameter range [0, 1] to the grid box (Liang-Barsky).
  double t0 = 0.0, t1 = 1.0;
  const double lo[2] = {0.0, 0.0};
  const double hi[2] = {static_cast<double>(geometry.width()), static_cast<double>(geometry.height())};
  for (int k = 0; k < 2; ++k) {
    if (d[k] == 0.0) {
      if (a[k] < lo[k] || a[k] >= hi[k]) return true;
      continue;
    }
    double ta = (lo[k] - a[k]) / d[k], tb = (hi[k] - a[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 > t1) return true;

  const Eigen::Vector2d start = a + t0 * d;
  int x = std::clamp(static_cast<int>(std::floor(start.x())), 0, geometry.width() - 1);
  int y = std::clamp(static_cast<int>(std::floor(start.y())), 0, geometry.height() - 1);
  if (geometry.width() == 0 || geometry.height() == 0) return true;
  const int end_x = std::clamp(static_cast<int>(std::floor((a + t1 * d).x())), 0, geometry.width() - 1);
  const int end_y = std::clamp(static_cast<int>(std::floor((a + t1 * d).y())), 0, geometry.height() - 1);

  constexpr double kInf = std::numeric_limits<double>::infinity();
  const int step_x = d.x() > 0 ? 1 : (d.x() < 0 ? -1 : 0);
  const int step_y = d.y() > 0 ? 1 : (d.y() < 0 ? -1 : 0);
  // Parameter t (fraction of the segment) at which the next vertical / horizontal boundary is hit.
  double t_max_x = step_x > 0 ? (x + 1 - a.x()) / d.x() : (step_x < 0 ? (x - a.x()) / d.x() : kInf);
  double t_max_y = step_y > 0 ? (y + 1 - a.y()) / d.y() : (step_y < 0 ? (y - a.y()) / d.y() : kInf);
  const double t_delta_x = step_x != 0 ? 1.0 / std::abs(d.x()) : kInf;
  const double t_delta_y = step_y != 0 ? 1.0 / std::abs(d.y()) : kInf;

  double t_enter = t0;
  // The walk cannot take more steps than the Manhattan distance between its end cells.
  const int max_steps = std::abs(end_x - x) + std::abs(end_y - y);
  for (int i = 0; i <= max_steps; ++i) {
    if (!visit(core::Cell{x, y}, t_enter * length_cells * res)) return false;
    if (x == end_x && y == end_y) break;
    if (t_max_x < t_max_y) {
      t_enter = t_max_x;
      t_max_x += t_delta_x;
      x += step_x;
    } else {
      t_enter = t_max_y;
      t_max_y += t_delta_y;
      y += step_y;
    }
    if (x < 0 || y < 0 || x >= geometry.width() || y >= geometry.height() || t_enter > t1) break;
  }
  return true;
}

}  // namespace fleetmap::mapping
