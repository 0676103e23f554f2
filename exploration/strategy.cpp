#include "exploration/strategy.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "core/error.h"
#include "exploration/strategies.h"

namespace fleetmap::exploration {

core::Registry<StrategyFactory>& strategy_registry() {
  static core::Registry<StrategyFactory> registry("strategy");
  static const bool built_in = [] {
    auto& r = registry;
    r.add("uncoordinated", "each robot to its nearest frontier by wave cost (Yamauchi 1998)", make_uncoordinated_strategy);
    const auto beta = core::ParamSpec::number(
        "beta", 1.0, {0, 1e6}, "", "weight of travel cost against utility, costs scaled to [0, 1]");
    r.add("coordinated", "greedy utility minus beta * cost, utility reduced around assigned targets (Burgard et al. 2005)",
          make_coordinated_strategy, {beta});
    r.add("optimized",
          "assignment minimising squared costs minus utility, solved exactly (Hungarian method; the wave "
          "algorithm paper's eq. (3))",
          make_optimized_strategy, {beta});
    r.add("directional", "nearest frontier with a preference for each robot's own direction (the wave algorithm's "
                         "directional priority)",
          make_directional_strategy,
          {core::ParamSpec::number("weight", 0.5, {0, 1e6}, "",
                                   "how strongly a robot prefers targets in its own direction (0: not at all)")});
    r.add("market", "sequential single-item auction, min-max bids on wave cost (Koenig et al. 2006; Zlot et al. 2002)",
          make_market_strategy);
    r.add("tour",
          "an open tour per robot through every frontier target, split so that the unknown area behind the targets "
          "is reached soonest (least area-weighted latency), repaired between rounds; each robot drives to its tour's "
          "first target (after TARE, Cao et al. 2021, and RACER, Zhou et al. 2023)",
          make_tour_strategy);
    return true;
  }();
  (void)built_in;
  return registry;
}

void register_strategy(std::string name, std::string help, StrategyFactory make, std::vector<core::ParamSpec> params) {
  strategy_registry().add(std::move(name), std::move(help), std::move(make), std::move(params));
}

std::vector<std::string> strategy_names() { return strategy_registry().names(); }

std::string strategy_help() { return strategy_registry().help(); }

StrategyOptions strategy_options(const std::string& name, const StrategySettings& settings) {
  return strategy_registry().configure(name, settings);
}

StrategySettings declared_settings(const std::string& name, const StrategySettings& settings) {
  return strategy_registry().declared(name, settings);
}

std::unique_ptr<CoordinationStrategy> make_strategy(const std::string& name, const StrategySettings& settings) {
  return strategy_registry().get(name).make(strategy_options(name, settings));
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

Eigen::MatrixXd target_costs(const AssignmentInput& input) {
  if (input.target_costs_m) return input.target_costs_m();
  const auto m = Eigen::Index(input.targets.size());
  Eigen::MatrixXd c(m, m);
  for (Eigen::Index a = 0; a < m; ++a)
    for (Eigen::Index b = 0; b < m; ++b) c(a, b) = (input.targets[std::size_t(a)].goal_m - input.targets[std::size_t(b)].goal_m).norm();
  return c;
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

void report_scores(const AssignmentInput& input, ScoreSheet sheet,
                   const std::function<CandidateScore(std::size_t robot, std::size_t target)>& score) {
  if (!input.scores) return;
  sheet.robots.resize(input.robots.size());
  for (std::size_t i = 0; i < input.robots.size(); ++i) {
    for (std::size_t t = 0; t < input.targets.size(); ++t) {
      if (!std::isfinite(input.robots[i].cost_m[t])) continue;
      CandidateScore c = score(i, t);
      c.target = int(t);
      sheet.robots[i].candidates.push_back(std::move(c));
    }
  }
  *input.scores = std::move(sheet);
}

}  // namespace fleetmap::exploration
