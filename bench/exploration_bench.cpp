// Exploration benchmarks. Results: bench/README.md, "## Exploration".
//
// wave/...: one compute_wave on the built-in "campus" map (1200x1200) over the cells a 0.2 m robot
// may enter (traversable_cells with default options), into one WaveField reused across
// iterations, from one source (the traversable cell nearest the centre) or nine (the traversable
// cells nearest the points of a 3x3 lattice at the quarters of the map). Variants: 4-connected
// (BFS), 8-connected (Dial's buckets), 8-connected with occupancy_weight 2 (per-cell P(occ) from
// the map's log-odds). Counters: cells reached per wave, cells reached per second.
//
// explore/MAP/STRATEGY: one whole 9-robot run (Simulation construction, which takes the first
// readings, and run()) with the default scenario on each 200x200 built-in map and every strategy.
// A run is deterministic for its seed, so one iteration is timed. Counters: steps to 99% coverage
// (-1: never reached), steps run, wall milliseconds per step, final coverage, whether every robot
// finished before the step limit, waves computed by the explorer, and the share of the step loop's
// time spent deciding (TeamExplorer::update: waves, frontiers, assignment).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdint>
#include <limits>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "exploration/strategy.h"
#include "exploration/traversability.h"
#include "exploration/wave.h"
#include "maps/builtin_maps.h"
#include "mapping/occupancy_grid.h"
#include "sim/scenario.h"
#include "sim/simulation.h"

namespace fleetmap::exploration {
namespace {

constexpr int kRobots = 9;

struct WaveCase {
  mapping::OccupancyGrid truth;
  std::vector<std::uint8_t> passable;
  std::vector<float> occupancy;  // P(occ) per cell
  std::vector<Cell> one_source;
  std::vector<Cell> nine_sources;
};

// The passable cell nearest to `target` (squared Euclidean distance in cells).
Cell nearest_passable(const std::vector<std::uint8_t>& passable, int width, int height, const Cell& target) {
  Cell best = target;
  std::int64_t best_d2 = std::numeric_limits<std::int64_t>::max();
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      if (!passable[std::size_t(y * width + x)]) continue;
      const std::int64_t dx = x - target.x, dy = y - target.y;
      if (dx * dx + dy * dy < best_d2) {
        best_d2 = dx * dx + dy * dy;
        best = {x, y};
      }
    }
  return best;
}

const WaveCase& campus() {
  static const WaveCase c = [] {
    WaveCase w;
    w.truth = maps::load_map_source("campus");
    w.passable = traversable_cells(w.truth, TraversabilityOptions{});
    w.occupancy.resize(w.passable.size());
    for (std::size_t i = 0; i < w.occupancy.size(); ++i)
      w.occupancy[i] = float(mapping::log_odds_to_probability(w.truth.log_odds_at(int(i))));
    const int width = w.truth.width(), height = w.truth.height();
    w.one_source.push_back(nearest_passable(w.passable, width, height, {width / 2, height / 2}));
    for (int j = 1; j <= 3; ++j)
      for (int i = 1; i <= 3; ++i)
        w.nine_sources.push_back(nearest_passable(w.passable, width, height, {width * i / 4, height * j / 4}));
    return w;
  }();
  return c;
}

void wave_benchmark(benchmark::State& state, const WaveOptions& options, bool weighted, int sources) {
  const WaveCase& c = campus();
  const WaveGrid grid{c.truth.width(), c.truth.height(), c.passable,
                      weighted ? std::span<const float>(c.occupancy) : std::span<const float>(), {}};
  const std::span<const Cell> from = sources == 1 ? std::span<const Cell>(c.one_source) : std::span<const Cell>(c.nine_sources);
  WaveField field;
  compute_wave(grid, from, options, field);  // sizes the reused storage
  for (auto _ : state) {
    compute_wave(grid, from, options, field);
    benchmark::DoNotOptimize(field.costs().data());
    benchmark::ClobberMemory();
  }
  const double reached = double(field.reached_count());
  state.counters["cells_reached"] = reached;
  state.counters["cells_per_s"] = benchmark::Counter(reached * double(state.iterations()), benchmark::Counter::kIsRate);
}

const mapping::OccupancyGrid& builtin(const std::string& name) {
  static std::map<std::string, mapping::OccupancyGrid> grids;
  auto it = grids.find(name);
  if (it == grids.end()) it = grids.emplace(name, maps::load_map_source(name)).first;
  return it->second;
}

void explore_benchmark(benchmark::State& state, const std::string& map, const std::string& strategy) {
  const mapping::OccupancyGrid& truth = builtin(map);
  sim::Scenario scenario;
  scenario.map = map;
  scenario.robot_count = kRobots;
  scenario.exploration.strategy = strategy;
  sim::RunResult result;
  double wall_ms = 0.0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    sim::Simulation simulation(scenario, truth);
    result = simulation.run();
    wall_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  const double runs = double(state.iterations());
  state.counters["steps_to_99"] = result.steps_to_99 ? double(*result.steps_to_99) : -1.0;
  state.counters["steps"] = double(result.steps);
  state.counters["ms_per_step"] = result.steps > 0 ? wall_ms / runs / double(result.steps) : 0.0;
  state.counters["coverage"] = result.coverage.empty() ? 0.0 : result.coverage.back();
  state.counters["finished"] = result.finished ? 1.0 : 0.0;
  state.counters["waves"] = double(result.exploration.waves);
  state.counters["decide_share"] = result.timing.total > 0.0 ? result.timing.exploration / result.timing.total : 0.0;
}

void register_benchmarks() {
  struct Variant {
    const char* name;
    WaveOptions options;
    bool weighted;
  };
  const Variant variants[] = {
      {"4-connected", WaveOptions{.eight_connected = false, .occupancy_weight = 0.0}, false},
      {"8-connected", WaveOptions{.eight_connected = true, .occupancy_weight = 0.0}, false},
      {"8-connected_weight2", WaveOptions{.eight_connected = true, .occupancy_weight = 2.0}, true},
  };
  for (const Variant& v : variants)
    for (const int sources : {1, 9})
      benchmark::RegisterBenchmark(("wave/campus/" + std::string(v.name) + "/sources:" + std::to_string(sources)).c_str(),
                                   [v, sources](benchmark::State& state) { wave_benchmark(state, v.options, v.weighted, sources); })
          ->Unit(benchmark::kMillisecond)
          ->Repetitions(5)
          ->ReportAggregatesOnly(true);

  for (const char* map : {"empty", "unstructured", "office", "corridor", "cave", "maze"})
    for (const std::string& strategy : strategy_names())
      benchmark::RegisterBenchmark(("explore/" + std::string(map) + "/" + strategy).c_str(),
                                   [map = std::string(map), strategy](benchmark::State& state) {
                                     explore_benchmark(state, map, strategy);
                                   })
          ->Iterations(1)
          ->UseRealTime()
          ->Unit(benchmark::kMillisecond);
}

}  // namespace
}  // namespace fleetmap::exploration

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  fleetmap::exploration::register_benchmarks();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
