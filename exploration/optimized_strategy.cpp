#include <fmt/format.h>

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
  explicit Optimized(const StrategyOptions& o) : beta_(o.number("beta")) {}
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
    if (input.scores) explain(input, utility, scale, cost, out);
    return out;
  }

 private:
  void explain(const AssignmentInput& input, const std::vector<double>& utility, double scale, const Eigen::MatrixXd& cost,
               const std::vector<int>& out) const {
    report_scores(input,
                  {.terms = {"utility", "wave cost (m)", "beta * (cost / largest cost)^2"},
                   .score = "beta * (cost / largest cost)^2 - utility",
                   .lower_is_better = true,
                   .rule = fmt::format("one target per robot, the assignment whose total over the team is least, solved "
                                       "exactly (the wave algorithm paper's eq. (3), Hungarian method; beta {}; costs "
                                       "scaled by the largest of the round)",
                                       beta_), .robots = {}},
                  [&](std::size_t i, std::size_t t) {
                    const double v = input.robots[i].cost_m[t] / scale;
                    return CandidateScore{.target = -1, .terms = {utility[t], input.robots[i].cost_m[t], beta_ * v * v},
                                          .score = cost(Eigen::Index(i), Eigen::Index(t))};
                  });
    double total = 0.0;
    int assigned = 0;
    for (std::size_t i = 0; i < out.size(); ++i)
      if (out[i] >= 0) total += cost(Eigen::Index(i), Eigen::Index(out[i])), ++assigned;
    const std::string note = fmt::format("the team's least total: {:.3f} over {} robots and {} targets; largest cost {:.1f} m",
                                         total, assigned, input.targets.size(), scale);
    for (auto& r : input.scores->robots) r.note = note;
  }

  double beta_;
};

}  // namespace

std::unique_ptr<CoordinationStrategy> make_optimized_strategy(const StrategyOptions& options) {
  return std::make_unique<Optimized>(options);
}

}  // namespace fleetmap::exploration
