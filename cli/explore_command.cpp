// `fleetmap explore`: one exploration run, from flags or a scenario file, with its outputs.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>

#include "cli/command.h"
#include "cli/plan_output.h"
#include "cli/progress.h"
#include "cli/validators.h"
#include "core/error.h"
#include "exploration/strategy.h"
#include "localization/localizer.h"
#include "core/file_io.h"
#include "maps/builtin_maps.h"
#include "planning/planner.h"
#include "sim/run_output.h"
#include "sim/scenario.h"
#include "sim/simulation.h"

namespace fleetmap::cli {

namespace fs = std::filesystem;

namespace {

struct ExploreFlags {
  std::string scenario;
  std::optional<std::string> map, strategy, localization, comm_range, path_planner, merging;
  std::string plan_from, plan_to, planner = "astar";
  double plan_time = 1.0;
  std::optional<int> robots, steps, beams;
  std::optional<std::uint64_t> seed;
  std::optional<double> sensor_range;
  std::string out;
  bool animate = false;
  bool quiet = false;
  long long max_cells = 64'000'000;
};

double parse_range(const std::string& text) {
  if (text == "inf" || text == "infinite" || text == "unlimited") return std::numeric_limits<double>::infinity();
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size() && v >= 0.0 && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  throw InputError("--comm-range: expected metres >= 0 or 'inf', got '" + text + "'");
}

// A scenario map given as a relative path is relative to the scenario file.
std::string resolve_map(const sim::Scenario& s) {
  if (maps::is_builtin_map(s.map) && (!fs::exists(s.map) || fs::is_directory(s.map))) return s.map;
  const fs::path p = s.map;
  if (p.is_relative() && !s.base_dir.empty() && fs::exists(s.base_dir / p)) return (s.base_dir / p).string();
  return s.map;
}

int run_explore(const ExploreFlags& f) {
  sim::Scenario s;
  if (!f.scenario.empty()) s = sim::load_scenario(f.scenario);
  if (f.map) s.map = *f.map, s.base_dir.clear();
  if (f.robots) {
    s.robot_count = *f.robots;
    if (s.placement == sim::Placement::List) s.placement = sim::Placement::Cluster, s.starts.clear();
  }
  if (f.strategy) s.exploration.strategy = *f.strategy;
  if (f.localization) s.localization = *f.localization;
  if (f.comm_range) s.communication.range_m = parse_range(*f.comm_range);
  if (f.merging) s.merging = *f.merging;
  if (f.steps) s.steps = *f.steps;
  if (f.seed) s.seed = *f.seed;
  if (f.sensor_range) s.range.max_range_m = *f.sensor_range;
  if (f.beams) s.range.beams = *f.beams, s.range.angles_rad.clear();
  if (f.path_planner) s.path_planner = *f.path_planner;
  sim::validate_scenario(s);
  // A plan after the run: its endpoints are checked before the run starts.
  std::optional<Eigen::Vector2d> plan_from, plan_to;
  if (f.plan_from.empty() != f.plan_to.empty()) throw InputError("--plan-from and --plan-to go together: give both");
  if (!f.plan_from.empty()) {
    planning::make_planner(f.planner);  // an unknown planner is refused before the run
    const auto point = [](const std::string& flag, const std::string& text) {
      const auto p = parse_pair(text);
      if (!p) throw InputError(flag + " '" + text + "': expected x,y in metres, e.g. 2.5,4");
      return Eigen::Vector2d(p->first, p->second);
    };
    plan_from = point("--plan-from", f.plan_from);
    plan_to = point("--plan-to", f.plan_to);
  }

  mapping::MapLoadOptions load;
  load.max_cells = f.max_cells;
  const std::string map_source = resolve_map(s);
  auto truth = maps::load_map_source(map_source, load);
  bool any_free = false;
  for (int i = 0; i < truth.width() * truth.height() && !any_free; ++i) any_free = truth.state_at(i) == mapping::CellState::Free;
  if (!any_free) throw InputError(map_source + ": the map has no free cell: nowhere for a robot to start");
  const std::string label = maps::is_builtin_map(s.map) ? s.map : fs::path(s.map).stem().string();
  const fs::path out = f.out.empty() ? fs::path("out") / label : fs::path(f.out);

  // Placing the robots is where a scenario meets its map: errors name the scenario, or the map.
  std::optional<sim::Simulation> made;
  try {
    made.emplace(s, std::move(truth));
  } catch (const InputError& e) {
    throw InputError((f.scenario.empty() ? map_source : f.scenario) + ": " + e.what());
  }
  sim::Simulation& simulation = *made;
  ProgressBar bar(!f.quiet);
  std::unique_ptr<sim::RunVideo> video;
  if (f.animate) video = std::make_unique<sim::RunVideo>(out / "run.mp4");
  const sim::RunResult result = simulation.run(
      [&](int step, int limit, double coverage) { bar.update(step, limit, "coverage " + format_percent(coverage)); },
      [&](const sim::Simulation& sim) {
        if (video) video->add_frame(sim, label);
      });
  bar.finish();

  // The plan on the merged map, drawn on merged.png and written to path.json.
  std::optional<planning::PlanResult> plan;
  mapping::Overlays extra;
  if (plan_from) {
    planning::PlanPathOptions o;
    o.planner = f.planner;
    o.space.robot_radius_m = s.robot.radius_m;
    o.search.time_budget_s = f.plan_time;
    o.search.seed = s.seed;
    plan = planning::plan_path(result.merged, *plan_from, *plan_to, o);
    if (plan->success()) {
      char text[96];
      std::snprintf(text, sizeof text, "%s path on the merged map, %.2f m", plan->planner.c_str(), plan->length_m);
      extra.paths.push_back({plan->path, {20, 20, 20}, text, 3, false});
    }
    extra.poses.push_back({{plan_from->x(), plan_from->y(), 0.0}, s.robot.radius_m, {44, 160, 44}, "plan start"});
    extra.poses.push_back({{plan_to->x(), plan_to->y(), 0.0}, s.robot.radius_m, {214, 39, 40}, "plan goal"});
  }
  auto written = sim::write_run_outputs(result, label, out, extra);
  if (plan) {
    core::write_file_atomic(out / "path.json",
                            plan_json(*plan, {label, *plan_from, *plan_to, s.robot.radius_m, "obstacle", f.plan_time, s.seed})
                                    .dump(2) +
                                "\n");
    written.push_back(out / "path.json");
  }
  if (video) {
    video->finish();
    written.push_back(out / "run.mp4");
  }
  // A plan that failed: the run's outputs are written; the plan's problem gets one line.
  const auto plan_exit = [&]() {
    if (!plan || plan->success()) return 0;
    using planning::PlanStatus;
    const bool bad_point = plan->status == PlanStatus::StartOutsideMap || plan->status == PlanStatus::StartInObstacle ||
                           plan->status == PlanStatus::GoalOutsideMap || plan->status == PlanStatus::GoalInObstacle;
    const bool at_start = plan->status == PlanStatus::StartOutsideMap || plan->status == PlanStatus::StartInObstacle;
    std::fprintf(stderr, "fleetmap: %s: no path on the merged map: %s\n",
                 bad_point ? (at_start ? ("--plan-from " + f.plan_from).c_str() : ("--plan-to " + f.plan_to).c_str())
                           : "--plan-from/--plan-to",
                 plan->detail.c_str());
    return bad_point ? 2 : 1;
  };
  if (f.quiet) {
    std::printf("%s\n", (out / "merged.png").c_str());
    return plan_exit();
  }
  const auto& sc = result.scenario;
  double distance = 0.0;
  for (const auto& t : result.robots) distance += t.distance_m;
  const auto step_text = [](const std::optional<int>& v) { return v ? std::to_string(*v) : std::string("not reached"); };
  char range[64];
  if (std::isinf(sc.communication.range_m)) std::snprintf(range, sizeof range, "unlimited");
  else if (sc.communication.range_m == 0.0) std::snprintf(range, sizeof range, "only at rendezvous");
  else std::snprintf(range, sizeof range, "%g m", sc.communication.range_m);
  std::printf("%s: %d robots, strategy %s, localization %s, communication %s, seed %llu\n", label.c_str(),
              sc.robot_count, sc.exploration.strategy.c_str(), sc.localization.c_str(), range,
              static_cast<unsigned long long>(sc.seed));
  std::printf("explored %s of the reachable free space in %d steps (%s); 95%% at step %s, 99%% at step %s\n",
              format_percent(result.coverage.back()).c_str(), result.steps,
              result.finished ? "no reachable frontier left" : "step limit reached", step_text(result.steps_to_95).c_str(),
              step_text(result.steps_to_99).c_str());
  std::printf("travelled %.1f m in all, redundancy %.2f, %lld bytes sent in %d meetings, %.2f s\n", distance,
              result.redundancy, static_cast<long long>(result.bytes_sent), result.meetings, result.timing.total);
  if (sc.merging != "known") {
    int made = 0;
    double worst_deg = 0.0, worst_m = 0.0;
    for (const auto& m : result.merges) {
      if (!m.merged) continue;
      ++made;
      worst_deg = std::max(worst_deg, m.rotation_error_deg);
      worst_m = std::max(worst_m, m.position_error_m);
    }
    std::printf("merging (%s): %d merges made, %zu refused; worst error against the truth %.2f deg, %.3f m\n",
                sc.merging.c_str(), made, result.merges.size() - made, worst_deg, worst_m);
  }
  if (plan && plan->success()) {
    std::printf("planned on the merged map (%s): %.2f m in %zu waypoints, %.3f s\n", plan->planner.c_str(),
                plan->length_m, plan->path.size(), plan->time_s);
  }
  std::printf("merged map: %s\n", (out / "merged.png").c_str());
  std::printf("all outputs in %s/:", out.c_str());
  for (const auto& p : written) std::printf(" %s", p.filename().c_str());
  std::printf("\n");
  return plan_exit();
}

}  // namespace

Command add_explore_command(CLI::App& root) {
  CLI::App* app = root.add_subcommand(
      "explore",
      "Explore a map with a team of simulated robots; writes the merged map, each robot's map, metrics and map files");
  app->footer(
      "Flags override the scenario file; without one, the defaults above apply.\n\n"
      "Strategies (--strategy):\n" +
      exploration::strategy_help() + "\nLocalization (--localization):\n" + localization::localizer_help() +
      "\nMerging (--merging): how robots bring each other's maps into their own frame\n"
      "  known       every robot knows its start pose in one shared frame (default)\n"
      "  rendezvous  each robot maps in its own frame; robots that detect each other take the\n"
      "              relative transform from the detection (seed 000 section 3.2)\n"
      "  overlap     each robot maps in its own frame; robots that can talk search their maps for\n"
      "              the best overlap (as `fleetmap merge`) and merge only above a confidence\n");
  auto f = std::make_shared<ExploreFlags>();
  app->add_option("--scenario", f->scenario, "Scenario YAML file (see scenarios/); flags below override it")
      ->check(CLI::ExistingFile);
  app->add_option("--map", f->map, "Built-in map name, image or map_server YAML [default: office]");
  app->add_option("--robots", f->robots, "Number of robots, placed together near the map centre [default: 4]")
      ->check(CLI::Range(1, 64));
  app->add_option("--strategy", f->strategy, "Coordination strategy [default: directional]")
      ->check(CLI::IsMember(exploration::strategy_names()));
  app->add_option("--localization", f->localization, "How robots know their pose [default: ideal]")
      ->check(CLI::IsMember(localization::localizer_names()));
  app->add_option("--comm-range", f->comm_range,
                  "Communication range in metres; 0 = only when robots see each other; inf = always [default: inf]");
  app->add_option("--merging", f->merging, "known, rendezvous or overlap (see above) [default: known]")
      ->check(CLI::IsMember(sim::merging_names()));
  app->add_option("--steps", f->steps, "Step limit [default: 2000]")->check(positive());
  app->add_option("--seed", f->seed, "Random seed: the same seed gives the same run [default: 1]")->check(whole_number());
  app->add_option("--sensor-range", f->sensor_range, "Laser range in metres [default: 4]")->check(positive());
  app->add_option("--beams", f->beams, "Laser beams over 360 degrees [default: 360]")->check(positive());
  app->add_option("--path-planner", f->path_planner,
                  "How robots get paths to targets: wave, or a planner of `fleetmap plan` (astar, rrtconnect, ...) "
                  "[default: wave]")
      ->check(CLI::IsMember(sim::path_planner_names()));
  app->add_option("--plan-from", f->plan_from, "After the run, plan from x,y (metres) on the merged map ...");
  app->add_option("--plan-to", f->plan_to, "... to x,y; the path goes on merged.png and into path.json");
  app->add_option("--planner", f->planner, "Planner for --plan-from/--plan-to (see `fleetmap plan --help`)")
      ->capture_default_str();
  app->add_option("--plan-time", f->plan_time, "Time budget of that plan, seconds")->capture_default_str()->check(positive());
  app->add_option("--out", f->out, "Output folder, created if missing [default: out/<map>]");
  app->add_flag("--animate", f->animate, "Also write run.mp4, a frame per step");
  app->add_flag("--quiet,-q", f->quiet, "Print only the merged map's path; no progress bar");
  app->add_option("--max-cells", f->max_cells, "Refuse maps with more cells than this")->capture_default_str()->check(positive());
  return {app, [f]() { return run_explore(*f); }};
}

}  // namespace fleetmap::cli
