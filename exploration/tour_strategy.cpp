#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>

#include "exploration/strategies.h"
#include "exploration/tour_planner.h"

namespace fleetmap::exploration {

namespace {

// Multi-robot frontier tours, after TARE (Cao et al. 2021) and RACER (Zhou et al. 2023): every
// frontier target is a node, with wave costs from each robot and between the targets, weighted by
// the never-observed area behind it (unknown_area_behind, split among the targets so that no area
// counts twice); every robot gets an open tour, and the targets are split among the robots so that
// the weighted sum of the times at which they are reached is as small as the search finds
// (plan_latency_tours): the team reveals the most area soonest. Each robot drives to its tour's
// first target; a robot with an empty tour drives ahead to where unknown space will open
// (drive_ahead).
//
// Why not the min-max split (the longest tour as short as possible): measured on the
// wave-algorithm paper's maps it was slower than Burgard's utility reduction (bench/README.md,
// "Tour strategy"): once one tour is the longest, the others are free to grow up to it, so robots
// drove across the map to targets idle robots stood beside, and every frontier piece counted the
// same whatever lay behind it.
//
// Tours are repaired, not planned afresh, each round (RACER's incremental update): the previous
// round's tours are the starting solution, with the targets that vanished dropped and the new ones
// inserted, so a robot keeps its plan unless a move makes the team's tours better, and robots do
// not swap targets back and forth. A group of robots plans with its own members' earlier tours only:
// robots that cannot talk never see one another's plans.
class Tour final : public CoordinationStrategy {
 public:
  std::string name() const override { return "tour"; }
  bool joint() const override { return true; }

  std::vector<int> assign(const AssignmentInput& input) const override {
    const std::size_t n = input.robots.size(), m = input.targets.size();
    std::vector<int> out(n, -1);
    if (n == 0 || m == 0) return out;
    TourProblem problem;
    problem.start_cost.resize(Eigen::Index(n), Eigen::Index(m));
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t t = 0; t < m; ++t) problem.start_cost(Eigen::Index(i), Eigen::Index(t)) = input.robots[i].cost_m[t];
    // Costs between targets only matter when some robot has two or more to visit. They are the
    // whole wave cost: shortening legs by the sensor range (a target is seen from afar) made chains
    // of targets free, and one robot took them all.
    problem.between = m > 1 ? target_costs(input) : Eigen::MatrixXd::Zero(Eigen::Index(m), Eigen::Index(m));
    // A target's weight: the unknown area behind it plus kBaseWeight, so that a frontier piece with
    // nothing measurable behind it (the last corners, which 99% needs) is still worth a visit.
    std::vector<double> weight;
    if (input.target_gains_m2) {
      weight = input.target_gains_m2();
      for (double& w : weight) w += kBaseWeight;
    }

    const std::lock_guard<std::mutex> lock(mutex_);
    const Tours tours = plan_latency_tours(problem, weight, previous_tours(input, problem));
    for (std::size_t i = 0; i < n; ++i) {
      auto& kept = memory_[input.robots[i].team_index];
      kept.clear();
      for (int t : tours[i]) kept.push_back(input.targets[std::size_t(t)].goal_m);
      if (!tours[i].empty()) out[i] = tours[i].front();
    }
    const std::vector<int> ahead = drive_ahead(problem, weight, tours);
    for (std::size_t i = 0; i < n; ++i)
      if (ahead[i] >= 0) out[i] = ahead[i];
    if (input.scores) explain(input, problem, weight, tours, ahead);
    return out;
  }

 private:
  // Robots the minimum-latency split leaves free (every target is reached sooner by another robot)
  // do not wait: each drives ahead to the target with the most unknown area per metre of its way
  // (weight / (1 + wave cost)), already on another robot's tour, where new frontiers will open
  // once that robot sees it, as RACER (Zhou et al. 2023) keeps every robot moving toward unknown
  // space of its own. No two free robots drive ahead to the same target. Measured on the
  // wave-algorithm paper's maps (bench/README.md, "Tour strategy"): waiting robots made the last
  // corridors slow. Per robot: the target it drives ahead to, or -1 (its tour is not empty, or it
  // reaches no target).
  static std::vector<int> drive_ahead(const TourProblem& problem, const std::vector<double>& weight, const Tours& tours) {
    const auto n = std::size_t(problem.start_cost.rows()), m = std::size_t(problem.start_cost.cols());
    std::vector<int> ahead(n, -1);
    std::vector<char> taken(m, false);
    for (std::size_t i = 0; i < n; ++i) {
      if (!tours[i].empty()) continue;
      double best = 0.0;
      for (std::size_t t = 0; t < m; ++t) {
        const double cost = problem.start_cost(Eigen::Index(i), Eigen::Index(t));
        if (!std::isfinite(cost) || taken[t]) continue;
        const double rate = (weight.empty() ? 1.0 : weight[t]) / (1.0 + cost);
        if (ahead[i] < 0 || rate > best) best = rate, ahead[i] = int(t);
      }
      if (ahead[i] >= 0) taken[std::size_t(ahead[i])] = true;
    }
    return ahead;
  }

  // Per candidate: its wave cost, the area behind it, and when the tour it belongs to reaches it.
  static void explain(const AssignmentInput& input, const TourProblem& problem, const std::vector<double>& weight,
                      const Tours& tours, const std::vector<int>& ahead) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::vector<double> arrival(input.targets.size(), nan);
    std::vector<int> owner(input.targets.size(), -1);
    for (std::size_t i = 0; i < tours.size(); ++i) {
      double at = 0.0;
      for (std::size_t k = 0; k < tours[i].size(); ++k) {
        const auto t = Eigen::Index(tours[i][k]);
        at += k == 0 ? problem.start_cost(Eigen::Index(i), t) : problem.between(Eigen::Index(tours[i][k - 1]), t);
        arrival[std::size_t(t)] = at;
        owner[std::size_t(t)] = int(i);
      }
    }
    report_scores(input,
                  {.terms = {"wave cost (m)", "unknown area behind (m2)", "on the tour of robot",
                              "reached along that tour at (m)"},
                   .score = "reached along its own tour at (m)",
                   .lower_is_better = true,
                   .rule = "every robot gets an open tour through the targets; the tours make the area-weighted sum of "
                           "the times targets are reached least (minimum latency, after TARE, Cao et al. 2021, and "
                           "RACER, Zhou et al. 2023); each robot drives to its tour's first target, one with an empty tour "
                           "ahead to the target with the most unknown area per metre of its way", .robots = {}},
                  [&](std::size_t i, std::size_t t) {
                    const double area = weight.empty() ? nan : weight[t] - kBaseWeight;
                    const int o = owner[t];
                    return CandidateScore{
                        .terms = {input.robots[i].cost_m[t], area, o < 0 ? nan : double(input.robots[std::size_t(o)].team_index + 1),
                                  arrival[t]},
                        .score = o == int(i) ? arrival[t] : nan};
                  });
    for (std::size_t i = 0; i < tours.size(); ++i) {
      input.scores->robots[i].note =
          tours[i].empty() ? (ahead[i] < 0 ? std::string("an empty tour: the others reach every target sooner")
                                            : std::string("an empty tour: the others reach every target sooner; drives ahead to "
                                                          "the target with the most unknown area per metre"))
                           : fmt::format("its tour: {} target{}, {:.1f} m, weighted latency {:.0f} m*m2", tours[i].size(),
                                         tours[i].size() == 1 ? "" : "s", tour_length(problem, int(i), tours[i]),
                                         tour_latency(problem, weight, int(i), tours[i]));
    }
  }

  // The previous round's tours in this round's targets: each remembered goal becomes a target
  // within kSameTarget (frontiers shrink and their goals move as they are seen), nearest pairs
  // first, so a target that is still there keeps its place; goals with none (explored meanwhile)
  // are dropped.
  Tours previous_tours(const AssignmentInput& input, const TourProblem& problem) const {
    struct Pair {
      double distance;
      std::size_t robot, slot, target;
    };
    std::vector<Pair> pairs;
    std::vector<std::vector<int>> slots(input.robots.size());
    for (std::size_t i = 0; i < input.robots.size(); ++i) {
      const auto it = memory_.find(input.robots[i].team_index);
      if (it == memory_.end()) continue;
      slots[i].assign(it->second.size(), -1);
      for (std::size_t k = 0; k < it->second.size(); ++k) {
        for (std::size_t t = 0; t < input.targets.size(); ++t) {
          const double d = (input.targets[t].goal_m - it->second[k]).norm();
          if (d <= kSameTarget && std::isfinite(problem.start_cost(Eigen::Index(i), Eigen::Index(t)))) pairs.push_back({d, i, k, t});
        }
      }
    }
    std::stable_sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.distance < b.distance; });
    std::vector<char> used(input.targets.size(), false);
    for (const Pair& p : pairs) {
      if (used[p.target] || slots[p.robot][p.slot] >= 0) continue;
      used[p.target] = true;
      slots[p.robot][p.slot] = int(p.target);
    }
    Tours tours(input.robots.size());
    for (std::size_t i = 0; i < slots.size(); ++i)
      for (int t : slots[i])
        if (t >= 0) tours[i].push_back(t);
    return tours;
  }

  static constexpr double kSameTarget = 1.0;  // metres
  static constexpr double kBaseWeight = 1.0;  // square metres
  // Per robot (team index): the goals of its last tour, in the frame of the map it was planned on.
  // The strategy's only state; assign() is const for its callers, so it is mutable and guarded.
  mutable std::map<int, std::vector<Eigen::Vector2d>> memory_;
  mutable std::mutex mutex_;
};

}  // namespace

std::unique_ptr<CoordinationStrategy> make_tour_strategy(const StrategyOptions&) { return std::make_unique<Tour>(); }

}  // namespace fleetmap::exploration
