// Registers a coordination strategy of its own and explores a built-in map with it, through the
// installed headers and libraries only. Exit status 0 when the strategy ran and mapped the room.
#include <fleetmap/core/transform2.h>
#include <fleetmap/exploration/strategy.h>
#include <fleetmap/maps/builtin_maps.h>
#include <fleetmap/sim/scenario.h>
#include <fleetmap/sim/simulation.h>

#include <cmath>
#include <iostream>
#include <limits>
#include <memory>

namespace {

using namespace fleetmap;

int g_calls = 0;

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

int main() {
  // A core type straight from the installed headers.
  const core::Transform2 t = core::Pose2{1.0, 2.0, 0.5}.as_transform();
  if ((t.inverse() * t).translation().norm() > 1e-12) return 1;

  exploration::register_strategy("cheapest-free", "each robot takes the cheapest target left (the consumer's own)",
                                 [](const exploration::StrategyOptions&) { return std::make_unique<CheapestFreeTarget>(); });
  sim::Scenario scenario;
  scenario.map = "empty";
  scenario.robot_count = 2;
  scenario.steps = 60;
  scenario.exploration.strategy = "cheapest-free";
  sim::Simulation simulation(scenario, maps::load_map_source(scenario.map));
  const sim::RunResult result = simulation.run();
  std::cout << "strategy cheapest-free: " << g_calls << " assignment rounds, coverage " << result.coverage.back()
            << " after " << result.steps << " steps\n";
  return g_calls > 0 && result.coverage.back() > result.coverage.front() ? 0 : 1;
}
