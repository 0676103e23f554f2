#include <cmath>
#include <limits>

#include "exploration/strategies.h"

namespace fleetmap::exploration {

namespace {

// Burgard, Moors, Stachniss, Schneider 2005, Algorithm 1: repeatedly pick the robot-target pair
// with the best utility minus beta times (scaled) cost, then lower the utility of targets the
// chosen one would likely reveal (within the sensor range).
class Coordinated final : public CoordinationStrategy {
 public:
  explicit Coordinated(const StrategyOptions& o) : beta_(o.beta) {}
  std::string name() const override { return "coordinated"; }
  bool joint() const override { return true; }

  std::vector<int> assign(const AssignmentInput& input) const override {
    const std::size_t n = input.robots.size(), m = input.targets.size();
    std::vector<int> out(n, -1);
    std::vector<double> utility = initial_utilities(input);
    const double scale = cost_scale(input);
    std::vector<char> taken(m, false), done(n, false);
    for (std::size_t round = 0; round < n; ++round) {
      double best = -std::numeric_limits<double>::infinity();
      int best_robot = -1, best_target = -1;
      for (std::size_t i = 0; i < n; ++i) {
        if (done[i]) continue;
        for (std::size_t t = 0; t < m; ++t) {
          const double c = input.robots[i].cost_m[t];
          if (!std::isfinite(c) || taken[t]) continue;
          const double score = utility[t] - beta_ * c / scale;
          if (score > best) best = score, best_robot = int(i), best_target = int(t);
        }
      }
      if (best_robot < 0) break;
      out[std::size_t(best_robot)] = best_target;
      done[std::size_t(best_robot)] = true;
      taken[std::size_t(best_target)] = true;
      const Eigen::Vector2d g = input.targets[std::size_t(best_target)].goal_m;
      for (std::size_t t = 0; t < m; ++t) utility[t] -= visibility_overlap((input.targets[t].goal_m - g).norm(), input.sensor_range_m);
    }
    return out;
  }

 private:
  double beta_;
};

}  // namespace

std::unique_ptr<CoordinationStrategy> make_coordinated_strategy(const StrategyOptions& options) {
  return std::make_unique<Coordinated>(options);
}

}  // namespace fleetmap::exploration
