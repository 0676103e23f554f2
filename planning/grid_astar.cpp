#include "planning/grid_astar.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <limits>
#include <memory>
#include <queue>
#include <tuple>
#include <utility>

#include "planning/planners.h"

namespace fleetmap::planning {

namespace {

constexpr double kSqrt2 = 1.4142135623730951;

// Octile distance in metres: the 8-connected cost on an empty grid, a consistent heuristic.
double octile(const Cell& a, const Cell& b, double res) {
  const int dx = std::abs(a.x - b.x), dy = std::abs(a.y - b.y);
  return res * (std::max(dx, dy) + (kSqrt2 - 1.0) * std::min(dx, dy));
}

class AStarPlanner final : public Planner {
 public:
  std::string name() const override { return "astar"; }

 protected:
  Search search(const FreeSpace& space, const Eigen::Vector2d& start, const Eigen::Vector2d& goal,
                const PlannerOptions& options, Clock::time_point deadline) override {
    Search s;
    const Cell a = *space.geometry().world_to_cell(start), b = *space.geometry().world_to_cell(goal);
    const GridSearch grid = astar_grid(space, a, b, deadline);
    if (grid.outcome == GridSearch::Outcome::NoPath) {
      s.unreachable = true;
      s.detail = "astar: no collision-free path joins start and goal on the grid";
      return s;
    }
    if (grid.outcome == GridSearch::Outcome::Stopped) return s;
    s.first_solution = Clock::now();
    s.found = true;
    s.path = grid_path_waypoints(space, grid.path, start, goal);
    if (options.simplify) s.path = smooth_any_angle(space, s.path);
    return s;
  }
};

}  // namespace

GridSearch astar_grid(const FreeSpace& space, const Cell& start, const Cell& goal,
                      std::optional<std::chrono::steady_clock::time_point> deadline) {
  GridSearch result;
  if (!space.valid(start) || !space.valid(goal)) return result;
  const GridGeometry& geo = space.geometry();
  const double res = geo.resolution();
  const auto n = static_cast<std::size_t>(geo.cell_count());
  std::vector<double> g(n, std::numeric_limits<double>::infinity());
  std::vector<int> parent(n, -1);
  std::vector<std::uint8_t> closed(n, 0);

  // Min-heap on f; among equal f the larger g (the deeper node) first, which explores less.
  using Entry = std::tuple<double, double, int>;  // f, -g, index
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  const int start_index = geo.index(start), goal_index = geo.index(goal);
  g[static_cast<std::size_t>(start_index)] = 0.0;
  open.emplace(octile(start, goal, res), -0.0, start_index);

  static constexpr Cell kSteps[8] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {1, -1}, {-1, 1}, {-1, -1}};
  std::size_t pops = 0;
  while (!open.empty()) {
    const auto [f, neg_g, index] = open.top();
    open.pop();
    const auto u = static_cast<std::size_t>(index);
    if (closed[u]) continue;
    closed[u] = 1;
    if (index == goal_index) {
      result.outcome = GridSearch::Outcome::Found;
      result.path.cost_m = g[u];
      for (int i = goal_index; i != -1; i = parent[static_cast<std::size_t>(i)]) {
        result.path.cells.push_back(geo.cell_of_index(i));
      }
      std::reverse(result.path.cells.begin(), result.path.cells.end());
      return result;
    }
    if (deadline && (++pops & 4095) == 0 && std::chrono::steady_clock::now() > *deadline) {
      result.outcome = GridSearch::Outcome::Stopped;
      return result;
    }
    const Cell c = geo.cell_of_index(index);
    for (const Cell& step : kSteps) {
      const Cell next = c + step;
      if (!space.valid(next)) continue;
      const bool diagonal = step.x != 0 && step.y != 0;
      if (diagonal && (!space.valid(Cell{c.x + step.x, c.y}) || !space.valid(Cell{c.x, c.y + step.y}))) continue;
      const auto v = static_cast<std::size_t>(geo.index(next));
      if (closed[v]) continue;
      const double candidate = g[u] + (diagonal ? kSqrt2 * res : res);
      if (candidate < g[v]) {
        g[v] = candidate;
        parent[v] = index;
        open.emplace(candidate + octile(next, goal, res), -candidate, static_cast<int>(v));
      }
    }
  }
  return result;
}

Path grid_path_waypoints(const FreeSpace& space, const GridPath& grid_path, const Eigen::Vector2d& start,
                         const Eigen::Vector2d& goal) {
  Path path{start};
  for (std::size_t i = 1; i + 1 < grid_path.cells.size(); ++i) path.push_back(space.geometry().cell_center(grid_path.cells[i]));
  path.push_back(goal);
  return path;
}

Path smooth_any_angle(const FreeSpace& space, const Path& path) {
  if (path.size() <= 2) return path;
  Path out{path.front()};
  std::size_t i = 0;
  while (i + 1 < path.size()) {
    std::size_t j = i + 1;
    while (j + 1 < path.size() && space.segment_valid(path[i], path[j + 1])) ++j;
    out.push_back(path[j]);
    i = j;
  }
  return out;
}

std::unique_ptr<Planner> make_astar_planner() { return std::make_unique<AStarPlanner>(); }

}  // namespace fleetmap::planning
