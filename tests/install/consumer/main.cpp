// Registers a coordination strategy of its own, with a parameter of its own, explores a built-in map
// with it and writes the run's files into the folder given as its argument, through the installed
// headers and libraries only. Exit status 0 when the strategy ran and mapped the room, the files
// are there (the merged map read back has the run's cells), and its parameter reached it from a
// scenario file, from `--set`'s call and from each value of a sweep axis.
#include <fleetmap/core/transform2.h>
#include <fleetmap/exploration/strategy.h>
#include <fleetmap/io/map_io.h>
#include <fleetmap/maps/builtin_maps.h>
#include <fleetmap/sim/run_files.h>
#include <fleetmap/sim/scenario.h>
#include <fleetmap/sim/simulation.h>
#include <fleetmap/sweep/sweep.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>

namespace {

using namespace fleetmap;

int g_calls = 0;
std::vector<double> g_built_with;  // the `patience` of every strategy made, in order

// Every robot takes the reachable target with the lowest wave cost that no teammate took.
class CheapestFreeTarget final : public exploration::CoordinationStrategy {
 public:
  std::string name() const override { return "cheapest-free"; }
  bool joint() const override { return true; }
  std::vector<int> assign(const exploration::AssignmentInput& input) const override {
    ++g_calls;
    std::vector<int> out(input.robots.size(), -1);
    std::vector<char> taken(input.targets.size(), 0);
    for (std::size_t r = 0; r < input.robots.size(); ++r) {
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t t = 0; t < input.targets.size(); ++t) {
        const double cost = input.robots[r].cost_m[t];
        if (!taken[t] && std::isfinite(cost) && cost < best) best = cost, out[r] = int(t);
      }
      if (out[r] >= 0) taken[std::size_t(out[r])] = 1;
    }
    return out;
  }
};

}  // namespace

// The run's files: every name run_output_files promises, each non-empty; metrics.json names the
// map; map.yaml reads back as the merged map.
bool check_run_files(const sim::RunResult& result, const std::filesystem::path& dir) {
  const auto written = sim::write_run_outputs(result, "empty", dir);
  for (const std::string& name : sim::run_output_files(result.scenario)) {
    const auto path = dir / name;
    if (!std::filesystem::exists(path) || std::filesystem::file_size(path) == 0 ||
        std::find(written.begin(), written.end(), path) == written.end()) {
      std::cerr << "consumer: " << path << " was not written\n";
      return false;
    }
  }
  std::ifstream metrics(dir / "metrics.json");
  const std::string text((std::istreambuf_iterator<char>(metrics)), std::istreambuf_iterator<char>());
  if (text.find("\"map\": \"empty\"") == std::string::npos) {
    std::cerr << "consumer: metrics.json does not name the map\n";
    return false;
  }
  const mapping::OccupancyGrid back = io::load_map(dir / "map.yaml");
  if (back.width() != result.merged.width() || back.height() != result.merged.height()) {
    std::cerr << "consumer: map.yaml is " << back.width() << " x " << back.height() << ", the run's map "
              << result.merged.width() << " x " << result.merged.height() << "\n";
    return false;
  }
  std::cout << written.size() << " files written to " << dir << "\n";
  return true;
}

// The strategy's parameter reaches it from a scenario file, from set_parameter (what `--set
// strategy.patience=2` calls) and from every value of a `--vary strategy.patience=...` axis.
bool check_parameter() {
  const auto made_with = [](const sim::Scenario& s) {
    g_built_with.clear();
    exploration::make_strategy(s.exploration.strategy, s.exploration.strategy_settings);
    return g_built_with.size() == 1 ? g_built_with.front() : -1.0;
  };
  sim::Scenario from_file = sim::parse_scenario("exploration:\n  strategy: {name: cheapest-free, patience: 3}\n", "own.yaml", ".");
  if (made_with(from_file) != 3.0) return std::cerr << "consumer: patience from a scenario file not used\n", false;
  sim::Scenario set;
  set.exploration.strategy = "cheapest-free";
  sim::set_parameter(set, "strategy.patience=2", "--set strategy.patience=2");
  sim::validate_scenario(set);
  if (made_with(set) != 2.0) return std::cerr << "consumer: patience from --set not used\n", false;
  try {
    sim::set_parameter(set, "strategy.patience=-1", "--set strategy.patience=-1");
    sim::validate_scenario(set);
    return std::cerr << "consumer: patience -1 accepted\n", false;
  } catch (const InputError&) {
  }
  sweep::Sweep sweep;
  sweep.maps = {"empty"};
  sweep.strategies = {"cheapest-free"};
  sweep.robots = {1};
  sweep.seeds = 1;
  sweep.axes = {sweep::parse_axis("strategy.patience=4,5", "--vary")};
  std::vector<double> swept;
  for (const auto& run : sweep::sweep_runs(sweep)) swept.push_back(made_with(sweep::run_scenario(sweep, run)));
  if (swept != std::vector<double>{4.0, 5.0}) return std::cerr << "consumer: patience not swept\n", false;
  std::cout << "strategy cheapest-free: patience from a file, --set and a sweep axis\n";
  return true;
}

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: consumer OUTPUT_FOLDER\n";
    return 2;
  }
  // A core type straight from the installed headers.
  const core::Transform2 t = core::Pose2{1.0, 2.0, 0.5}.as_transform();
  if ((t.inverse() * t).translation().norm() > 1e-12) return 1;

  exploration::register_strategy(
      "cheapest-free", "each robot takes the cheapest target left (the consumer's own)",
      [](const exploration::StrategyOptions& options) {
        g_built_with.push_back(options.number("patience"));
        return std::make_unique<CheapestFreeTarget>();
      },
      {core::ParamSpec::number("patience", 1, {0, 10}, "rounds", "how long a robot waits for a better target")});
  if (!check_parameter()) return 1;
  sim::Scenario scenario;
  scenario.map = "empty";
  scenario.robot_count = 2;
  scenario.steps = 60;
  scenario.exploration.strategy = "cheapest-free";
  sim::Simulation simulation(scenario, maps::load_map_source(scenario.map));
  const sim::RunResult result = simulation.run();
  std::cout << "strategy cheapest-free: " << g_calls << " assignment rounds, coverage " << result.coverage.back()
            << " after " << result.steps << " steps\n";
  if (g_calls == 0 || result.coverage.back() <= result.coverage.front()) return 1;
  return check_run_files(result, argv[1]) ? 0 : 1;
}
