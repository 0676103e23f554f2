#include "exploration/traversability.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "mapping/distance_field.h"

namespace fleetmap::exploration {

using mapping::CellState;

namespace {

// Squared distance, in cells, from a cell's centre to the square of the cell (dx, dy) cells away.
double square_distance2(int dx, int dy) {
  const double ex = std::max(std::abs(dx) - 0.5, 0.0), ey = std::max(std::abs(dy) - 0.5, 0.0);
  return ex * ex + ey * ey;
}

// The radius tested against a robot's own map (see wall_tolerance_m).
double map_radius(const mapping::OccupancyGrid& map, const TraversabilityOptions& options) {
  return std::max(0.0, options.robot_radius_m - std::min(options.wall_tolerance_m, map.resolution()));
}

}  // namespace

std::vector<std::uint8_t> fitting_cells(const core::GridGeometry& geometry, const std::vector<std::uint8_t>& blocking,
                                        double radius_m) {
  const int w = geometry.width(), h = geometry.height();
  if (blocking.size() != std::size_t(geometry.cell_count())) throw Error("fitting_cells: one flag per cell expected");
  std::vector<std::uint8_t> out(blocking.size(), 0);
  if (w == 0 || h == 0) return out;
  const double rho = radius_m / geometry.resolution();
  const std::vector<float> dist = mapping::distance_to_blocked(w, h, blocking);
  const int reach = int(std::ceil(rho)) + 1;
  const auto closed = [&](int x, int y) { return x < 0 || y < 0 || x >= w || y >= h || blocking[std::size_t(y * w + x)] != 0; };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (closed(x, y)) continue;
      // The nearest blocking centre is dc away; its square is between dc - sqrt(1/2) and dc - 1/2 away,
      // and no other square is nearer than dc - sqrt(1/2). Only the band in between needs a look.
      const double dc = dist[std::size_t(y * w + x)];
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
  std::vector<std::uint8_t> not_free(out.size());
  for (std::size_t i = 0; i < out.size(); ++i) not_free[i] = map.state_at(int(i)) != CellState::Free;
  const std::vector<float> dist = mapping::distance_to_blocked(w, h, not_free);
  const double need_cells = (options.robot_radius_m + options.safety_margin_m) / map.resolution();
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = dist[i] > need_cells;
  return out;
}

std::vector<std::uint8_t> passage_cells(const mapping::OccupancyGrid& map, const TraversabilityOptions& options) {
  const std::size_t n = std::size_t(map.geometry().cell_count());
  std::vector<std::uint8_t> occupied(n);
  for (std::size_t i = 0; i < n; ++i) occupied[i] = map.state_at(int(i)) == CellState::Occupied;
  std::vector<std::uint8_t> out = fitting_cells(map.geometry(), occupied, map_radius(map, options));
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
  const double rho = map_radius(map, options) / map.resolution();
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
