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
  explicit Directional(const StrategyOptions& o) : weight_(o.directional_weight) {}
  std::string name() const override { return "directional"; }
  bool joint() const override { return false; }

  std::vector<int> assign(const AssignmentInput& input) const override {
    std::vector<int> out(input.robots.size(), -1);
    const double scale = cost_scale(input);
    for (std::size_t i = 0; i < input.robots.size(); ++i) {
      const auto& r = input.robots[i];
      const double preferred = 2.0 * std::numbers::pi * r.team_index / std::max(1, r.team_size);
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t t = 0; t < input.targets.size(); ++t) {
        if (!std::isfinite(r.cost_m[t])) continue;
        const Eigen::Vector2d d = input.targets[t].goal_m - r.position_m;
        const double off = d.squaredNorm() > 0.0 ? 0.5 * (1.0 - std::cos(std::atan2(d.y(), d.x()) - preferred)) : 0.0;
        const double rank = r.cost_m[t] / scale + weight_ * off;
        if (rank < best) best = rank, out[i] = int(t);
      }
    }
    return out;
  }

 private:
  double weight_;
};

}  // namespace

std::unique_ptr<CoordinationStrategy> make_directional_strategy(const StrategyOptions& options) {
  return std::make_unique<Directional>(options);
}

}  // namespace fleetmap::exploration
