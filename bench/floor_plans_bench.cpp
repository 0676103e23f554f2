// Exploration on real maps: every strategy with 1, 3 and 6 robots on the HouseExpo floor plans
// (Li et al. 2019; 60 of them in ../shared/datasets/houseexpo/, 0.05 m per cell) or on real laser
// maps (bench/real_maps/), each run required to reach 99% of the observable space and to stop by
// itself. Prints, per strategy and team size, the runs below 99% or not finished, the efficiency
// (lower bound / steps to 99%) as mean with its 95% confidence interval and as median, the median
// ratio of the step a run ended at to the step it reached 99%, the median share of robot-steps
// blocked, per run what the explorer's approaches came to (targets reached, of them reached with
// the unseen cell still unseen; given up stalled or cut off; frontiers abandoned), and every run
// that fell short with what it left (metrics.json's "unexplored"). Exit
// status 1 when a run fell short, 2 on bad arguments. Results: bench/README.md, "## Real floor
// plans" and "## Exploring real laser maps".
//
//   fleetmap_bench_floor_plans [FOLDER | --list A.yaml,B.yaml,...] [--maps N] [--strategies all]
//                              [--robots 1,3,6] [--seeds 1] [--starts cluster|random] [--steps 2000] [--jobs 1]
//
// FOLDER holds <id>.yaml map_server maps (default: the dataset beside the source tree); --list
// names the maps instead (each at its own resolution); --maps N takes the first N in name order, to
// keep a run within minutes. --starts random places the robots at random in the largest region
// they can reach, 4 m apart where room allows (as `fleetmap explore --starts random
// --min-separation 4`).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/format.h"
#include "core/parallel.h"
#include "maps/builtin_maps.h"
#include "sim/simulation.h"
#include "sweep/lower_bound.h"
#include "sweep/statistics.h"
#include "sweep/sweep.h"

namespace fleetmap {
namespace {

struct Options {
  std::filesystem::path folder = std::filesystem::path(FLEETMAP_SOURCE_DIR) / ".." / "shared" / "datasets" / "houseexpo";
  std::size_t maps = 0;  // 0: all
  std::vector<std::string> strategies = exploration::strategy_names();
  std::vector<int> robots = {1, 3, 6};
  int seeds = 1;
  int jobs = 1;
  std::vector<std::filesystem::path> list;  // --list: these maps instead of the folder's
  bool random_starts = false;
  int steps = 2000;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw InputError(a + ": a value is missing");
      return argv[++i];
    };
    const auto count = [&](const std::string& v, int lo, int hi) {
      std::size_t used = 0;
      int n = 0;
      try {
        n = std::stoi(v, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != v.size() || n < lo || n > hi) throw InputError(fmt::format("{} {}: expected a whole number from {} to {}", a, v, lo, hi));
      return n;
    };
    if (a == "--maps") o.maps = std::size_t(count(value(), 1, 100000));
    else if (a == "--strategies") o.strategies = sweep::parse_strategy_list(value(), a);
    else if (a == "--robots") o.robots = sweep::parse_team_sizes(value(), a);
    else if (a == "--seeds") o.seeds = count(value(), 1, 1000);
    else if (a == "--jobs") o.jobs = count(value(), 1, 1024);
    else if (a == "--steps") o.steps = count(value(), 1, 10'000'000);
    else if (a == "--list") {
      for (const auto& item : core::split_list(value(), a)) o.list.emplace_back(item);
    } else if (a == "--starts") {
      const std::string v = value();
      if (v != "cluster" && v != "random") throw InputError(a + " " + v + ": expected cluster or random");
      o.random_starts = v == "random";
    }
    else if (!a.empty() && a[0] == '-') throw InputError(a + ": unknown option (see the comment at the top of floor_plans_bench.cpp)");
    else o.folder = a;
  }
  return o;
}

struct Run {
  std::string map, strategy;
  int robots = 0;
  std::uint64_t seed = 1;
  // Results.
  double coverage = 0.0;
  bool finished = false;
  std::optional<double> efficiency;
  std::optional<double> end_over_99;  // the step it ended at / the step it reached 99%
  double blocked_share = 0.0;         // blocked moves per robot-step
  std::string left;  // what a run that fell short left
  int steps = 0;
  std::optional<int> steps_to_99;
  exploration::TeamExplorer::Stats stats;
};

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int run(const Options& o) {
  std::vector<std::filesystem::path> plans = o.list;
  if (plans.empty()) {
    if (!std::filesystem::is_directory(o.folder)) throw InputError(o.folder.string() + ": not a folder");
    for (const auto& e : std::filesystem::directory_iterator(o.folder))
      if (e.path().extension() == ".yaml") plans.push_back(e.path());
  }
  std::sort(plans.begin(), plans.end());
  if (o.maps > 0 && plans.size() > o.maps) plans.resize(o.maps);
  if (plans.empty()) throw InputError(o.folder.string() + ": no .yaml map in it");
  std::map<std::string, mapping::OccupancyGrid> grids;
  for (const auto& p : plans) grids.emplace(p.stem().string(), maps::load_map_source(p.string()));

  std::vector<Run> runs;
  for (const auto& [map, grid] : grids)
    for (const auto& strategy : o.strategies)
      for (const int robots : o.robots)
        for (int s = 0; s < o.seeds; ++s) runs.push_back({map, strategy, robots, std::uint64_t(1 + s), 0.0, false, {}, {}, 0.0, {}, 0, {}, {}});
  int done = 0;
  const auto progress = [&](int) {
    if (++done % 25 == 0 || done == int(runs.size())) fmt::print(stderr, "{} of {} runs\n", done, runs.size());
  };
  core::parallel_for(int(runs.size()), o.jobs, [&](int k) {
    Run& r = runs[std::size_t(k)];
    sim::Scenario s;
    s.map = r.map;
    s.robot_count = r.robots;
    s.seed = r.seed;
    s.exploration.strategy = r.strategy;
    s.steps = o.steps;
    if (o.random_starts) s.placement = sim::Placement::Random, s.min_separation_m = 4.0;
    const mapping::OccupancyGrid& truth = grids.at(r.map);
    sim::Simulation simulation(s, truth);
    const sim::RunResult result = simulation.run();
    r.coverage = result.coverage.back();
    r.finished = result.finished;
    r.steps = result.steps;
    r.steps_to_99 = result.steps_to_99;
    r.stats = result.exploration;
    sweep::LowerBoundOptions lb;
    lb.sensor_range_m = s.range.max_range_m;
    lb.step_length_m = s.robot.max_speed_mps * s.period_s;
    lb.robot_radius_m = s.robot.radius_m;
    std::vector<Eigen::Vector2d> starts;
    for (const auto& t : result.robots) starts.push_back(t.truth.front().position());
    const sim::World world(truth, {});
    r.efficiency = sweep::exploration_efficiency(sweep::exploration_lower_bound(world, starts, lb).steps(), result.steps_to_99);
    if (result.steps_to_99 && *result.steps_to_99 > 0) r.end_over_99 = double(result.steps) / double(*result.steps_to_99);
    int blocked = 0;
    for (const auto& t : result.robots) blocked += t.blocked_moves;
    r.blocked_share = double(blocked) / (double(std::max(1, result.steps)) * double(result.robots.size()));
    if (!result.unexplored.empty() && (r.coverage < 0.99 || !r.finished)) {
      const auto& u = result.unexplored.front();
      r.left = fmt::format("largest region left {:.2f} m2 at ({:.1f}, {:.1f}): {}", u.area_m2, u.centre_m.x(), u.centre_m.y(), u.reason);
    }
  }, progress);

  int short_runs = 0;
  fmt::print("| strategy | robots | runs | below 99% or not finished | lowest coverage | efficiency (mean, 95% CI) | "
             "efficiency (median) | end / step of 99% (median) | blocked share (median) |\n|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& strategy : o.strategies) {
    for (const int robots : o.robots) {
      std::vector<double> efficiency, end_ratio, blocked;
      int n = 0, bad = 0;
      double lowest = 2.0;
      std::string lowest_map;
      for (const auto& r : runs) {
        if (r.strategy != strategy || r.robots != robots) continue;
        ++n;
        bad += r.coverage < 0.99 || !r.finished;
        if (r.coverage < lowest) lowest = r.coverage, lowest_map = r.map;
        efficiency.push_back(r.efficiency.value_or(0.0));  // a run that never reached 99% counts as 0
        if (r.end_over_99) end_ratio.push_back(*r.end_over_99);
        blocked.push_back(r.blocked_share);
      }
      short_runs += bad;
      const auto e = sweep::summarize(efficiency);
      fmt::print("| {} | {} | {} | {} | {:.2f}% ({}) | {:.3f} [{:.3f}, {:.3f}] | {:.3f} | {:.2f} | {:.3f} |\n", strategy, robots, n,
                 bad, 100.0 * lowest, lowest_map, e.mean, e.ci_low, e.ci_high, median(efficiency), median(end_ratio),
                 median(blocked));
    }
  }
  // Per run: what the explorer did (reached targets, of them unobservable; given up stalled / cut off).
  for (const auto& r : runs) {
    fmt::print("run: {} {} {} robots seed {}: {:.2f}%{}, 99% at {}, efficiency {:.3f}, targets reached {} (unobservable {}), "
               "given up {} (stalled {}, cut off {}), abandoned {}\n",
               r.map, r.strategy, r.robots, r.seed, 100.0 * r.coverage, r.finished ? fmt::format(", ended at {}", r.steps) : ", step limit",
               r.steps_to_99 ? std::to_string(*r.steps_to_99) : std::string("-"), r.efficiency.value_or(0.0),
               r.stats.targets_reached, r.stats.unobservable, r.stats.targets_given_up, r.stats.given_up_stalled,
               r.stats.given_up_unreachable, r.stats.frontiers_abandoned);
  }
  for (const auto& r : runs) {
    if (r.coverage >= 0.99 && r.finished) continue;
    fmt::print("short: {} {} {} robots seed {}: {:.2f}%{}; {}\n", r.map, r.strategy, r.robots, r.seed, 100.0 * r.coverage,
               r.finished ? "" : ", step limit", r.left);
  }
  fmt::print("{} runs on {} plans, {} below 99% of the observable space or not finished\n", runs.size(), plans.size(), short_runs);
  return short_runs == 0 ? 0 : 1;
}

}  // namespace
}  // namespace fleetmap

int main(int argc, char** argv) {
  try {
    return fleetmap::run(fleetmap::parse(argc, argv));
  } catch (const fleetmap::InputError& e) {
    fmt::print(stderr, "fleetmap_bench_floor_plans: {}\n", e.what());
    return 2;
  }
}
