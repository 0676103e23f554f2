#include "exploration/tour_gain.h"

#include <cstdint>

namespace fleetmap::exploration {

std::vector<double> unknown_area_behind(const mapping::OccupancyGrid& map, const std::vector<Target>& targets,
                                        double reach_m) {
  std::vector<double> area(targets.size(), 0.0);
  const auto& g = map.geometry();
  const double reach = reach_m / map.resolution();
  const double reach2 = reach * reach;
  // Breadth-first, all targets at once: a cell belongs to the target whose flood arrives first.
  std::vector<std::int32_t> owner(std::size_t(map.width()) * std::size_t(map.height()), -1);
  std::vector<int> queue;
  for (std::size_t t = 0; t < targets.size(); ++t) {
    const Cell& c = targets[t].unknown;
    if (!map.contains(c) || map.observed(c)) continue;
    const int i = g.index(c);
    if (owner[std::size_t(i)] >= 0) continue;
    owner[std::size_t(i)] = std::int32_t(t);
    queue.push_back(i);
  }
  const double cell_area = map.resolution() * map.resolution();
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const int i = queue[head];
    const auto t = std::size_t(owner[std::size_t(i)]);
    area[t] += cell_area;
    const Cell c{i % map.width(), i / map.width()};
    const Cell& from = targets[t].unknown;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const Cell n{c.x + dx, c.y + dy};
        if ((dx == 0 && dy == 0) || !map.contains(n)) continue;
        const int k = g.index(n);
        if (owner[std::size_t(k)] >= 0 || map.observed(n)) continue;
        const double ex = n.x - from.x, ey = n.y - from.y;
        if (ex * ex + ey * ey > reach2) continue;
        owner[std::size_t(k)] = owner[std::size_t(i)];
        queue.push_back(k);
      }
    }
  }
  return area;
}

}  // namespace fleetmap::exploration
