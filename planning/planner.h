#pragma once
// One interface for every path planner: OMPL's sampling planners, grid A* and the map-alignment paper's reactive
// steering. Planners are chosen by name (`fleetmap plan --planner`, scenario files) through
// make_planner(); tests and benchmarks iterate over planner_names().
//
// Expected outcomes (a goal in a wall, outside the map, unreachable, no path within the budget)
// are PlanStatus values; exceptions are kept for misuse (an unknown name, a negative budget).
// Planners do no I/O and never print.
#include <Eigen/Core>

#include <chrono>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/range.h"
#include "core/registry.h"
#include "mapping/occupancy_grid.h"
#include "planning/free_space.h"

namespace fleetmap::planning {

using Path = std::vector<Eigen::Vector2d>;  // waypoints in metres, joined by straight segments

// Sum of the segment lengths, in metres.
double path_length(const Path& path);

enum class PlanStatus {
  Success,
  StartOutsideMap,
  GoalOutsideMap,
  StartInObstacle,  // in an obstacle, or closer to one than the robot radius
  GoalInObstacle,
  Unreachable,  // proved: start and goal lie in separate regions of free space
  NotFound,     // the planner found no path within its budget; one may exist
};

// "success", "start outside map", ..., "no path within budget".
std::string_view to_string(PlanStatus s);
std::ostream& operator<<(std::ostream& os, PlanStatus s);

struct PlanResult {
  PlanStatus status = PlanStatus::NotFound;
  std::string planner;
  Path path;  // from the start to the goal, both exactly; empty unless success
  double length_m = 0.0;
  double time_s = 0.0;  // wall time of the whole call
  // Seconds from the call's start to the first path found (before any further optimisation).
  std::optional<double> first_solution_s;
  std::string detail;  // one line for a user, e.g. "goal (3.00, 4.00) is inside an obstacle"

  bool success() const { return status == PlanStatus::Success; }
};

// The time budgets a planner accepts, in seconds (the CLI flags and scenario keys use it too).
inline constexpr core::Range kTimeBudgetRange{1e-3, 3600};

struct PlannerOptions {
  // Wall-clock budget of the whole call, within kTimeBudgetRange. Optimising planners (RRT*,
  // PRM*, BIT*) use all of it; the others stop at their first path. 10% is kept for OMPL's path
  // simplification.
  double time_budget_s = 1.0;
  // When > 0, OMPL planners also stop after this many iterations (checks of their termination
  // condition), and path simplification after a tenth as many: a budget that gives the same path
  // on every machine however busy, as long as the time budget is not reached first.
  long iteration_budget = 0;
  // OMPL planners reseed OMPL's process-wide generator with it at each call, one call at a time:
  // reproducible (RRT-Connect exactly; the anytime planners exactly with an iteration budget,
  // otherwise up to how far their time budget gets).
  std::uint64_t seed = 1;
  // OMPL: shortcutting and smoothing of the solution; astar: any-angle smoothing of the grid path;
  // reactive: merging collinear steps.
  bool simplify = true;
  // Answer Unreachable at once when start and goal lie in separate regions of free space, instead
  // of letting the planner spend its budget.
  bool check_reachability = true;
};

class Planner {
 public:
  using Clock = std::chrono::steady_clock;

  virtual ~Planner() = default;
  virtual std::string name() const = 0;

  // Checks the endpoints (inside the map, valid for the robot radius) and reachability, then
  // searches. Throws InputError for a non-positive or non-finite budget; never for an outcome.
  PlanResult plan(const FreeSpace& space, const Eigen::Vector2d& start, const Eigen::Vector2d& goal,
                  const PlannerOptions& options = {});

 protected:
  // What a search returns: a valid path from `start` to `goal`, or why there is none.
  struct Search {
    bool found = false;
    bool unreachable = false;  // the search proved that no path exists
    Path path;
    std::optional<Clock::time_point> first_solution;
    std::string detail;  // why nothing was found
  };
  // Called with valid endpoints; must return by `deadline` (give or take one step of work).
  virtual Search search(const FreeSpace& space, const Eigen::Vector2d& start, const Eigen::Vector2d& goal,
                        const PlannerOptions& options, Clock::time_point deadline) = 0;
};

struct PlannerInfo {
  std::string name;
  std::string description;  // one line: the algorithm and its source
  // Finds a path whenever one exists, given enough time: resolution complete (astar) or
  // probabilistically complete (OMPL's planners). The reactive baseline is not.
  bool complete = true;
};

// A registered planner: how to make one from its declared parameters' values, and whether it is
// complete.
struct PlannerMaker {
  std::function<std::unique_ptr<Planner>(const core::Params&)> make;
  bool complete = true;
};

// Every planner by name: the built-in ones, then those registered by the program.
core::Registry<PlannerMaker>& planner_registry();
// Adds a planner: `fleetmap plan --planner NAME`, `--path-planner NAME` and the test harnesses
// reach it. Throws Error when the name is taken or unusable.
// `params` are the settings it accepts (core/params.h).
void register_planner(std::string name, std::string help, PlannerMaker maker, std::vector<core::ParamSpec> params = {});

// The registered planners, in the order --help lists them.
std::vector<PlannerInfo> planner_infos();
std::vector<std::string> planner_names();
// One line per planner, for --help and README.
std::string planner_help();
// The planner's declared parameters with `settings` applied; throws InputError for an unknown name
// (naming the valid ones), a setting it does not declare or a value it refuses.
core::Params planner_options(const std::string& name, const core::Settings& settings = {});
// Throws as planner_options.
std::unique_ptr<Planner> make_planner(const std::string& name, const core::Settings& settings = {});

struct PlanPathOptions {
  std::string planner = "rrtstar";
  core::Settings planner_settings;  // the planner's own parameters (planner_options)
  FreeSpaceOptions space;
  PlannerOptions search;
};

// One query on a grid: builds the free space, makes the planner and plans. Callers with many
// queries on one map should build a FreeSpace once and call Planner::plan.
PlanResult plan_path(const mapping::OccupancyGrid& grid, const Eigen::Vector2d& start_m,
                     const Eigen::Vector2d& goal_m, const PlanPathOptions& options = {});

}  // namespace fleetmap::planning
