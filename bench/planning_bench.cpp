// Path planning on every built-in map: for each map, 50 random start/goal pairs (seeded; valid
// for a 0.2 m robot, joined by free space, at least a quarter of the map's shorter side apart);
// for each planner and budget (0.1, 0.5, 2 s) one benchmark that plans every pair once.
// Counters: success rate, mean time to the first solution and mean path length divided by the
// grid optimum (the shortest 8-connected grid path, A* unsmoothed), both over the successes.
// Results: bench/README.md, "## Planning".
//
// Own flags (before Google Benchmark's): --pairs=N (50), --budgets=0.1,0.5,2, --maps=a,b (all),
// --planners=a,b (all), --markdown=FILE (also write the summary tables there).
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <tuple>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "io/file_io.h"
#include "core/random.h"
#include "maps/builtin_maps.h"
#include "planning/grid_astar.h"
#include "planning/planner.h"

namespace fleetmap::planning {
namespace {

constexpr double kRadius = 0.2;

struct Pair {
  Eigen::Vector2d start, goal;
  double grid_optimum_m = 0.0;
};

struct MapCase {
  std::string name;
  std::unique_ptr<mapping::OccupancyGrid> grid;
  std::unique_ptr<FreeSpace> space;
  std::vector<Pair> pairs;
};

struct Row {
  std::string map, planner;
  double budget = 0.0;
  int runs = 0, successes = 0;
  double first_s = 0.0, ratio = 0.0;  // means over the successes
};

std::vector<Row>& rows() {
  static std::vector<Row> r;
  return r;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

// Seeded pairs of valid points in one region of free space, with their grid optimum.
std::vector<Pair> random_pairs(const FreeSpace& space, int count, std::uint64_t seed) {
  const GridGeometry& g = space.geometry();
  const double min_distance = 0.25 * std::min(g.width_m(), g.height_m());
  core::Random rng(seed);
  std::vector<Pair> pairs;
  for (int attempt = 0; static_cast<int>(pairs.size()) < count && attempt < 1'000'000; ++attempt) {
    const Eigen::Vector2d a(rng.uniform(0, g.width_m()), rng.uniform(0, g.height_m()));
    const Eigen::Vector2d b(rng.uniform(0, g.width_m()), rng.uniform(0, g.height_m()));
    if (!space.valid(a) || !space.valid(b) || (a - b).norm() < min_distance) continue;
    const Cell ca = *g.world_to_cell(a), cb = *g.world_to_cell(b);
    if (!space.connected(ca, cb)) continue;
    const GridSearch optimum = astar_grid(space, ca, cb);
    pairs.push_back({a, b, path_length(grid_path_waypoints(space, optimum.path, a, b))});
  }
  return pairs;
}

void run_case(benchmark::State& state, const MapCase* c, const std::string& planner_name, double budget) {
  auto planner = make_planner(planner_name);
  PlannerOptions options;
  options.time_budget_s = budget;
  Row row{c->name, planner_name, budget};
  std::size_t i = 0;
  for (auto _ : state) {
    const Pair& p = c->pairs[i % c->pairs.size()];
    options.seed = i + 1;
    const PlanResult r = planner->plan(*c->space, p.start, p.goal, options);
    state.SetIterationTime(r.time_s);
    ++row.runs;
    if (r.success()) {
      ++row.successes;
      row.first_s += r.first_solution_s.value_or(r.time_s);
      row.ratio += r.length_m / p.grid_optimum_m;
    }
    ++i;
  }
  if (row.successes > 0) {
    row.first_s /= row.successes;
    row.ratio /= row.successes;
  }
  state.counters["success"] = double(row.successes) / std::max(1, row.runs);
  state.counters["first_ms"] = 1e3 * row.first_s;
  state.counters["len_ratio"] = row.ratio;
  rows().push_back(row);
}

std::string format_cell(const Row& r) {
  if (r.successes == 0) return "0%";
  const double ms = 1e3 * r.first_s;
  return ms < 10 ? fmt::format("{:.0f}% · {:.1f} ms · {:.3f}", 100.0 * r.successes / r.runs, ms, r.ratio)
                 : fmt::format("{:.0f}% · {:.0f} ms · {:.3f}", 100.0 * r.successes / r.runs, ms, r.ratio);
}

// One table per budget: a row per planner, a column per map; each cell "success · first · ratio".
std::string markdown(const std::vector<std::string>& maps, const std::vector<std::string>& planners,
                     const std::vector<double>& budgets) {
  std::map<std::tuple<std::string, std::string, double>, Row> by_key;
  for (const Row& r : rows()) by_key[{r.map, r.planner, r.budget}] = r;
  std::string s;
  for (const double budget : budgets) {
    s += fmt::format("\nBudget {:g} s:\n\n", budget);
    s += "| planner |";
    for (const auto& m : maps) {
      s += ' ';
      s += m;
      s += " |";
    }
    s += "\n|---|";
    for (std::size_t k = 0; k < maps.size(); ++k) s += "---|";
    s += "\n";
    for (const auto& p : planners) {
      s += "| `";
      s += p;
      s += "` |";
      for (const auto& m : maps) {
        const auto it = by_key.find({m, p, budget});
        s += ' ';
        s += it == by_key.end() ? std::string("-") : format_cell(it->second);
        s += " |";
      }
      s += "\n";
    }
  }
  return s;
}

}  // namespace
}  // namespace fleetmap::planning

int main(int argc, char** argv) {
  namespace fp = fleetmap::planning;
  int pairs = 50;
  std::vector<double> budgets = {0.1, 0.5, 2.0};
  std::vector<std::string> maps, planners = fp::planner_names(), budget_words;
  std::string markdown_path;
  std::vector<char*> rest{argv[0]};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&](const char* flag) { return a.rfind(flag, 0) == 0 ? a.substr(std::string(flag).size()) : std::string(); };
    if (!value("--pairs=").empty()) pairs = std::atoi(value("--pairs=").c_str());
    else if (!value("--budgets=").empty()) {
      budgets.clear();
      for (const auto& b : fp::split(value("--budgets="))) budgets.push_back(std::atof(b.c_str()));
    } else if (!value("--maps=").empty()) maps = fp::split(value("--maps="));
    else if (!value("--planners=").empty()) planners = fp::split(value("--planners="));
    else if (!value("--markdown=").empty()) markdown_path = value("--markdown=");
    else rest.push_back(argv[i]);
  }
  if (maps.empty())
    for (const auto& info : fleetmap::maps::builtin_maps()) maps.push_back(info.name);

  std::vector<std::unique_ptr<fp::MapCase>> cases;
  for (std::size_t k = 0; k < maps.size(); ++k) {
    auto c = std::make_unique<fp::MapCase>();
    c->name = maps[k];
    c->grid = std::make_unique<fleetmap::mapping::OccupancyGrid>(fleetmap::maps::load_map_source(maps[k]));
    c->space = std::make_unique<fp::FreeSpace>(*c->grid, fp::FreeSpaceOptions{fp::kRadius, fp::UnknownCells::Obstacle});
    c->pairs = fp::random_pairs(*c->space, pairs, 1000 + k);
    for (const auto& planner : planners) {
      for (const double budget : budgets) {
        const std::string name = fmt::format("{}/{}/budget:{:g}s", maps[k], planner, budget);
        benchmark::RegisterBenchmark(name.c_str(), fp::run_case, c.get(), planner, budget)
            ->Iterations(static_cast<benchmark::IterationCount>(c->pairs.size()))
            ->UseManualTime()
            ->Unit(benchmark::kMillisecond);
      }
    }
    cases.push_back(std::move(c));
  }

  int rest_argc = static_cast<int>(rest.size());
  benchmark::Initialize(&rest_argc, rest.data());
  if (benchmark::ReportUnrecognizedArguments(rest_argc, rest.data())) return 2;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  const std::string tables = fp::markdown(maps, planners, budgets);
  std::fputs(tables.c_str(), stdout);
  if (!markdown_path.empty()) fleetmap::io::write_file_atomic(markdown_path, tables);
  return 0;
}
