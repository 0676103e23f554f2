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

double longest(const TourProblem& p, const Tours& tours) {
  double m = 0.0;
  for (std::size_t r = 0; r < tours.size(); ++r) m = std::max(m, tour_length(p, int(r), tours[r]));
  return m;
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

TEST(TourPlanner, PointsOnALineSplitBetweenRobotsAtTheEnds) {
  // Robots at x = 0 and x = 11, targets at x = 1..10: each robot takes its own half, nearest first.
  std::vector<Eigen::Vector2d> targets;
  for (int x = 1; x <= 10; ++x) targets.push_back({double(x), 0.0});
  const TourProblem p = euclidean({{0.0, 0.0}, {11.0, 0.0}}, targets);
  const Tours tours = plan_tours(p);
  ASSERT_EQ(tours.size(), 2u);
  EXPECT_EQ(tours[0], (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(tours[1], (std::vector<int>{9, 8, 7, 6, 5}));
  EXPECT_DOUBLE_EQ(longest(p, tours), 5.0);
}

TEST(TourPlanner, OneRobotVisitsAllInOrderAlongTheLine) {
  // Scattered along a line, in shuffled index order: the open tour walks them from the near end.
  const std::vector<Eigen::Vector2d> targets = {{7, 0}, {2, 0}, {9, 0}, {4, 0}, {1, 0}};
  const TourProblem p = euclidean({{0.0, 0.0}}, targets);
  EXPECT_EQ(plan_tours(p)[0], (std::vector<int>{4, 1, 3, 0, 2}));
}

TEST(TourPlanner, EveryReachableTargetOnceByARobotThatReachesIt) {
  std::mt19937 rng(17);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 1 + trial % 9, m = trial % 25;
    TourProblem p = euclidean(random_points(rng, n), random_points(rng, m));
    std::bernoulli_distribution lost(0.3);
    for (Eigen::Index r = 0; r < p.start_cost.rows(); ++r)
      for (Eigen::Index t = 0; t < p.start_cost.cols(); ++t)
        if (lost(rng)) p.start_cost(r, t) = kNoPath;
    const Tours tours = plan_tours(p);
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
  }
}

TEST(TourPlanner, LongestTourNotWorseThanGreedy) {
  // The min-max split alone: giving idle robots a target (every_robot_busy) may lengthen a tour.
  TourOptions pure;
  pure.every_robot_busy = false;
  std::mt19937 rng(5);
  double sum_planned = 0.0, sum_greedy = 0.0;
  for (int trial = 0; trial < 100; ++trial) {
    const int n = 2 + trial % 8, m = 5 + trial % 30;
    const TourProblem p = euclidean(random_points(rng, n), random_points(rng, m));
    const Tours g = greedy(p);
    const double planned = longest(p, plan_tours(p, {}, pure)), from_greedy = longest(p, plan_tours(p, g, pure));
    EXPECT_LE(planned, longest(p, g) + 1e-9) << "trial " << trial;
    // Repairing the greedy tours never makes the longest one longer.
    EXPECT_LE(from_greedy, longest(p, g) + 1e-9) << "trial " << trial;
    sum_planned += planned;
    sum_greedy += longest(p, g);
  }
  EXPECT_LT(sum_planned, 0.8 * sum_greedy) << "min-max tours should be clearly shorter than greedy ones on average";
}

TEST(TourPlanner, EveryRobotGetsATargetWhileThereAreEnough) {
  // Nine targets around (0, 0), a robot there and one 30 m away: the min-max split leaves the far
  // robot idle (any target makes its tour the longest); every_robot_busy sends it to the nearest.
  std::vector<Eigen::Vector2d> targets;
  for (int k = 0; k < 9; ++k) targets.push_back({std::cos(k * 0.7), std::sin(k * 0.7)});
  const TourProblem p = euclidean({{0.0, 0.0}, {30.0, 0.0}}, targets);
  TourOptions pure;
  pure.every_robot_busy = false;
  EXPECT_TRUE(plan_tours(p, {}, pure)[1].empty());
  const Tours busy = plan_tours(p);
  ASSERT_EQ(busy[1].size(), 1u);
  EXPECT_EQ(busy[1][0], 0) << "the far robot takes the target nearest to it";
  EXPECT_EQ(busy[0].size(), 8u);
}

TEST(TourPlanner, StableForTheSameInputAndPreviousTours) {
  std::mt19937 rng(23);
  for (int trial = 0; trial < 50; ++trial) {
    const TourProblem p = euclidean(random_points(rng, 1 + trial % 6), random_points(rng, 3 + trial % 20));
    const Tours first = plan_tours(p);
    EXPECT_EQ(plan_tours(p), first) << "same input, other tours";
    // Given its own answer as the previous tours, it keeps them.
    EXPECT_EQ(plan_tours(p, first), first) << "trial " << trial;
  }
}

TEST(TourPlanner, RepairKeepsThePlanWhenATargetVanishesAndOneAppears) {
  // Robots that started at x = 0 and x = 11 with targets at x = 1..10 reached their first targets
  // (x = 1 and x = 10 are gone, the robots stand there); a target appeared at x = 5.5 between the
  // halves. The halves stay as they were and the new target goes to the end of one of them.
  std::vector<Eigen::Vector2d> targets;
  for (int x = 2; x <= 9; ++x) targets.push_back({double(x), 0.0});
  targets.push_back({5.5, 0.0});
  const TourProblem p = euclidean({{1.0, 0.0}, {10.0, 0.0}}, targets);
  const Tours previous = {{0, 1, 2, 3}, {7, 6, 5, 4}};  // x = 2..5 and x = 9..6
  const Tours tours = plan_tours(p, previous);
  EXPECT_EQ(tours[0], (std::vector<int>{0, 1, 2, 3, 8}));
  EXPECT_EQ(tours[1], previous[1]);
  EXPECT_DOUBLE_EQ(longest(p, tours), 4.5);
}

TEST(TourPlanner, PreviousToursWithStaleEntriesAreCleaned) {
  const TourProblem p = euclidean({{0.0, 0.0}, {10.0, 0.0}}, {{1.0, 0.0}, {9.0, 0.0}});
  // Out of range, repeated, and negative indices are dropped; the targets are still each planned once.
  const Tours tours = plan_tours(p, {{5, 0, 0, -1}, {0, 1}});
  EXPECT_EQ(tours, (Tours{{0}, {1}}));
}

TEST(TourPlanner, AFarRobotHandsItsOnlyTargetToAnIdleOneBesideIt) {
  // Last round robot 0 was given the target; now robot 1, idle, stands beside it and robot 0 is
  // 30 m away. Keeping every robot busy must not keep the far robot on it.
  const TourProblem p = euclidean({{30.0, 0.0}, {1.0, 0.0}}, {{0.0, 0.0}});
  EXPECT_EQ(plan_tours(p, {{0}, {}}), (Tours{{}, {0}}));
}

// The weighted latency of all tours.
double total_latency(const TourProblem& p, const std::vector<double>& w, const Tours& tours) {
  double sum = 0.0;
  for (std::size_t r = 0; r < tours.size(); ++r) sum += tour_latency(p, w, int(r), tours[r]);
  return sum;
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
  EXPECT_ANY_THROW(plan_tours(p));
  EXPECT_ANY_THROW(plan_latency_tours(p, {}));
  const TourProblem q = euclidean({{0.0, 0.0}}, {{1.0, 0.0}, {2.0, 0.0}});
  EXPECT_ANY_THROW(plan_latency_tours(q, {1.0}));         // one weight for two targets
  EXPECT_ANY_THROW(plan_latency_tours(q, {1.0, -1.0}));   // a negative weight
}

}  // namespace
}  // namespace fleetmap::exploration
