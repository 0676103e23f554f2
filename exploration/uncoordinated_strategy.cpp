#include <limits>

#include "exploration/strategies.h"

namespace fleetmap::exploration {

namespace {

// Yamauchi's frontier-based exploration: every robot drives to its nearest frontier target and
// ignores the others.
class Uncoordinated final : public CoordinationStrategy {
 public:
  std::string name() const override { return "uncoordinated"; }
  bool joint() const override { return false; }
  std::vector<int> assign(const AssignmentInput& input) const override {
    std::vector<int> out(input.robots.size(), -1);
    nearest_targets(input, out);
    report_scores(input,
                  {.terms = {"wave cost (m)"},
                   .score = "wave cost (m)",
                   .lower_is_better = true,
                   .rule = "each robot drives to its nearest target by wave cost and ignores the others (Yamauchi 1998)", .robots = {}},
                  [&](std::size_t i, std::size_t t) {
                    const double c = input.robots[i].cost_m[t];
                    return CandidateScore{.target = -1, .terms = {c}, .score = c};
                  });
    return out;
  }
};

}  // namespace

std::unique_ptr<CoordinationStrategy> make_uncoordinated_strategy(const StrategyOptions&) {
  return std::make_unique<Uncoordinated>();
}

}  // namespace fleetmap::exploration
