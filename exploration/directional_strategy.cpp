#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "exploration/strategies.h"

namespace fleetmap::exploration {

namespace {

// The wave-algorithm paper, §IV, the wave algorithm with directional priority: robot k of n prefers the direction
// 2 pi k / n on the plane, so robots spread out from the start without talking. A target's rank is
// its scaled wave cost plus weight * (1 - cos(angle between the target and the preferred
// direction)) / 2.
class Directional final : public CoordinationStrategy {
 public:
  explicit Directional(const StrategyOptions& o) : weight_(o.number("weight")) {}
  std::string name() const override { return "directional"; }
  bool joint() const override { return false; }

  std::vector<int> assign(const AssignmentInput& input) const override {
    std::vector<int> out(input.robots.size(), -1);
    const double scale = cost_scale(input);
    for (std::size_t i = 0; i < input.robots.size(); ++i) {
      const auto& r = input.robots[i];
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t t = 0; t < input.targets.size(); ++t) {
        if (!std::isfinite(r.cost_m[t])) continue;
        const double off = off_direction(r, input.targets[t].goal_m);
        const double rank = r.cost_m[t] / scale + weight_ * off;
        if (rank < best) best = rank, out[i] = int(t);
      }
    }
    if (input.scores) explain(input, scale);
    return out;
  }

 private:
  void explain(const AssignmentInput& input, double scale) const {
    report_scores(input,
                  {.terms = {"wave cost (m)", "off its direction (0-1)"},
                   .score = "cost / largest cost + weight * off",
                   .lower_is_better = true,
                   .rule = fmt::format("each robot takes the lowest wave cost (scaled by the largest of the round) plus {} "
                                       "times how far the target lies off its own direction (the wave algorithm's "
                                       "directional priority)",
                                       weight_), .robots = {}},
                  [&](std::size_t i, std::size_t t) {
                    const double off = off_direction(input.robots[i], input.targets[t].goal_m);
                    return CandidateScore{.target = -1, .terms = {input.robots[i].cost_m[t], off},
                                          .score = input.robots[i].cost_m[t] / scale + weight_ * off};
                  });
    for (std::size_t i = 0; i < input.robots.size(); ++i)
      input.scores->robots[i].note = fmt::format("its own direction: {:.0f} deg (robot {} of {}); largest cost {:.1f} m",
                                                 preferred(input.robots[i]) * 180.0 / std::numbers::pi,
                                                 input.robots[i].team_index + 1, input.robots[i].team_size, scale);
  }
  static double preferred(const AssignmentRobot& r) { return 2.0 * std::numbers::pi * r.team_index / std::max(1, r.team_size); }
  // 0 in the robot's own direction, 1 opposite it.
  static double off_direction(const AssignmentRobot& r, const Eigen::Vector2d& goal) {
    const Eigen::Vector2d d = goal - r.position_m;
    return d.squaredNorm() > 0.0 ? 0.5 * (1.0 - std::cos(std::atan2(d.y(), d.x()) - preferred(r))) : 0.0;
  }

  double weight_;
};

}  // namespace

std::unique_ptr<CoordinationStrategy> make_directional_strategy(const StrategyOptions& options) {
  return std::make_unique<Directional>(options);
}

}  // namespace fleetmap::exploration
