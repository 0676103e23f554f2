#include "exploration/strategy.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "core/error.h"
#include "exploration/strategies.h"

namespace fleetmap::exploration {

namespace {

struct Entry {
  std::string name;
  std::string help;
  std::function<std::unique_ptr<CoordinationStrategy>(const StrategyOptions&)> make;
};

const std::vector<Entry>& registry() {
  static const std::vector<Entry> kEntries = {
      {"uncoordinated", "each robot to its nearest frontier by wave cost (Yamauchi 1998)", make_uncoordinated_strategy},
      {"coordinated",
       "greedy utility minus beta * cost, utility reduced around assigned targets (Burgard et al. 2005)",
       make_coordinated_strategy},
      {"optimized", "assignment minimising squared costs minus utility, solved exactly (seed 003 eq. (3), Hungarian)",
       make_optimized_strategy},
      {"directional", "nearest frontier with a preference for each robot's own direction (seed 003 §IV)",
       make_directional_strategy},
      {"market", "sequential single-item auction, min-max bids on wave cost (Koenig et al. 2006; Zlot et al. 2002)",
       make_market_strategy},
  };
  return kEntries;
}

}  // namespace

std::vector<std::string> strategy_names() {
  std::vector<std::string> names;
  for (const auto& e : registry()) names.push_back(e.name);
  return names;
}

std::string strategy_help() {
  std::string s;
  for (const auto& e : registry()) s += "  " + e.name + ": " + e.help + "\n";
  return s;
}

std::unique_ptr<CoordinationStrategy> make_strategy(const std::string& name, const StrategyOptions& options) {
  for (const auto& e : registry()) {
    if (e.name == name) return e.make(options);
  }
  std::string names;
  for (const auto& e : registry()) names += (names.empty() ? "" : ", ") + e.name;
  throw InputError("unknown strategy '" + name + "' (valid: " + names + ")");
}

double visibility_overlap(double distance_m, double sensor_range_m) {
  if (sensor_range_m <= 0.0 || distance_m >= sensor_range_m) return 0.0;
  return 1.0 - distance_m / sensor_range_m;
}

std::vector<double> initial_utilities(const AssignmentInput& input) {
  std::vector<double> u(input.targets.size(), 1.0);
  for (std::size_t t = 0; t < u.size(); ++t) {
    for (const auto& c : input.claimed) u[t] -= visibility_overlap((input.targets[t].goal_m - c).norm(), input.sensor_range_m);
  }
  return u;
}

double cost_scale(const AssignmentInput& input) {
  double m = 0.0;
  for (const auto& r : input.robots)
    for (double c : r.cost_m)
      if (std::isfinite(c)) m = std::max(m, c);
  return m > 0.0 ? m : 1.0;
}

void nearest_targets(const AssignmentInput& input, std::vector<int>& assignment) {
  for (std::size_t i = 0; i < input.robots.size(); ++i) {
    if (assignment[i] >= 0) continue;
    const auto& cost = input.robots[i].cost_m;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < cost.size(); ++t) {
      if (cost[t] < best) best = cost[t], assignment[i] = int(t);
    }
  }
}

}  // namespace fleetmap::exploration
