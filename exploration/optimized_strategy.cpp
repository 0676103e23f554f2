#include <cmath>

#include "exploration/hungarian.h"
#include "exploration/strategies.h"

namespace fleetmap::exploration {

namespace {

// The wave-algorithm paper, eq. (3): choose the targets t_1..t_n for the robots that maximise
// sum_i (U(t_i) - beta * V_i(t_i)^2); squaring the travel costs favours assignments that finish
// together (wave-algorithm paper, Fig. 4). Solved exactly as an assignment problem with the Hungarian method.
class Optimized final : public CoordinationStrategy {
 public:
  explicit Optimized(const StrategyOptions& o) : beta_(o.beta) {}
  std::string name() const override { return "optimized"; }
  bool joint() const override { return true; }

  std::vector<int> assign(const AssignmentInput& input) const override {
    const std::size_t n = input.robots.size(), m = input.targets.size();
    std::vector<int> out(n, -1);
    if (m == 0) return out;
    const std::vector<double> utility = initial_utilities(input);
    const double scale = cost_scale(input);
    // Unreachable pairs get a cost above any reachable assignment's total.
    const double unreachable = 10.0 * double(n) * (beta_ + 2.0) + 10.0;
    Eigen::MatrixXd cost(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(m));
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t t = 0; t < m; ++t) {
        const double v = input.robots[i].cost_m[t] / scale;
        cost(Eigen::Index(i), Eigen::Index(t)) = std::isfinite(v) ? beta_ * v * v - utility[t] : unreachable;
      }
    }
    const std::vector<int> solution = solve_assignment(cost);
    for (std::size_t i = 0; i < n; ++i) {
      const int t = solution[i];
      if (t >= 0 && std::isfinite(input.robots[i].cost_m[std::size_t(t)])) out[i] = t;
    }
    return out;
  }

 private:
  double beta_;
};

}  // namespace

std::unique_ptr<CoordinationStrategy> make_optimized_strategy(const StrategyOptions& options) {
  return std::make_unique<Optimized>(options);
}

}  // namespace fleetmap::exploration
