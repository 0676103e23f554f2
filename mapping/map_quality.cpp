#include "mapping/map_quality.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "mapping/distance_field.h"

namespace fleetmap::mapping {

MapQuality map_quality(const OccupancyGrid& map, const OccupancyGrid& truth, const core::Transform2& map_to_truth,
                       const MapQualityOptions& options) {
  const core::GridGeometry& g = truth.geometry();
  std::vector<std::uint8_t> walls(std::size_t(g.cell_count()));
  for (int i = 0; i < g.cell_count(); ++i) walls[std::size_t(i)] = truth.state_at(i) == CellState::Occupied;
  const std::vector<float> wall_cells = distance_to_blocked(g.width(), g.height(), walls, false);
  const bool any_wall = std::find(walls.begin(), walls.end(), std::uint8_t(1)) != walls.end();
  const double tolerance = options.wall_tolerance_m >= 0.0 ? options.wall_tolerance_m : 2.0 * g.resolution();

  MapQuality q;
  std::int64_t wrong = 0, misplaced = 0;
  double wall_sum = 0.0;
  for (int y = 0; y < map.height(); ++y) {
    for (int x = 0; x < map.width(); ++x) {
      const CellState state = map.state({x, y});
      if (state == CellState::Unknown) continue;
      const Eigen::Vector2d p = map_to_truth.apply(map.geometry().cell_center({x, y}));
      const auto cell = g.world_to_cell(p);
      const CellState true_state = cell ? truth.state(*cell) : CellState::Unknown;
      if (true_state != CellState::Unknown) {
        ++q.known_cells;
        wrong += true_state != state;
      }
      if (state != CellState::Occupied || !any_wall) continue;
      // Outside the truth: the distance from the nearest cell inside, plus the way there.
      core::Cell c = g.world_to_cell_unbounded(p);
      c.x = std::clamp(c.x, 0, g.width() - 1);
      c.y = std::clamp(c.y, 0, g.height() - 1);
      const double d = double(wall_cells[std::size_t(g.index(c))]) * g.resolution() +
                       (cell ? 0.0 : (p - g.cell_center(c)).norm());
      wall_sum += d;
      misplaced += d > tolerance;
      ++q.wall_cells;
    }
  }
  if (q.known_cells > 0) q.wrong_cell_share = double(wrong) / double(q.known_cells);
  if (q.wall_cells > 0) {
    q.mean_wall_distance_m = wall_sum / double(q.wall_cells);
    q.misplaced_wall_share = double(misplaced) / double(q.wall_cells);
  }
  return q;
}

}  // namespace fleetmap::mapping
