#include <fmt/format.h>

#include <cmath>
#include <algorithm>
#include <limits>

#include "exploration/strategies.h"

namespace fleetmap::exploration {

namespace {

// A sequential single-item auction (Koenig, Tovey, Lagoudakis et al. 2006): targets are sold one
// per round; every robot bids the cost of its whole bundle with the target added (the min-max
// bid, which balances the work), travelling by wave cost to its first target and straight lines
// between targets after that. The lowest bid wins. Each robot then drives to the first target of
// its bundle; the auction is rerun when any robot of the group needs a new target.
class Market final : public CoordinationStrategy {
 public:
  std::string name() const override { return "market"; }
  bool joint() const override { return true; }

  std::vector<int> assign(const AssignmentInput& input) const override {
    const std::size_t n = input.robots.size(), m = input.targets.size();
    std::vector<int> first(n, -1);
    std::vector<double> bundle_cost(n, 0.0);
    std::vector<Eigen::Vector2d> last(n);
    std::vector<char> sold(m, false);
    std::vector<int> won_in(n, -1), items(n, 0);
    if (input.scores) {
      *input.scores = {.terms = {"wave cost (m)", "its bid (m)", "best rival bid (m)"},
                       .score = "its bid (m)",
                       .lower_is_better = true,
                       .rule = "targets are sold one per round to the lowest bid; a bid is the robot's whole bundle "
                               "with the target added (min-max bids, Koenig et al. 2006); each robot drives to the "
                               "first target it won", .robots = {}};
      input.scores->robots.resize(n);
    }
    for (std::size_t round = 0; round < m; ++round) {
      double best = std::numeric_limits<double>::infinity();
      int winner = -1, item = -1;
      for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t t = 0; t < m; ++t) {
          if (sold[t] || !std::isfinite(input.robots[i].cost_m[t])) continue;
          const double marginal = first[i] < 0 ? input.robots[i].cost_m[t] : (input.targets[t].goal_m - last[i]).norm();
          const double bid = bundle_cost[i] + marginal;
          if (bid < best) best = bid, winner = int(i), item = int(t);
        }
      }
      if (winner < 0) break;
      const auto w = std::size_t(winner);
      // The round that decides the winner's target: its bids against the best of the others.
      if (input.scores && first[w] < 0) explain(input, w, bundle_cost, first, last, sold), won_in[w] = int(round);
      sold[std::size_t(item)] = true;
      ++items[w];
      if (first[w] < 0) first[w] = item;
      bundle_cost[w] = best;
      last[w] = input.targets[std::size_t(item)].goal_m;
    }
    if (input.scores) {
      for (std::size_t i = 0; i < n; ++i) {
        auto& r = input.scores->robots[i];
        if (won_in[i] < 0) {
          explain(input, i, bundle_cost, first, last, sold);
          r.note = "won no target: lower bids took every target it can reach";
        } else {
          r.note = fmt::format("won round {} with the lowest bid; its bundle: {} target{}, {:.1f} m", won_in[i] + 1,
                               items[i], items[i] == 1 ? "" : "s", bundle_cost[i]);
        }
      }
    }
    return first;
  }

 private:
  static double bid(const AssignmentInput& input, std::size_t i, std::size_t t, const std::vector<double>& bundle_cost,
                    const std::vector<int>& first, const std::vector<Eigen::Vector2d>& last) {
    return bundle_cost[i] + (first[i] < 0 ? input.robots[i].cost_m[t] : (input.targets[t].goal_m - last[i]).norm());
  }
  // Robot i's bids on every target it can reach as the auction stands (NaN where a target is sold).
  static void explain(const AssignmentInput& input, std::size_t i, const std::vector<double>& bundle_cost,
                      const std::vector<int>& first, const std::vector<Eigen::Vector2d>& last, const std::vector<char>& sold) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    auto& candidates = input.scores->robots[i].candidates;
    candidates.clear();
    for (std::size_t t = 0; t < input.targets.size(); ++t) {
      if (!std::isfinite(input.robots[i].cost_m[t])) continue;
      double rival = std::numeric_limits<double>::infinity();
      for (std::size_t j = 0; j < input.robots.size(); ++j)
        if (j != i && std::isfinite(input.robots[j].cost_m[t])) rival = std::min(rival, bid(input, j, t, bundle_cost, first, last));
      const double own = sold[t] ? nan : bid(input, i, t, bundle_cost, first, last);
      candidates.push_back({int(t), {input.robots[i].cost_m[t], own, sold[t] || std::isinf(rival) ? nan : rival}, own});
    }
  }
};

}  // namespace

std::unique_ptr<CoordinationStrategy> make_market_strategy(const StrategyOptions&) { return std::make_unique<Market>(); }

}  // namespace fleetmap::exploration
