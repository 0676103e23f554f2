#include "exploration/tour_planner.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>

namespace fleetmap::exploration {
namespace {

constexpr double kNoPath = std::numeric_limits<double>::infinity();

// Robots and targets as points; costs are straight-line distances.
TourProblem euclidean(const std::vector<Eigen::Vector2d>& robots, const std::vector<Eigen::Vector2d>& targets) {
  TourProblem p;
  p.start_cost.resize(Eigen::Index(robots.size()), Eigen::Index(targets.size()));
  p.between.resize(Eigen::Index(targets.size()), Eigen::Index(targets.size()));
  for (std::size_t r = 0; r < robots.size(); ++r)
    for (std::size_t t = 0; t < targets.size(); ++t) p.start_cost(Eigen::Index(r), Eigen::Index(t)) = (robots[r] - targets[t]).norm();
  for (std::size_t a = 0; a < targets.size(); ++a)
    for (std::size_t b = 0; b < targets.size(); ++b) p.between(Eigen::Index(a), Eigen::Index(b)) = (targets[a] - targets[b]).norm();
  return p;
}

// The usual greedy split: every target to its nearest robot, each robot's targets visited nearest
// first.
Tours greedy(const TourProblem& p) {
  const auto n = p.start_cost.rows(), m = p.start_cost.cols();
  std::vector<std::vector<int>> own(static_cast<std::size_t>(n));
  for (Eigen::Index t = 0; t < m; ++t) {
    Eigen::Index best = -1;
    for (Eigen::Index r = 0; r < n; ++r)
      if (std::isfinite(p.start_cost(r, t)) && (best < 0 || p.start_cost(r, t) < p.start_cost(best, t))) best = r;
    if (best >= 0) own[std::size_t(best)].push_back(int(t));
  }
  Tours tours(static_cast<std::size_t>(n));
  for (Eigen::Index r = 0; r < n; ++r) {
    auto left = own[std::size_t(r)];
    int at = -1;
    while (!left.empty()) {
      auto cost = [&](int t) { return at < 0 ? p.start_cost(r, t) : p.between(at, t); };
      const auto next = std::min_element(left.begin(), left.end(), [&](int a, int b) { return cost(a) < cost(b); });
      at = *next;
      tours[std::size_t(r)].push_back(at);
      left.erase(next);
    }
  }
  return tours;
}

std::vector<Eigen::Vector2d> random_points(std::mt19937& rng, int count) {
  std::uniform_real_distribution<double> u(0.0, 20.0);
  std::vector<Eigen::Vector2d> out;
  for (int i = 0; i < count; ++i) out.push_back({u(rng), u(rng)});
  return out;
}

// The weighted latency of all tours.
double total_latency(const TourProblem& p, const std::vector<double>& w, const Tours& tours) {
  double sum = 0.0;
  for (std::size_t r = 0; r < tours.size(); ++r) sum += tour_latency(p, w, int(r), tours[r]);
  return sum;
}

TEST(TourPlanner, ATourIsTheSumOfItsLegs) {
  const TourProblem p = euclidean({{0.0, 0.0}}, {{1.0, 0.0}, {1.0, 2.0}});
  EXPECT_DOUBLE_EQ(tour_length(p, 0, {0, 1}), 3.0);
  EXPECT_DOUBLE_EQ(tour_length(p, 0, {}), 0.0);
}

TEST(TourPlanner, LatencyVisitsTheHeavierTargetFirst) {
  // A robot at 0 between a target at x = -1 and one at x = 2. Alike, the near one first (1 + 4
  // against 2 + 5); when the far one weighs ten times more, it first (10 * 2 + 5 against 1 + 10 * 4).
  const TourProblem p = euclidean({{0.0, 0.0}}, {{-1.0, 0.0}, {2.0, 0.0}});
  EXPECT_EQ(plan_latency_tours(p, {})[0], (std::vector<int>{0, 1}));
  EXPECT_EQ(plan_latency_tours(p, {1.0, 10.0})[0], (std::vector<int>{1, 0}));
  EXPECT_DOUBLE_EQ(tour_latency(p, {1.0, 10.0}, 0, {1, 0}), 25.0);
}

TEST(TourPlanner, LatencyToursLeaveAFarRobotFreeAndSendItToWhatIsNearIt) {
  // Nine targets around (0, 0), a robot there and one 30 m away: the near robot takes them all. A
  // target appears at (29, 0): the far robot takes that one.
  std::vector<Eigen::Vector2d> targets;
  for (int k = 0; k < 9; ++k) targets.push_back({std::cos(k * 0.7), std::sin(k * 0.7)});
  const Tours first = plan_latency_tours(euclidean({{0.0, 0.0}, {30.0, 0.0}}, targets), {});
  EXPECT_EQ(first[0].size(), 9u);
  EXPECT_TRUE(first[1].empty());
  targets.push_back({29.0, 0.0});
  const Tours second = plan_latency_tours(euclidean({{0.0, 0.0}, {30.0, 0.0}}, targets), {}, first);
  EXPECT_EQ(second[0], first[0]);
  EXPECT_EQ(second[1], (std::vector<int>{9}));
}

TEST(TourPlanner, LatencyToursVisitEveryReachableTargetOnceAndBeatGreedy) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> weight(0.0, 20.0);
  double sum_planned = 0.0, sum_greedy = 0.0;
  for (int trial = 0; trial < 100; ++trial) {
    const int n = 1 + trial % 9, m = trial % 25;
    TourProblem p = euclidean(random_points(rng, n), random_points(rng, m));
    std::bernoulli_distribution lost(0.3);
    for (Eigen::Index r = 0; r < p.start_cost.rows(); ++r)
      for (Eigen::Index t = 0; t < p.start_cost.cols(); ++t)
        if (lost(rng)) p.start_cost(r, t) = kNoPath;
    std::vector<double> w(static_cast<std::size_t>(m));
    for (double& x : w) x = weight(rng);
    const Tours tours = plan_latency_tours(p, w);
    ASSERT_EQ(tours.size(), std::size_t(n));
    std::multiset<int> seen;
    for (int r = 0; r < n; ++r) {
      for (int t : tours[std::size_t(r)]) {
        seen.insert(t);
        EXPECT_TRUE(std::isfinite(p.start_cost(r, t))) << "robot " << r << " given target " << t << " it cannot reach";
      }
    }
    for (int t = 0; t < m; ++t) {
      const bool reachable = (p.start_cost.col(t).array() < kNoPath).any();
      EXPECT_EQ(seen.count(t), reachable ? 1u : 0u) << "trial " << trial << " target " << t;
    }
    // Given its own answer as the previous tours, it keeps them; from the greedy tours it never
    // gets worse than they are.
    EXPECT_EQ(plan_latency_tours(p, w, tours), tours) << "trial " << trial;
    const Tours g = greedy(p);
    EXPECT_LE(total_latency(p, w, plan_latency_tours(p, w, g)), total_latency(p, w, g) + 1e-9) << "trial " << trial;
    sum_planned += total_latency(p, w, tours);
    sum_greedy += total_latency(p, w, g);
  }
  EXPECT_LT(sum_planned, 0.9 * sum_greedy) << "latency tours should be clearly better than greedy ones on average";
}

TEST(TourPlanner, RejectsMismatchedCosts) {
  TourProblem p;
  p.start_cost = Eigen::MatrixXd::Zero(2, 3);
  p.between = Eigen::MatrixXd::Zero(2, 2);
  EXPECT_ANY_THROW(plan_latency_tours(p, {}));
  const TourProblem q = euclidean({{0.0, 0.0}}, {{1.0, 0.0}, {2.0, 0.0}});
  EXPECT_ANY_THROW(plan_latency_tours(q, {1.0}));         // one weight for two targets
  EXPECT_ANY_THROW(plan_latency_tours(q, {1.0, -1.0}));   // a negative weight
}

}  // namespace
}  // namespace fleetmap::exploration
