#include "sim/placement.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "core/error.h"
#include "core/format.h"

namespace fleetmap::sim {

namespace {

std::string point_text(const Eigen::Vector2d& p) { return core::format_point(p); }

std::string extent_text(const core::GridGeometry& g) { return core::format_extent(g); }

// Free cells in order of 4-connected BFS distance from the free cell nearest to `centre`.
std::vector<Cell> free_cells_from(const World& world, const Eigen::Vector2d& centre, std::size_t enough) {
  const auto& g = world.geometry();
  const int w = g.width(), h = g.height();
  Cell start = g.world_to_cell_unbounded(centre);
  start.x = std::clamp(start.x, 0, w - 1);
  start.y = std::clamp(start.y, 0, h - 1);
  std::vector<std::uint8_t> seen(std::size_t(w) * std::size_t(h), 0);
  std::vector<Cell> queue = {start}, out;
  seen[std::size_t(g.index(start))] = 1;
  // Through any cell until the first free one, then through free cells only.
  bool in_free = false;
  for (std::size_t head = 0; head < queue.size() && out.size() < enough; ++head) {
    const Cell c = queue[head];
    const bool free = !world.blocked(c);
    if (free && !in_free) {
      in_free = true;
      queue.erase(queue.begin() + std::ptrdiff_t(head) + 1, queue.end());
      std::fill(seen.begin(), seen.end(), 0);
      seen[std::size_t(g.index(c))] = 1;
    }
    if (in_free && !free) continue;
    if (free) out.push_back(c);
    const Cell n[4] = {{c.x + 1, c.y}, {c.x - 1, c.y}, {c.x, c.y + 1}, {c.x, c.y - 1}};
    for (const Cell& m : n) {
      if (!g.contains(m) || seen[std::size_t(g.index(m))]) continue;
      seen[std::size_t(g.index(m))] = 1;
      queue.push_back(m);
    }
  }
  return out;
}

}  // namespace

std::vector<core::Pose2> place_robots(const Scenario& s, const World& world, core::Random& rng) {
  const double r = s.robot.radius_m;
  const auto& g = world.geometry();
  if (s.placement == Placement::List) {
    for (std::size_t i = 0; i < s.starts.size(); ++i) {
      const Eigen::Vector2d p = s.starts[i].position();
      const std::string who = "robot " + std::to_string(i + 1) + " starts at " + point_text(p);
      const auto cell = g.world_to_cell(p);
      if (!cell) throw InputError(who + ", outside the map (" + extent_text(g) + ")");
      if (world.blocked(*cell)) throw InputError(who + ", inside a wall");
      if (!world.disc_free(p, r)) {
        const double clearance = world.clearance(p, 2.0 * r);
        throw InputError(who + fmt::format(", too close to a wall (clearance {:.2f} m, radius {:.2f} m)", clearance, r));
      }
      for (std::size_t j = 0; j < i; ++j) {
        if ((s.starts[j].position() - p).norm() < 2.0 * r) {
          throw InputError(who + ", on robot " + std::to_string(j + 1) + " (centres closer than two radii, " +
                           std::to_string(2.0 * r).substr(0, 4) + " m)");
        }
      }
    }
    return s.starts;
  }

  Eigen::Vector2d centre = g.grid_to_world({0.5 * g.width(), 0.5 * g.height()});
  if (s.cluster_at) {
    centre = *s.cluster_at;
    const auto cell = g.world_to_cell(centre);
    if (!cell) throw InputError("robots.cluster_at " + point_text(centre) + " is outside the map (" + extent_text(g) + ")");
    if (world.blocked(*cell)) throw InputError("robots.cluster_at " + point_text(centre) + " is inside a wall");
  }
  const ReachableRegions regions = world.reachable_regions(r);
  if (regions.largest < 0) {
    throw InputError(fmt::format("robots: a robot of radius {:.2f} m fits nowhere on the map: no free place is {:.2f} m wide",
                                 r, 2.0 * r));
  }
  // Every robot starts in one region: the one of the free cells around cluster_at when the user
  // chose it (the region nearest to it), else the largest, so that the team can meet and has the
  // most to explore wherever the map's centre happens to fall.
  const double separation = std::max(s.min_separation_m, 2.0 * r + 0.05);
  const double need = r + 0.05;
  std::vector<Cell> candidates = free_cells_from(world, centre, std::size_t(-1) / 2);
  int region = regions.largest;
  if (s.cluster_at) {
    for (const Cell& c : candidates) {
      if (const int l = regions.at(g.index(c)); l >= 0) {
        region = l;
        break;
      }
    }
  }
  const auto in_region = [&](const Cell& c) { return regions.at(g.index(c)) == region; };
  if (std::none_of(candidates.begin(), candidates.end(), in_region)) {
    // The free space around the point does not lead into the region: start from its cell nearest the point.
    Cell nearest{0, 0};
    double best = INFINITY;
    for (int i = 0; i < g.cell_count(); ++i) {
      if (regions.at(i) != region) continue;
      const double d = (g.cell_center(g.cell_of_index(i)) - centre).squaredNorm();
      if (d < best) best = d, nearest = g.cell_of_index(i);
    }
    candidates = free_cells_from(world, g.cell_center(nearest), std::size_t(-1) / 2);
  }
  if (s.placement == Placement::Random) std::shuffle(candidates.begin(), candidates.end(), rng.engine());
  std::erase_if(candidates, [&](const Cell& c) { return !in_region(c); });
  std::vector<core::Pose2> starts;
  for (const Cell& c : candidates) {
    if (int(starts.size()) == s.robot_count) break;
    const Eigen::Vector2d p = g.cell_center(c);
    if (world.clearance(p, need) < need) continue;
    const bool apart = std::all_of(starts.begin(), starts.end(), [&](const core::Pose2& q) {
      return (q.position() - p).norm() >= separation;
    });
    if (!apart) continue;
    const double heading = s.placement == Placement::Random ? rng.uniform(-M_PI, M_PI) : 0.0;
    starts.emplace_back(p.x(), p.y(), heading);
  }
  if (int(starts.size()) < s.robot_count) {
    throw InputError("robots: only " + std::to_string(starts.size()) + " of " + std::to_string(s.robot_count) +
                     " robots fit in the free space around " + point_text(centre) + " (radius " + std::to_string(r).substr(0, 4) +
                     " m, separation " + std::to_string(separation).substr(0, 4) + " m)");
  }
  return starts;
}

}  // namespace fleetmap::sim
