// Decision time of the coordination strategies, the `tour` strategy's above all. Results:
// bench/README.md, "## Tour strategy: decision time".
//
// decide/MAP/ROBOTS/STRATEGY: one decision round of a team in mid-exploration. A run of the default
// scenario (ideal localization, 4 m laser, unlimited communication, `tour`) is stepped to a fixed
// step (office: 20 of its about 80 steps to 99%; campus: 150 steps); its robots' maps and poses are
// the input. Each iteration builds a fresh TeamExplorer with the timed strategy and runs one
// update(): every robot needs a target, so the whole team is assigned at once (its waves, the
// frontier targets, and the strategy: for `tour` also the costs between targets and the tours).
// Counters: the waves the round computed (one per robot, and for `tour` one more, labelled, for the
// costs between targets) and how many robots got a target. `coordinated` and `market` from the same
// state show what the round costs without tours.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "exploration/team_explorer.h"
#include "maps/builtin_maps.h"
#include "sim/scenario.h"
#include "sim/simulation.h"

namespace fleetmap::exploration {
namespace {

struct Snapshot {
  std::vector<mapping::OccupancyGrid> maps;
  std::vector<core::Pose2> poses;
};

const Snapshot& snapshot(const std::string& map, int robots, int steps) {
  static std::map<std::string, Snapshot> cache;
  const std::string key = map + "/" + std::to_string(robots) + "/" + std::to_string(steps);
  auto it = cache.find(key);
  if (it != cache.end()) return it->second;
  sim::Scenario scenario;
  scenario.map = map;
  scenario.robot_count = robots;
  scenario.exploration.strategy = "tour";
  sim::Simulation simulation(scenario, maps::load_map_source(map));
  for (int s = 0; s < steps && !simulation.done(); ++s) simulation.step();
  Snapshot shot;
  for (int i = 0; i < robots; ++i) shot.maps.push_back(simulation.robot_map(i));
  shot.poses = simulation.estimated_poses();
  return cache.emplace(key, std::move(shot)).first->second;
}

void decide_benchmark(benchmark::State& state, const std::string& map, int robots, int steps, const std::string& strategy) {
  const Snapshot& shot = snapshot(map, robots, steps);
  std::vector<ExplorerRobot> team;
  for (int i = 0; i < robots; ++i) {
    ExplorerRobot r;
    r.map = &shot.maps[std::size_t(i)];
    r.pose = shot.poses[std::size_t(i)];
    team.push_back(r);
  }
  const std::vector<std::vector<char>> links(std::size_t(robots), std::vector<char>(std::size_t(robots), 1));
  // The options the simulator gives the default scenario's explorer (sensor range 4 m, radius 0.2 m):
  // the defaults, with goals up to the range less two planning cells.
  ExplorationOptions options;
  options.strategy = strategy;
  options.targets.max_observe_range_m = 4.0 - 2.0 * options.planning_resolution_m;
  int waves = 0, busy = 0;
  for (auto _ : state) {
    TeamExplorer explorer(robots, options);
    explorer.update(team, links);
    waves = explorer.stats().waves;
    busy = 0;
    for (int i = 0; i < robots; ++i) busy += explorer.goal(i).has_value();
    benchmark::DoNotOptimize(busy);
  }
  state.counters["waves"] = waves;
  state.counters["robots_with_target"] = busy;
}

const bool registered = [] {
  for (const std::string strategy : {"tour", "coordinated", "market"}) {
    benchmark::RegisterBenchmark(("decide/office/9/" + strategy).c_str(), decide_benchmark, "office", 9, 20, strategy)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("decide/campus/16/" + strategy).c_str(), decide_benchmark, "campus", 16, 150, strategy)
        ->Unit(benchmark::kMillisecond)
        ->Iterations(5);
  }
  return true;
}();

}  // namespace
}  // namespace fleetmap::exploration

BENCHMARK_MAIN();
