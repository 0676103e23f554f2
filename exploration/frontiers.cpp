#include "exploration/frontiers.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace fleetmap::exploration {

using mapping::CellState;

bool is_frontier(const mapping::OccupancyGrid& map, const Cell& c) {
  if (!map.contains(c) || map.state(c) != CellState::Free) return false;
  const Cell n[4] = {{c.x + 1, c.y}, {c.x - 1, c.y}, {c.x, c.y + 1}, {c.x, c.y - 1}};
  for (const Cell& m : n) {
    if (map.contains(m) && !map.observed(m)) return true;
  }
  return false;
}

std::vector<FrontierRegion> find_frontier_regions(const mapping::OccupancyGrid& map, const FrontierOptions& options) {
  const int w = map.width(), h = map.height();
  std::vector<std::uint8_t> frontier(std::size_t(w) * std::size_t(h), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) frontier[std::size_t(y * w + x)] = is_frontier(map, {x, y});

  std::vector<FrontierRegion> regions;
  std::vector<int> stack;
  for (int i = 0; i < w * h; ++i) {
    if (frontier[std::size_t(i)] != 1) continue;
    FrontierRegion region;
    frontier[std::size_t(i)] = 2;
    stack.assign(1, i);
    while (!stack.empty()) {
      const int j = stack.back();
      stack.pop_back();
      const Cell c{j % w, j / w};
      region.cells.push_back(c);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = c.x + dx, ny = c.y + dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const int k = ny * w + nx;
          if (frontier[std::size_t(k)] == 1) {
            frontier[std::size_t(k)] = 2;
            stack.push_back(k);
          }
        }
    }
    if (region.size() < options.min_region_cells) continue;
    std::sort(region.cells.begin(), region.cells.end(),
              [](const Cell& a, const Cell& b) { return a.y != b.y ? a.y < b.y : a.x < b.x; });
    for (const Cell& c : region.cells) region.centroid_m += map.geometry().cell_center(c);
    region.centroid_m /= double(region.size());
    regions.push_back(std::move(region));
  }
  return regions;
}

namespace {

// Nearest traversable cell to `from` by a BFS over known-free cells, up to `max_steps` steps.
std::optional<Cell> approach_cell(const mapping::OccupancyGrid& map, const std::vector<std::uint8_t>& traversable,
                                  const Cell& from, int max_steps) {
  const int w = map.width();
  if (traversable[std::size_t(from.y * w + from.x)]) return from;
  thread_local std::vector<std::pair<Cell, int>> queue;
  thread_local std::vector<int> seen;
  queue.assign(1, {from, 0});
  seen.assign(1, from.y * w + from.x);
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const auto [c, d] = queue[head];
    if (d >= max_steps) continue;
    const Cell n[4] = {{c.x + 1, c.y}, {c.x - 1, c.y}, {c.x, c.y + 1}, {c.x, c.y - 1}};
    for (const Cell& m : n) {
      if (!map.contains(m) || map.state(m) != CellState::Free) continue;
      const int k = m.y * w + m.x;
      if (std::find(seen.begin(), seen.end(), k) != seen.end()) continue;
      if (traversable[std::size_t(k)]) return m;
      seen.push_back(k);
      queue.push_back({m, d + 1});
    }
  }
  return std::nullopt;
}

}  // namespace

std::vector<Target> make_targets(const mapping::OccupancyGrid& map, const std::vector<std::uint8_t>& traversable,
                                 const TargetOptions& options) {
  const auto regions = find_frontier_regions(map, options.frontiers);
  const double piece_cells = std::max(1.0, options.piece_radius_m / map.resolution());
  const int approach_steps = std::max(1, int(std::ceil(options.approach_radius_m / map.resolution())));
  std::vector<Target> targets;
  for (std::size_t r = 0; r < regions.size(); ++r) {
    const auto& cells = regions[r].cells;
    // Farthest-point sampling: seeds until every cell is within a piece radius of one.
    std::vector<Cell> seeds;
    std::vector<double> d2(cells.size(), std::numeric_limits<double>::infinity());
    std::size_t next = 0;
    {
      // Start from the cell nearest the centroid so a small region's target is its middle.
      const Eigen::Vector2d c = regions[r].centroid_m;
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < cells.size(); ++i) {
        const double d = (map.geometry().cell_center(cells[i]) - c).squaredNorm();
        if (d < best) best = d, next = i;
      }
    }
    while (true) {
      seeds.push_back(cells[next]);
      double far = -1.0;
      for (std::size_t i = 0; i < cells.size(); ++i) {
        const double dx = cells[i].x - cells[next].x, dy = cells[i].y - cells[next].y;
        d2[i] = std::min(d2[i], dx * dx + dy * dy);
      }
      for (std::size_t i = 0; i < cells.size(); ++i) {
        if (d2[i] > far) far = d2[i], next = i;
      }
      if (far <= piece_cells * piece_cells) break;
    }
    // Each cell belongs to its nearest seed; the piece size is its cell count.
    std::vector<int> counts(seeds.size(), 0);
    for (const Cell& c : cells) {
      std::size_t best = 0;
      double best_d = std::numeric_limits<double>::infinity();
      for (std::size_t s = 0; s < seeds.size(); ++s) {
        const double dx = c.x - seeds[s].x, dy = c.y - seeds[s].y, d = dx * dx + dy * dy;
        if (d < best_d) best_d = d, best = s;
      }
      ++counts[best];
    }
    for (std::size_t s = 0; s < seeds.size(); ++s) {
      const auto goal = approach_cell(map, traversable, seeds[s], approach_steps);
      if (!goal) continue;
      targets.push_back({seeds[s], *goal, map.geometry().cell_center(*goal), counts[s], int(r)});
    }
  }
  return targets;
}

int frontier_cells_near(const mapping::OccupancyGrid& map, const Cell& c, double radius_m) {
  const int r = int(std::ceil(radius_m / map.resolution()));
  const double r2 = double(r) * r;
  int n = 0;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx)
      if (double(dx * dx + dy * dy) <= r2 && is_frontier(map, {c.x + dx, c.y + dy})) ++n;
  return n;
}

}  // namespace fleetmap::exploration
