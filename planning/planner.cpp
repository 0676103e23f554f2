#include "planning/planner.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>

#include "core/error.h"
#include "core/format.h"

namespace fleetmap::planning {

namespace {

using core::format_extent;
using core::format_point;

// Why a point inside the map is not a valid robot position.
std::string why_invalid(const FreeSpace& space, const Eigen::Vector2d& p) {
  const Cell c = *space.geometry().world_to_cell(p);
  if (space.is_obstacle(c)) {
    return space.cell_state(c) == mapping::CellState::Unknown
               ? "is in unknown space (unknown cells count as obstacles)"
               : "is inside an obstacle";
  }
  return fmt::format("is {:.2f} m from the nearest obstacle, not more than the robot radius {:.2f} m", space.clearance(c),
                     space.robot_radius());
}

}  // namespace

double path_length(const Path& path) {
  double length = 0.0;
  for (std::size_t i = 0; i + 1 < path.size(); ++i) length += (path[i + 1] - path[i]).norm();
  return length;
}

std::string_view to_string(PlanStatus s) {
  switch (s) {
    case PlanStatus::Success: return "success";
    case PlanStatus::StartOutsideMap: return "start outside map";
    case PlanStatus::GoalOutsideMap: return "goal outside map";
    case PlanStatus::StartInObstacle: return "start in obstacle";
    case PlanStatus::GoalInObstacle: return "goal in obstacle";
    case PlanStatus::Unreachable: return "unreachable";
    case PlanStatus::NotFound: return "no path within budget";
  }
  return "unknown status";
}

std::ostream& operator<<(std::ostream& os, PlanStatus s) { return os << to_string(s); }

PlanResult Planner::plan(const FreeSpace& space, const Eigen::Vector2d& start, const Eigen::Vector2d& goal,
                         const PlannerOptions& options) {
  if (!(options.time_budget_s >= kTimeBudgetRange.lo && options.time_budget_s <= kTimeBudgetRange.hi)) {
    throw InputError("planning time budget: expected " + core::expected_text(kTimeBudgetRange) + " seconds, got " +
                     std::to_string(options.time_budget_s));
  }
  const Clock::time_point t0 = Clock::now();
  const auto seconds_since_start = [t0](Clock::time_point t) { return std::chrono::duration<double>(t - t0).count(); };
  PlanResult result;
  result.planner = name();
  const auto finish = [&](PlanStatus status, std::string detail) {
    result.status = status;
    result.detail = std::move(detail);
    result.time_s = seconds_since_start(Clock::now());
    return result;
  };

  const GridGeometry& g = space.geometry();
  if (!g.world_to_cell(start)) {
    return finish(PlanStatus::StartOutsideMap, "start " + format_point(start) + " is outside the map (" + format_extent(g) + ")");
  }
  if (!g.world_to_cell(goal)) {
    return finish(PlanStatus::GoalOutsideMap, "goal " + format_point(goal) + " is outside the map (" + format_extent(g) + ")");
  }
  if (!space.valid(start)) return finish(PlanStatus::StartInObstacle, "start " + format_point(start) + " " + why_invalid(space, start));
  if (!space.valid(goal)) return finish(PlanStatus::GoalInObstacle, "goal " + format_point(goal) + " " + why_invalid(space, goal));
  if (options.check_reachability && !space.connected(*g.world_to_cell(start), *g.world_to_cell(goal))) {
    const std::string radius = fmt::format("{:.2f}", space.robot_radius());
    return finish(PlanStatus::Unreachable, "goal " + format_point(goal) + " cannot be reached from start " +
                                               format_point(start) + ": no collision-free corridor joins them for a robot of radius " +
                                               radius + " m");
  }

  if (start == goal) {  // some sampling planners never connect a start to itself
    result.path = {start, goal};
    result.first_solution_s = seconds_since_start(Clock::now());
    return finish(PlanStatus::Success, "start and goal coincide");
  }

  const Clock::time_point deadline =
      t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options.time_budget_s));
  Search found = search(space, start, goal, options, deadline);
  if (found.first_solution) result.first_solution_s = seconds_since_start(*found.first_solution);
  if (!found.found) {
    if (found.unreachable) return finish(PlanStatus::Unreachable, found.detail);
    if (found.detail.empty()) {
      found.detail = fmt::format("{} found no path within {:.2f} s", name(), options.time_budget_s);
    }
    return finish(PlanStatus::NotFound, found.detail);
  }
  result.path = std::move(found.path);
  result.length_m = path_length(result.path);
  return finish(PlanStatus::Success, fmt::format("path of {:.2f} m with {} waypoints", result.length_m, result.path.size()));
}

PlanResult plan_path(const mapping::OccupancyGrid& grid, const Eigen::Vector2d& start_m, const Eigen::Vector2d& goal_m,
                     const PlanPathOptions& options) {
  auto planner = make_planner(options.planner, options.planner_settings);
  const FreeSpace space(grid, options.space);
  return planner->plan(space, start_m, goal_m, options.search);
}

}  // namespace fleetmap::planning
