// `fleetmap plan`: a collision-free path for a disc robot on any map, by any registered planner.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "cli/command.h"
#include "cli/map_notes.h"
#include "cli/outputs.h"
#include "cli/plan_output.h"
#include "cli/validators.h"
#include "core/error.h"
#include "core/params.h"
#include "io/file_io.h"
#include "maps/builtin_maps.h"
#include "io/map_io.h"
#include "viz/render.h"
#include "planning/planner.h"

namespace fleetmap::cli {

namespace fs = std::filesystem;

namespace {

// Robot radii, in metres (0: a point robot).
constexpr core::Range kRadiusRange{0, 100};

struct PlanCommandOptions {
  std::string map;
  std::string from, to, from_cell, to_cell;
  std::string planner = "rrtstar";
  double time_s = 1.0;
  double radius_m = 0.2;
  std::string unknown = "obstacle";
  std::uint64_t seed = 1;
  std::string out, json;
  double resolution = 0.05;
  bool resolution_given = false;  // --resolution was on the command line
  std::vector<std::string> set;   // --set planner.KEY=VALUE
};

// An endpoint as the user gave it: the flag and its text, and the point in metres.
struct Endpoint {
  std::string flag, text;
  Eigen::Vector2d point;
};

Endpoint endpoint(const std::string& name, const std::string& metres, const std::string& cell,
                  const mapping::OccupancyGrid& grid) {
  const std::string flag_m = "--" + name, flag_c = "--" + name + "-cell";
  if (metres.empty() && cell.empty()) {
    throw InputError("missing " + std::string(name == "from" ? "start" : "goal") + ": give " + flag_m +
                     " x,y (metres) or " + flag_c + " column,row");
  }
  if (!metres.empty()) {
    const auto p = parse_pair(metres);
    if (!p) throw InputError(flag_m + " '" + metres + "': expected x,y in metres, e.g. 2.5,4");
    return {flag_m, metres, {p->first, p->second}};
  }
  const auto c = parse_pair(cell);
  if (!c || c->first != std::floor(c->first) || c->second != std::floor(c->second) || std::abs(c->first) > 1e9 ||
      std::abs(c->second) > 1e9) {
    throw InputError(flag_c + " '" + cell + "': expected column,row as two integers, e.g. 40,25");
  }
  const core::Cell at{static_cast<int>(c->first), static_cast<int>(c->second)};
  if (!grid.contains(at)) {
    throw InputError(flag_c + " " + cell + ": cell outside the map of " + std::to_string(grid.width()) + "x" +
                     std::to_string(grid.height()) + " cells (columns 0.." + std::to_string(grid.width() - 1) +
                     ", rows 0.." + std::to_string(grid.height() - 1) + " from the bottom)");
  }
  return {flag_c, cell, grid.geometry().cell_center(at)};
}

nlohmann::json result_json(const PlanCommandOptions& o, const planning::PlanResult& r, const Endpoint& start,
                           const Endpoint& goal) {
  return plan_json(r, {o.map, start.point, goal.point, o.radius_m, o.unknown, o.time_s, o.seed});
}

cv::Mat picture(const PlanCommandOptions& o, const mapping::OccupancyGrid& grid, const planning::FreeSpace& space,
                const planning::PlanResult& r, const Endpoint& start, const Endpoint& goal) {
  viz::Overlays overlays;
  // Where the robot's centre may not go although the map says free: the inflation by its radius.
  viz::CellsOverlay inflated{{}, {255, 200, 120}, "within the robot radius of an obstacle", 0.5};
  for (int y = 0; y < grid.height(); ++y)
    for (int x = 0; x < grid.width(); ++x)
      if (!space.is_obstacle({x, y}) && !space.valid(core::Cell{x, y})) inflated.cells.push_back({x, y});
  overlays.cells.push_back(std::move(inflated));
  if (r.success()) {
    overlays.paths.push_back({r.path, viz::palette_color(0), fmt::format("{} path, {:.2f} m", r.planner, r.length_m), 2, false});
  }
  // The robot at both ends, heading along the path (or straight at the goal when there is none).
  const auto heading = [](const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
    const Eigen::Vector2d d = to - from;
    return d.norm() > 0 ? std::atan2(d.y(), d.x()) : 0.0;
  };
  const std::size_t n = r.path.size();
  const double at_start = n >= 2 ? heading(r.path[0], r.path[1]) : heading(start.point, goal.point);
  const double at_goal = n >= 2 ? heading(r.path[n - 2], r.path[n - 1]) : at_start;
  overlays.poses.push_back({{start.point.x(), start.point.y(), at_start}, o.radius_m, {44, 160, 44}, "start"});
  overlays.poses.push_back({{goal.point.x(), goal.point.y(), at_goal}, o.radius_m, {214, 39, 40}, "goal"});
  viz::RenderOptions render;
  render.title = fs::path(o.map).stem().string() + ": " + r.planner + (r.success() ? "" : " (no path)");
  return viz::render_map(grid, overlays, render);
}

int run_plan(const PlanCommandOptions& o) {
  const std::vector<OutputFile> outputs = {{"--out", o.out}, {"--json", o.json}};
  if (!o.out.empty()) io::check_picture_path(o.out, "--out");
  check_outputs(outputs, maps::map_source_files(o.map));
  std::FILE* report = report_stream(outputs);
  core::Settings settings;
  for (const auto& text : o.set) {
    const auto a = core::parse_param_assignment(text, "--set " + text);
    if (a.family != "planner") throw InputError("--set " + text + ": plan takes planner.KEY=VALUE, not " + a.family + "." + a.key);
    settings.emplace_back(a.key, a.value);
  }
  auto planner = planning::make_planner(o.planner, settings);  // a bad setting is refused before the map is read
  io::MapLoadOptions load;
  load.default_resolution = o.resolution;
  const mapping::OccupancyGrid grid = maps::load_map_source(o.map, load);
  const Endpoint start = endpoint("from", o.from, o.from_cell, grid);
  const Endpoint goal = endpoint("to", o.to, o.to_cell, grid);

  planning::FreeSpaceOptions space_options;
  space_options.robot_radius_m = o.radius_m;
  space_options.unknown = o.unknown == "free" ? planning::UnknownCells::Free : planning::UnknownCells::Obstacle;
  const planning::FreeSpace space(grid, space_options);
  planning::PlannerOptions search;
  search.time_budget_s = o.time_s;
  search.seed = o.seed;
  const planning::PlanResult r = planner->plan(space, start.point, goal.point, search);

  using planning::PlanStatus;
  if (r.status == PlanStatus::StartOutsideMap || r.status == PlanStatus::StartInObstacle) {
    throw InputError(start.flag + " " + start.text + ": " + r.detail);
  }
  if (r.status == PlanStatus::GoalOutsideMap || r.status == PlanStatus::GoalInObstacle) {
    throw InputError(goal.flag + " " + goal.text + ": " + r.detail);
  }

  if (!o.json.empty()) write_output(o.json, result_json(o, r, start, goal).dump(2) + "\n");
  if (!o.out.empty()) write_picture(o.out, picture(o, grid, space, r, start, goal));
  if (!r.success()) {
    // How the map was read may be why (a resolution that makes doors too narrow): said in the same line.
    fmt::print(stderr, "fleetmap plan: no path on {}: {}{}\n", o.map, r.detail, map_notes_suffix(o.map, load, o.resolution_given));
    return 1;
  }
  print_map_notes(o.map, load, o.resolution_given);  // how the map was read
  fmt::print(report, "{}: {:.2f} m in {} waypoints; first path after {:.3f} s, {:.3f} s in all\n", r.planner, r.length_m,
             r.path.size(), r.first_solution_s.value_or(r.time_s), r.time_s);
  for (const auto& out : outputs) {
    if (!out.path.empty() && !io::is_standard_output(out.path)) fmt::print(report, "wrote {}\n", out.path.string());
  }
  return 0;
}

}  // namespace

Command add_plan_command(CLI::App& root) {
  CLI::App* plan = root.add_subcommand("plan", "Plan a collision-free path for a disc robot on a map");
  plan->footer("Planners:\n" + planning::planner_help() +
               "\nA state is valid when its distance to the nearest obstacle cell exceeds --radius; motions are\n"
               "checked cell by cell, so no path cuts a corner. Exit codes: 0 path found, 1 no path (unreachable,\n"
               "or none found within --time), 2 bad input (a start or goal outside the map or in an obstacle).");
  auto o = std::make_shared<PlanCommandOptions>();
  plan->add_option("--map", o->map, "Built-in map name, image file or map_server YAML")->required();
  auto* from = plan->add_option("--from", o->from, "Start x,y in metres (map frame)");
  auto* to = plan->add_option("--to", o->to, "Goal x,y in metres (map frame)");
  plan->add_option("--from-cell", o->from_cell, "Start cell column,row (row 0 at the bottom), instead of --from")
      ->excludes(from);
  plan->add_option("--to-cell", o->to_cell, "Goal cell column,row (row 0 at the bottom), instead of --to")->excludes(to);
  plan->add_option("--planner", o->planner, "Planner name (see the list below)")
      ->capture_default_str()
      ->check(one_of(planning::planner_names()));
  plan->add_option("--set", o->set,
                   "A parameter of the planner, planner.KEY=VALUE (repeat for more), e.g. --planner reactive --set "
                   "planner.turn_angle_deg=20; each planner's parameters are listed below and by `fleetmap plugins`")
      ->expected(1)
      ->take_all();
  plan->add_option("--time", o->time_s, "Time budget in seconds")->capture_default_str()->check(in_range(planning::kTimeBudgetRange));
  plan->add_option("--radius", o->radius_m, "Robot radius in metres")->capture_default_str()->check(in_range(kRadiusRange));
  plan->add_option("--unknown", o->unknown, "Unknown cells are 'obstacle' or 'free'")
      ->capture_default_str()
      ->check(one_of({"obstacle", "free"}));
  plan->add_option("--seed", o->seed, "Seed of the sampling planners")->capture_default_str()->check(seed_number());
  plan->add_option("--out,-o", o->out, "Draw the map and the path to this PNG; - for the standard output (default: none)");
  plan->add_option("--json", o->json,
                   "Write planner, success, time, length and waypoints to this JSON; - for the standard output (default: none)");
  CLI::Option* resolution =
      plan->add_option("--resolution", o->resolution, "Metres per cell for a bare image without YAML")
          ->capture_default_str()
          ->check(in_range(io::kResolutionRange));
  return {plan, [o, resolution]() {
            o->resolution_given = resolution->count() > 0;
            return run_plan(*o);
          }};
}

}  // namespace fleetmap::cli
