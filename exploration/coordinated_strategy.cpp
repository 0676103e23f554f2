#include <fmt/format.h>

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
  explicit Coordinated(const StrategyOptions& o) : beta_(o.number("beta")) {}
  std::string name() const override { return "coordinated"; }
  bool joint() const override { return true; }

  std::vector<int> assign(const AssignmentInput& input) const override {
    const std::size_t n = input.robots.size(), m = input.targets.size();
    std::vector<int> out(n, -1);
    std::vector<double> utility = initial_utilities(input);
    const double scale = cost_scale(input);
    std::vector<char> taken(m, false), done(n, false);
    if (input.scores) *input.scores = sheet(n);
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
      if (input.scores) {
        explain(input, utility, scale, std::size_t(best_robot));
        input.scores->robots[std::size_t(best_robot)].note =
            fmt::format("picked {} of {} in the greedy order (the best utility - beta * cost left); largest cost {:.1f} m",
                        round + 1, n, scale);
      }
      out[std::size_t(best_robot)] = best_target;
      done[std::size_t(best_robot)] = true;
      taken[std::size_t(best_target)] = true;
      const Eigen::Vector2d g = input.targets[std::size_t(best_target)].goal_m;
      for (std::size_t t = 0; t < m; ++t) utility[t] -= visibility_overlap((input.targets[t].goal_m - g).norm(), input.sensor_range_m);
    }
    if (input.scores) {
      for (std::size_t i = 0; i < n; ++i) {
        if (done[i]) continue;
        explain(input, utility, scale, i);
        input.scores->robots[i].note = "none left: every target it can reach went to a robot picked before it";
      }
    }
    return out;
  }

 private:
  ScoreSheet sheet(std::size_t robots) const {
    ScoreSheet s{.terms = {"utility", "wave cost (m)", "beta * cost / largest cost"},
                 .score = "utility - beta * cost / largest cost",
                 .lower_is_better = false,
                 .rule = fmt::format("robot-target pairs are picked best first; a picked target lowers the utility of "
                                     "those within the sensor range of it (Burgard et al. 2005, Algorithm 1; beta {}; "
                                     "costs scaled by the largest of the round)",
                                     beta_), .robots = {}};
    s.robots.resize(robots);
    return s;
  }
  // Robot i's candidates with the utilities as they stand when it is picked.
  void explain(const AssignmentInput& input, const std::vector<double>& utility, double scale, std::size_t i) const {
    auto& candidates = input.scores->robots[i].candidates;
    for (std::size_t t = 0; t < input.targets.size(); ++t) {
      const double c = input.robots[i].cost_m[t];
      if (!std::isfinite(c)) continue;
      candidates.push_back({int(t), {utility[t], c, beta_ * c / scale}, utility[t] - beta_ * c / scale});
    }
  }

  double beta_;
};

}  // namespace

std::unique_ptr<CoordinationStrategy> make_coordinated_strategy(const StrategyOptions& options) {
  return std::make_unique<Coordinated>(options);
}

}  // namespace fleetmap::exploration
