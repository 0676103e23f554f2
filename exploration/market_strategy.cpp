#include <cmath>
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
      sold[std::size_t(item)] = true;
      if (first[w] < 0) first[w] = item;
      bundle_cost[w] = best;
      last[w] = input.targets[std::size_t(item)].goal_m;
    }
    return first;
  }
};

}  // namespace

std::unique_ptr<CoordinationStrategy> make_market_strategy(const StrategyOptions&) { return std::make_unique<Market>(); }

}  // namespace fleetmap::exploration
