#include "mapping/ray_cast.h"

#include <cmath>

#include "mapping/grid_traversal.h"

namespace fleetmap::mapping {

namespace {
bool blocks(const OccupancyGrid& grid, const Cell& c, const RayCastOptions& options) {
  const CellState s = grid.state(c);
  return s == CellState::Occupied || (options.unknown_blocks && s == CellState::Unknown);
}
}  // namespace

std::optional<double> cast_ray(const OccupancyGrid& grid, const Eigen::Vector2d& from, double angle,
                               double max_range, const RayCastOptions& options) {
  const Eigen::Vector2d to = from + max_range * Eigen::Vector2d(std::cos(angle), std::sin(angle));
  std::optional<double> hit;
  traverse_segment(grid.geometry(), from, to, [&](const Cell& c, double t_enter) {
    if (!blocks(grid, c, options)) return true;
    if (t_enter <= max_range) hit = t_enter;
    return false;
  });
  return hit;
}

bool line_of_sight(const OccupancyGrid& grid, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                   const RayCastOptions& options) {
  return traverse_segment(grid.geometry(), a, b,
                          [&](const Cell& c, double) { return !blocks(grid, c, options); });
}

}  // namespace fleetmap::mapping
