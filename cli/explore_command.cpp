// `fleetmap explore`: one exploration run, from flags or a scenario file, with its outputs.
#include <algorithm>
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>

#include "cli/command.h"
#include "cli/map_notes.h"
#include "cli/plan_output.h"
#include "cli/progress.h"
#include "cli/validators.h"
#include "core/angle.h"
#include "core/error.h"
#include "core/format.h"
#include "exploration/strategy.h"
#include "io/file_io.h"
#include "io/map_io.h"
#include "localization/localizer.h"
#include "maps/builtin_maps.h"
#include "merging/map_aligner.h"
#include "planning/planner.h"
#include "sim/run_metrics.h"
#include "sim/run_output.h"
#include "sim/run_replay.h"
#include "sim/scenario.h"
#include "sim/simulation.h"

namespace fleetmap::cli {

namespace fs = std::filesystem;

namespace {

struct ExploreFlags {
  std::string scenario;
  std::optional<std::string> map, strategy, localization, comm_range, path_planner, merging, starts, cluster_at;
  std::vector<std::string> start;  // --start x,y[,heading_deg], once per robot
  std::vector<std::string> set;    // --set FAMILY.KEY=VALUE
  std::optional<double> min_separation, resolution;
  std::string plan_from, plan_to, planner = "astar";
  double plan_time = 1.0;
  std::optional<int> robots, steps, beams;
  std::optional<std::uint64_t> seed;
  std::optional<double> sensor_range, landmarks;
  std::string out;
  bool animate = false;
  bool html = false;
  std::string video;  // a file name inside --out; --animate is run.mp4
  std::string merge_attempts;  // debug: a folder for the two maps of every merge attempt
  bool quiet = false;
  long long max_cells = 64'000'000;
};

// "1 robot", "4 robots".
std::string counted(long long n, const std::string& one) { return fmt::format("{} {}{}", n, one, n == 1 ? "" : "s"); }

sim::Scenario scenario_from(const ExploreFlags& f) {
  sim::Scenario s;
  if (!f.scenario.empty()) s = sim::load_scenario(f.scenario);
  if (f.map) s.map = *f.map, s.base_dir.clear();
  if (f.resolution) s.map_resolution_m = *f.resolution;
  if (f.robots) {
    s.robot_count = *f.robots;
    if (s.placement == sim::Placement::List) s.placement = sim::Placement::Cluster, s.starts.clear();
  }
  if (f.starts) {
    s.placement = *f.starts == "random" ? sim::Placement::Random : sim::Placement::Cluster;
    s.starts.clear();
  }
  if (!f.start.empty()) {
    if (f.starts) throw InputError("--start and --starts " + *f.starts + " go apart: --start places each robot itself");
    if (f.cluster_at) throw InputError("--start and --cluster-at go apart: --start places each robot itself");
    if (f.robots && *f.robots != int(f.start.size())) {
      throw InputError(fmt::format("--robots {} and {} --start poses disagree: give one --start per robot", *f.robots,
                                   f.start.size()));
    }
    s.starts.clear();
    for (const auto& text : f.start) {
      const auto v = parse_numbers(text);
      if (!v || v->size() < 2 || v->size() > 3) {
        throw InputError("--start '" + text + "': expected x,y or x,y,heading (metres, degrees), e.g. 2.5,4 or 2.5,4,90");
      }
      s.starts.emplace_back((*v)[0], (*v)[1], v->size() > 2 ? core::deg2rad((*v)[2]) : 0.0);
    }
    s.placement = sim::Placement::List;
    s.robot_count = int(s.starts.size());
  }
  if (f.cluster_at) {
    const auto p = parse_pair(*f.cluster_at);
    if (!p) throw InputError("--cluster-at '" + *f.cluster_at + "': expected x,y in metres, e.g. 2.5,4");
    if (s.placement == sim::Placement::List) s.placement = sim::Placement::Cluster, s.starts.clear();
    s.cluster_at = Eigen::Vector2d(p->first, p->second);
  }
  if (f.min_separation) s.min_separation_m = *f.min_separation;
  if (f.strategy && *f.strategy != s.exploration.strategy) {
    s.exploration.strategy = *f.strategy;
    // The scenario's settings were for its own strategy: the new one keeps those it declares too.
    s.exploration.strategy_settings = exploration::declared_settings(*f.strategy, s.exploration.strategy_settings);
  }
  for (const auto& text : f.set) sim::set_parameter(s, text, "--set " + text);
  if (f.localization) s.localization = *f.localization;
  if (f.comm_range) s.communication.range_m = *core::parse_in_range(*f.comm_range, sim::limits::kCommRange);
  if (f.merging) s.merging = *f.merging;
  if (f.steps) s.steps = *f.steps;
  if (f.seed) s.seed = *f.seed;
  if (f.sensor_range) s.range.max_range_m = *f.sensor_range;
  if (f.beams) s.range.beams = *f.beams, s.range.angles_rad.clear();
  if (f.landmarks) s.landmarks_along_walls = *f.landmarks;
  if (f.path_planner) s.path_planner = *f.path_planner;
  if (f.html) s.html_replay = true;
  // Said here with the flag that helps; a scenario's own check names the keys only.
  if ((s.localization == "ekf" || s.localization == "ekf-slam") && s.landmarks.empty() && s.landmarks_along_walls <= 0.0) {
    throw InputError("localization '" + s.localization +
                     "' localizes against landmarks, and there are none: add some (--landmarks 0.5 places one per "
                     "2 m of wall; in a scenario, landmarks: {along_walls: 0.5} or landmarks: {points: [[x, y]]}), "
                     "or choose a localizer that needs none (odometry, scan-matching, rbpf, mcl, polynomial)");
  }
  sim::validate_scenario(s);
  // From here on the map is named as it is loaded: a built-in name, or a path from here.
  s.map = sim::map_source(s);
  s.base_dir.clear();
  return s;
}

void print_summary(const sim::RunResult& result, const std::string& label) {
  const auto& sc = result.scenario;
  double distance = 0.0;
  for (const auto& t : result.robots) distance += t.distance_m;
  const auto level_text = [](const char* level, const std::optional<int>& v) {
    return v ? fmt::format("{} at step {}", level, *v) : fmt::format("{} never reached", level);
  };
  const std::string range = std::isinf(sc.communication.range_m) ? "unlimited"
                            : sc.communication.range_m == 0.0  ? "only at rendezvous"
                                                               : fmt::format("{} m", sc.communication.range_m);
  fmt::print("{}: {}, strategy {}, localization {}, communication {}, seed {}\n", label,
             counted(sc.placement == sim::Placement::List ? long(sc.starts.size()) : sc.robot_count, "robot"),
             sc.exploration.strategy, sc.localization, range, sc.seed);
  if (sc.placement != sim::Placement::List && !sc.cluster_at && !sc.starts.empty()) {
    // The default placement, said once: where it put the robots and how to choose instead.
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : sc.starts) mean += p.position() / double(sc.starts.size());
    fmt::print("robots start {}, in the largest region a robot can reach (the default; --cluster-at x,y or --start x,y "
               "to choose)\n",
               sc.placement == sim::Placement::Random ? "at random places" : "packed around " + core::format_point(mean));
  }
  fmt::print("explored {} of the observable space in {} ({}); {}, {}\n", format_percent(result.coverage.back()),
             counted(result.steps, "step"), result.finished ? "no reachable frontier left" : "step limit reached",
             level_text("95%", result.steps_to_95), level_text("99%", result.steps_to_99));
  if (result.coverage.back() < 0.99 && !result.unexplored.empty()) {
    // Why the run ended short, for the largest region left (metrics.json lists more).
    double area = 0.0;
    for (const auto& u : result.unexplored) area += u.area_m2;
    const auto& big = result.unexplored.front();
    fmt::print("left unexplored: {:.2f} m2 in {}; the largest, {:.2f} m2 at {}: {}\n", area,
               counted(long(result.unexplored.size()), "region"), big.area_m2, core::format_point(big.centre_m), big.reason);
  }
  fmt::print("travelled {:.1f} m in all, redundancy {:.2f}, {} bytes sent in {}, {:.2f} s\n", distance,
             result.redundancy, result.bytes_sent, counted(result.meetings, "meeting"), result.timing.total);
  // How well the robots knew where they were, and what that did to the map.
  const sim::RunTotals totals = sim::run_totals(result);
  const auto& q = result.map_quality;
  fmt::print("{}map against the truth: {:.2f}% of its known cells wrong, walls {:.3f} m from the true walls on average\n",
             sc.localization == "ideal" ? ""
                                        : fmt::format("localization error (RMSE over robots) {:.3f} m; ", totals.position_rmse_m),
             100.0 * q.wrong_cell_share, q.mean_wall_distance_m);
  if (sc.merging == "none") {
    fmt::print("merging (none): every robot mapped alone, in its own frame (robot_<k>.yaml; fleetmap merge joins them)\n");
  } else if (sc.merging != "known") {
    int made = 0;
    double worst_deg = 0.0, worst_m = 0.0;
    const sim::MergeRecord* worst = nullptr;
    for (const auto& m : result.merges) {
      if (!m.merged) continue;
      ++made;
      worst_deg = std::max(worst_deg, m.rotation_error_deg);
      if (!worst || m.position_error_m > worst_m) worst_m = m.position_error_m, worst = &m;
    }
    const long refused = long(result.merges.size()) - made;
    if (made == 0) {
      fmt::print("merging ({}): no merge made, {} refused\n", sc.merging, refused);
    } else {
      fmt::print("merging ({}): {} made, {} refused; worst error against the truth {:.2f} deg, {:.3f} m (robot {} into "
                 "robot {}'s map at step {})\n",
                 sc.merging, counted(made, "merge"), refused, worst_deg, worst_m, worst->sender + 1, worst->receiver + 1,
                 worst->step);
    }
  }
}

// A plan after the run (--plan-from/--plan-to): its endpoints are checked before the run starts.
struct PlanRequest {
  Eigen::Vector2d from, to;
  std::string planner;
  double time_s = 1.0;
};

std::optional<PlanRequest> plan_request(const ExploreFlags& f) {
  if (f.plan_from.empty() != f.plan_to.empty()) throw InputError("--plan-from and --plan-to go together: give both");
  if (f.plan_from.empty()) return std::nullopt;
  planning::make_planner(f.planner);  // an unknown planner is refused before the run
  const auto point = [](const std::string& flag, const std::string& text) {
    const auto p = parse_pair(text);
    if (!p) throw InputError(flag + " '" + text + "': expected x,y in metres, e.g. 2.5,4");
    return Eigen::Vector2d(p->first, p->second);
  };
  return PlanRequest{point("--plan-from", f.plan_from), point("--plan-to", f.plan_to), f.planner, f.plan_time};
}

// Plans on the run's merged map and adds the path and its ends to `extra` (for merged.png).
planning::PlanResult plan_on(const sim::RunResult& result, const PlanRequest& request, const sim::Scenario& s,
                             viz::Overlays& extra) {
  planning::PlanPathOptions o;
  o.planner = request.planner;
  o.space.robot_radius_m = s.robot.radius_m;
  o.search.time_budget_s = request.time_s;
  o.search.seed = s.seed;
  const planning::PlanResult plan = planning::plan_path(result.merged, request.from, request.to, o);
  if (plan.success()) {
    extra.paths.push_back(
        {plan.path, {20, 20, 20}, fmt::format("{} path on the merged map, {:.2f} m", plan.planner, plan.length_m), 3, false});
  }
  extra.poses.push_back({{request.from.x(), request.from.y(), 0.0}, s.robot.radius_m, {44, 160, 44}, "plan start"});
  extra.poses.push_back({{request.to.x(), request.to.y(), 0.0}, s.robot.radius_m, {214, 39, 40}, "plan goal"});
  return plan;
}

// Where a run's outputs go, the files it will write and the inputs they must not overwrite.
struct ExploreOutputs {
  std::string label;  // the map's name
  fs::path out;
  std::string video_name;  // "" for none
  std::vector<std::string> files;
  std::vector<fs::path> inputs;
};

ExploreOutputs explore_outputs(const ExploreFlags& f, const sim::Scenario& s, bool plan) {
  ExploreOutputs o;
  o.label = maps::is_builtin_map(s.map) ? s.map : fs::path(s.map).stem().string();
  o.out = f.out.empty() ? fs::path("out") / o.label : fs::path(f.out);
  o.inputs = maps::map_source_files(s.map);
  if (!f.scenario.empty()) o.inputs.push_back(f.scenario);
  o.files = sim::run_output_files(s);
  if (plan) o.files.push_back("path.json");
  o.video_name = !f.video.empty() ? f.video : f.animate ? "run.mp4" : "";
  if (!o.video_name.empty()) {
    const auto& ext = sim::video_extensions();
    if (fs::path(o.video_name).filename() != o.video_name ||
        std::find(ext.begin(), ext.end(), fs::path(o.video_name).extension().string()) == ext.end()) {
      throw InputError("--video " + o.video_name + ": give a file name (no folder) ending in .mp4 (H.264) or .webm (VP9)");
    }
    o.files.push_back(o.video_name);
  }
  return o;
}

io::MapLoadOptions truth_load_options(const ExploreFlags& f, const sim::Scenario& s) {
  io::MapLoadOptions load;
  load.max_cells = f.max_cells;
  load.default_resolution = s.map_resolution_m;
  return load;
}

// The true map; one with no free cell is refused.
mapping::OccupancyGrid load_truth(const ExploreFlags& f, const sim::Scenario& s) {
  const io::MapLoadOptions load = truth_load_options(f, s);
  mapping::OccupancyGrid truth;
  try {
    truth = maps::load_map_source(s.map, load);
  } catch (const InputError& e) {
    if (f.map || f.scenario.empty()) throw;
    throw InputError(f.scenario + ": map: " + e.what());  // the map the scenario names
  }
  bool any_free = false;
  for (int i = 0; i < truth.width() * truth.height() && !any_free; ++i) any_free = truth.state_at(i) == mapping::CellState::Free;
  if (!any_free) {
    throw InputError(s.map + ": the map has no free cell: nowhere for a robot to start" +
                     map_notes_suffix(s.map, load, f.resolution || !f.scenario.empty()));
  }
  return truth;
}

// A plan that failed: the run's outputs are written; the plan's problem gets one line, and the
// exit code says which (2: a bad point, 1: no path).
int plan_exit_code(const ExploreFlags& f, const std::optional<planning::PlanResult>& plan) {
  if (!plan || plan->success()) return 0;
  using planning::PlanStatus;
  const bool bad_point = plan->status == PlanStatus::StartOutsideMap || plan->status == PlanStatus::StartInObstacle ||
                         plan->status == PlanStatus::GoalOutsideMap || plan->status == PlanStatus::GoalInObstacle;
  const bool at_start = plan->status == PlanStatus::StartOutsideMap || plan->status == PlanStatus::StartInObstacle;
  fmt::print(stderr, "fleetmap: {}: no path on the merged map: {}\n",
             bad_point ? (at_start ? "--plan-from " + f.plan_from : "--plan-to " + f.plan_to) : "--plan-from/--plan-to",
             plan->detail);
  return bad_point ? 2 : 1;
}

// Debug (--merge-attempts): the two maps of every merge attempt, as the aligner saw them, and
// attempts.csv; a folder of its own, since how many attempts a run makes is known only at its end.
class MergeAttempts {
 public:
  MergeAttempts(const fs::path& dir, const fs::path& out, const std::vector<fs::path>& inputs)
      : folder_(checked(dir, out), "explore --merge-attempts", {"attempts.csv"}, inputs,
                "--merge-attempts " + dir.string()) {}

  void claim() { folder_.claim(); }

  void add(const sim::MergeRecord& m, const mapping::OccupancyGrid& receiver, const mapping::OccupancyGrid& sender) {
    const std::string stem = fmt::format("step{:05d}_robot{}_robot{}", m.step, m.receiver + 1, m.sender + 1);
    const std::string rname = stem + "_receiver", sname = stem + "_sender";
    for (const auto& [name, map] : {std::pair{rname, &receiver}, std::pair{sname, &sender}}) {
      io::save_map_yaml(*map, folder_.dir() / (name + ".yaml"));
      files_.push_back(name + ".yaml");
      files_.push_back(name + ".pgm");
    }
    std::string reason = m.reason;
    std::replace(reason.begin(), reason.end(), '"', '\'');
    csv_ += fmt::format("{},{},{},{},{},{:.4f},{:.3f},{:.4f},{}.yaml,{}.yaml,\"{}\"\n", m.step, m.receiver + 1,
                        m.sender + 1, m.method, int(m.merged), m.confidence, m.rotation_error_deg, m.position_error_m,
                        rname, sname, reason);
  }

  void finish() {
    io::write_file_atomic(folder_.dir() / "attempts.csv", csv_);
    files_.push_back("attempts.csv");
    folder_.finish(files_);
  }

 private:
  static const fs::path& checked(const fs::path& dir, const fs::path& out) {
    if (fs::weakly_canonical(dir) == fs::weakly_canonical(out))
      throw InputError("--merge-attempts " + dir.string() + ": give a folder other than --out");
    return dir;
  }

  io::OutputFolder folder_;
  std::vector<std::string> files_;
  std::string csv_ =
      "step,receiver,sender,method,merged,confidence,rotation_error_deg,position_error_m,receiver_map,sender_map,reason\n";
};

int run_explore(const ExploreFlags& f) {
  sim::Scenario s = scenario_from(f);
  const std::optional<PlanRequest> request = plan_request(f);

  // Every output is checked before anything is read or run; nothing is written on bad input.
  const ExploreOutputs o = explore_outputs(f, s, request.has_value());
  const std::string& label = o.label;
  const fs::path& out = o.out;
  const std::string& video_name = o.video_name;
  io::OutputFolder folder(out, "explore", o.files, o.inputs, "--out " + out.string());
  std::optional<MergeAttempts> attempts;
  if (!f.merge_attempts.empty()) attempts.emplace(f.merge_attempts, out, o.inputs);
  auto truth = load_truth(f, s);

  // Placing the robots is where a scenario meets its map: errors name the scenario, or the map.
  std::optional<sim::Simulation> made;
  sim::SimulationSetup setup;
  if (attempts) {
    setup.on_merge_attempt = [&](const sim::MergeRecord& m, const mapping::OccupancyGrid& receiver,
                                 const mapping::OccupancyGrid& sender) { attempts->add(m, receiver, sender); };
  }
  try {
    made.emplace(s, std::move(truth), std::move(setup));
  } catch (const InputError& e) {
    throw InputError((f.scenario.empty() ? s.map : f.scenario) + ": " + e.what() +
                     map_notes_suffix(s.map, truth_load_options(f, s), f.resolution || !f.scenario.empty()));
  }
  // The input is good: how the map was read, said before the run.
  print_map_notes(s.map, truth_load_options(f, s), f.resolution || !f.scenario.empty());
  folder.claim();
  if (attempts) attempts->claim();
  sim::Simulation& simulation = *made;
  ProgressBar bar(!f.quiet);
  std::unique_ptr<sim::RunVideo> video;
  if (!video_name.empty()) video = std::make_unique<sim::RunVideo>(out / video_name);
  std::optional<sim::RunReplay> replay;
  if (s.html_replay) replay.emplace();
  const sim::RunResult result = simulation.run(
      [&](int step, int limit, double coverage) { bar.update(step, limit, "coverage " + format_percent(coverage)); },
      [&](const sim::Simulation& sim) {
        if (video) video->add_frame(sim, label);
        if (replay) replay->add_step(sim);
      });
  bar.finish();

  // The plan on the merged map, drawn on merged.png and written to path.json.
  viz::Overlays extra;
  const std::optional<planning::PlanResult> plan = request ? std::optional(plan_on(result, *request, s, extra)) : std::nullopt;
  auto written = sim::write_run_outputs(result, label, out, extra);
  if (plan) {
    io::write_file_atomic(out / "path.json",
                            plan_json(*plan, {label, request->from, request->to, s.robot.radius_m, "obstacle", f.plan_time, s.seed})
                                    .dump(2) +
                                "\n");
    written.push_back(out / "path.json");
  }
  if (replay) {
    io::write_file_atomic(out / "replay.html", replay->html(result, label));
    written.push_back(out / "replay.html");
  }
  if (video) {
    video->finish();
    written.push_back(out / video_name);
    if (!video->fallback_note().empty()) fmt::print(stderr, "fleetmap: {}: {}\n", video_name, video->fallback_note());
  }
  folder.finish(io::OutputFolder::names(written));
  if (attempts) attempts->finish();
  if (const std::string warning = sim::reachable_space_warning(result); !warning.empty()) {
    fmt::print(stderr, "fleetmap: warning: {}: {} (metrics.json: space)\n", label, warning);
  }
  if (f.quiet) {
    fmt::print("{}\n", (out / "merged.png").string());
    return plan_exit_code(f, plan);
  }
  print_summary(result, label);
  if (plan && plan->success()) {
    fmt::print("planned on the merged map ({}): {:.2f} m in {} waypoints, {:.3f} s\n", plan->planner, plan->length_m,
               plan->path.size(), plan->time_s);
  }
  fmt::print("merged map: {}\n", (out / "merged.png").string());
  std::string names;
  for (const auto& p : written) names += " " + p.filename().string();
  fmt::print("all outputs in {}/:{}\n", out.string(), names);
  return plan_exit_code(f, plan);
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
      "\nMerging (--merging): how robots bring each other's maps into their own frame (all but known: each "
      "robot maps in its own frame until it merges)\n" +
      merging::map_aligner_registry().help() +
      "\nMerge methods (overlap's merging.method), their parameters set as merging.METHOD.KEY:\n" +
      merging::merge_method_help() +
      "\nPath planners (--path-planner): wave (the wave's steepest descent, the default) or\n" + planning::planner_help() +
      "\nEvery parameter line above is set by --set FAMILY.KEY=VALUE (strategy, localization, merging, planner;\n"
      "merging.grid, merging.features for the merge methods).\n");
  auto f = std::make_shared<ExploreFlags>();
  app->add_option("--scenario", f->scenario, "Scenario YAML file (see scenarios/); flags below override it")
      ->check(CLI::ExistingFile);
  app->add_option("--map", f->map, "Built-in map name, image or map_server YAML [default: office]");
  app->add_option("--resolution", f->resolution,
                  "Metres per cell of a bare image map (PNG/PGM without YAML; a map_server YAML has its own) [default: 0.05]")
      ->check(in_range(io::kResolutionRange));
  app->add_option("--robots", f->robots, "Number of robots, placed as --starts says [default: 4]")
      ->check(in_range(sim::limits::kRobots));
  app->add_option("--starts", f->starts,
                 "Where robots start: cluster (packed together) or random (anywhere in the region, --min-separation "
                 "apart, random headings); both in the largest region a robot can reach, or in the one around "
                 "--cluster-at [default: cluster]")
      ->check(one_of({"cluster", "random"}));
  app->add_option("--start", f->start,
                  "Where a robot starts: x,y or x,y,heading (metres in the map's frame, degrees); once per robot, "
                  "e.g. --start 2,3 --start 4,3,90 (instead of --robots and --starts)")
      ->expected(1)
      ->take_all();
  app->add_option("--cluster-at", f->cluster_at,
                  "Pack the robots (or, with --starts random, choose their region) around x,y in metres "
                  "[default: nearest the map's centre in the largest region a robot can reach]");
  app->add_option("--min-separation", f->min_separation,
                  "Least distance between robot centres at the start, metres [default: 0.6; try 4 with --starts random]")
      ->check(in_range(sim::limits::kSeparation));
  app->add_option("--strategy", f->strategy, "Coordination strategy [default: directional]")
      ->check(one_of(exploration::strategy_names()));
  app->add_option("--set", f->set,
                  "A parameter of the strategy, the localizer, the path planner, the aligner or a merge method, "
                  "FAMILY.KEY=VALUE (repeat for more), e.g. --set strategy.beta=0.5 --set localization.particles=50 --set "
                  "merging.method=features --set merging.features.ratio=0.7; each member's parameters and defaults are "
                  "listed below and by `fleetmap plugins`")
      ->expected(1)
      ->take_all();
  app->add_option("--localization", f->localization, "How robots know their pose [default: ideal]")
      ->check(one_of(localization::localizer_names()));
  app->add_option("--merging", f->merging, "How robots bring teammates' maps into their frame: " + core::join(sim::merging_names()) +
                      " (see below) [default: known]")
      ->check(one_of(sim::merging_names()));
  app->add_option("--comm-range", f->comm_range,
                  "Communication range in metres; 0 = only when robots see each other; inf = always [default: inf]")
      ->check(in_range(sim::limits::kCommRange));
  app->add_option("--steps", f->steps, "Step limit [default: 2000]")->check(in_range(sim::limits::kSteps));
  app->add_option("--seed", f->seed, "Random seed: the same seed gives the same run [default: 1]")->check(seed_number());
  app->add_option("--sensor-range", f->sensor_range, "Laser range in metres [default: 4]")
      ->check(in_range(sim::limits::kSensorRange));
  app->add_option("--beams", f->beams, "Laser beams over 360 degrees [default: 360]")->check(in_range(sim::limits::kBeams));
  app->add_option("--landmarks", f->landmarks,
                  "Point landmarks placed along the walls, per metre of wall, for --localization ekf, ekf-slam or fastslam2 "
                  "[default: 0]")
      ->check(in_range(sim::limits::kLandmarksPerMetre));
  app->add_option("--path-planner", f->path_planner,
                  "How robots get paths to targets: wave, or a planner of `fleetmap plan` (astar, rrtconnect, ...; "
                  "not prmstar, whose roadmap grows by wall-clock time, so runs would not repeat) [default: wave]")
      ->check(one_of(sim::path_planner_names()));
  app->add_option("--plan-from", f->plan_from, "After the run, plan from x,y (metres) on the merged map ...");
  app->add_option("--plan-to", f->plan_to, "... to x,y; the path goes on merged.png and into path.json");
  app->add_option("--planner", f->planner, "Planner for --plan-from/--plan-to (see `fleetmap plan --help`)")
      ->capture_default_str();
  app->add_option("--plan-time", f->plan_time, "Time budget of that plan, seconds")
      ->capture_default_str()
      ->check(in_range(planning::kTimeBudgetRange));
  app->add_option("--out,-o", f->out,
                  "Output folder: new, empty, or of an earlier explore run (its files are replaced) [default: out/<map>]");
  app->add_flag("--animate", f->animate, "Also write run.mp4 (H.264), a frame per step");
  app->add_flag("--html", f->html,
                "Also write replay.html: the run in a browser, from disk (timeline, play, each robot's map, "
                "targets, paths, frontiers, coverage and events, and why each robot chose its target: the strategy's "
                "candidates and their scores); a scenario asks for it with outputs: {html: true}; "
                "fleetmap replay-compare puts two runs' pages side by side");
  app->add_option("--video", f->video,
                  "Write the video under this name in --out: NAME.mp4 (H.264) or NAME.webm (VP9); implies --animate");
  app->add_option("--merge-attempts", f->merge_attempts,
                  "Debug: write the two maps of every merge attempt (map_server YAML, each in its robot's own frame, "
                  "named by step and robots) and attempts.csv to this folder; try one with `fleetmap merge`");
  app->add_flag("--quiet,-q", f->quiet, "Print only the merged map's path; no progress bar");
  app->add_option("--max-cells", f->max_cells, "Refuse maps with more cells than this")
      ->capture_default_str()
      ->check(in_range(kMaxCellsRange));
  return {app, [f]() { return run_explore(*f); }};
}

}  // namespace fleetmap::cli
