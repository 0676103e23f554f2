#include "exploration/strategy.h"

#include <gtest/gtest.h>

#include <limits>
#include <map>
#include <random>
#include <set>

#include "tests/test_support.h"

namespace fleetmap::exploration {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Target target_at(double x, double y) {
  Target t;
  t.goal_m = {x, y};
  t.cells = 5;
  return t;
}

AssignmentRobot robot(int index, int team, Eigen::Vector2d at, std::vector<double> costs) {
  AssignmentRobot r;
  r.team_index = index;
  r.team_size = team;
  r.position_m = at;
  r.cost_m = std::move(costs);
  return r;
}

AssignmentInput random_input(std::mt19937& rng, int robots, int targets, double unreachable) {
  AssignmentInput in;
  std::uniform_real_distribution<double> pos(0.0, 20.0), cost(0.5, 30.0);
  std::bernoulli_distribution lost(unreachable);
  for (int t = 0; t < targets; ++t) in.targets.push_back(target_at(pos(rng), pos(rng)));
  for (int i = 0; i < robots; ++i) {
    std::vector<double> c;
    for (int t = 0; t < targets; ++t) c.push_back(lost(rng) ? kInf : cost(rng));
    in.robots.push_back(robot(i, robots, {pos(rng), pos(rng)}, c));
  }
  return in;
}

class EveryStrategy : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryStrategy, AssignsReachableTargetsOnly) {
  const auto s = make_strategy(GetParam());
  EXPECT_EQ(s->name(), GetParam());
  std::mt19937 rng(11);
  for (int trial = 0; trial < 300; ++trial) {
    const AssignmentInput in = random_input(rng, 1 + trial % 9, trial % 13, 0.3);
    const auto a = s->assign(in);
    ASSERT_EQ(a.size(), in.robots.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (a[i] < 0) continue;
      ASSERT_LT(a[i], int(in.targets.size()));
      EXPECT_TRUE(std::isfinite(in.robots[i].cost_m[std::size_t(a[i])])) << "robot sent to an unreachable target";
    }
    // A robot that can reach some target gets one unless a joint strategy gave them all away.
    for (std::size_t i = 0; i < a.size(); ++i) {
      const bool can_reach = std::any_of(in.robots[i].cost_m.begin(), in.robots[i].cost_m.end(),
                                         [](double c) { return std::isfinite(c); });
      if (!s->joint() && can_reach) {
        EXPECT_GE(a[i], 0);
      }
      if (!can_reach) {
        EXPECT_EQ(a[i], -1);
      }
    }
  }
}

TEST_P(EveryStrategy, JointStrategiesNeverShareATargetWhileThereAreEnough) {
  const auto s = make_strategy(GetParam());
  if (!s->joint()) return;  // uncoordinated and directional decide robot by robot by design
  std::mt19937 rng(5);
  for (int trial = 0; trial < 300; ++trial) {
    const int robots = 1 + trial % 9;
    const AssignmentInput in = random_input(rng, robots, robots + trial % 5, 0.0);
    const auto a = s->assign(in);
    std::map<int, int> used;
    for (int t : a) {
      // Coordinated and optimized give every robot a target when there are enough (the auction may
      // leave a robot out when another one is cheaper for everything); so do the tours, whose
      // minimum-latency split may leave a robot free, which then drives ahead to a target on
      // another robot's tour: never more than two robots at one target.
      if (GetParam() != "market") {
        ASSERT_GE(t, 0) << "every robot can reach every target: all get one";
      }
      if (t >= 0) {
        EXPECT_LE(++used[t], GetParam() == "tour" ? 2 : 1) << GetParam() << " sent too many robots to target " << t;
      }
    }
  }
}

// Asked for its scores (a replay records them), every built-in strategy makes the same choices and
// says why: each robot's candidates are the targets it can reach, with one value per named term,
// and no candidate left to nobody scores better than the one it got; the Hungarian assignment is
// optimal instead (no swap of two robots' targets, and no move to a free target, lowers its total).
TEST_P(EveryStrategy, ReportsScoresThatExplainTheSameChoices) {
  const auto plain = make_strategy(GetParam()), scored = make_strategy(GetParam());
  std::mt19937 rng(23);
  for (int trial = 0; trial < 60; ++trial) {
    AssignmentInput in = random_input(rng, 1 + trial % 6, 1 + trial % 11, 0.2);
    const auto expected = plain->assign(in);
    ScoreSheet sheet;
    in.scores = &sheet;
    const auto a = scored->assign(in);
    ASSERT_EQ(a, expected) << "asking for scores changed the choice (trial " << trial << ")";
    ASSERT_EQ(sheet.robots.size(), in.robots.size());
    ASSERT_FALSE(sheet.terms.empty());
    EXPECT_FALSE(sheet.rule.empty());
    const auto better = [&](double x, double y) { return sheet.lower_is_better ? x < y - 1e-9 : x > y + 1e-9; };
    std::set<int> given(a.begin(), a.end());
    std::vector<std::map<int, double>> score(in.robots.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      for (const auto& c : sheet.robots[i].candidates) {
        ASSERT_EQ(c.terms.size(), sheet.terms.size());
        ASSERT_TRUE(std::isfinite(in.robots[i].cost_m[std::size_t(c.target)])) << "an unreachable candidate";
        score[i][c.target] = c.score;
      }
      if (a[i] < 0) continue;
      ASSERT_TRUE(score[i].count(a[i])) << "robot " << i << "'s target is not among its candidates";
      if (GetParam() == "optimized") continue;
      for (const auto& [t, v] : score[i])
        EXPECT_FALSE(!given.count(t) && better(v, score[i][a[i]]))
            << GetParam() << ": robot " << i << " got target " << a[i] << " (" << score[i][a[i]] << ") but free target " << t
            << " scored " << v;
    }
    if (GetParam() != "optimized") continue;
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (a[i] < 0) continue;
      for (const auto& [t, v] : score[i]) EXPECT_FALSE(!given.count(t) && v < score[i][a[i]] - 1e-9) << "a free target is cheaper";
      for (std::size_t j = 0; j < a.size(); ++j) {
        if (j == i || a[j] < 0 || !score[i].count(a[j]) || !score[j].count(a[i])) continue;
        EXPECT_LE(score[i][a[i]] + score[j][a[j]], score[i][a[j]] + score[j][a[i]] + 1e-9) << "swapping two robots' targets is cheaper";
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(All, EveryStrategy, ::testing::ValuesIn(strategy_names()));

TEST(Strategies, UnknownNameListsTheValidOnes) {
  fleetmap::testing::expect_input_error([] { make_strategy("greedy"); },
                                        {"unknown strategy 'greedy'", "uncoordinated", "coordinated", "optimized",
                                         "directional", "market"});
}

TEST(Strategies, UncoordinatedTakesTheNearest) {
  AssignmentInput in;
  in.targets = {target_at(0, 0), target_at(5, 5), target_at(9, 9)};
  in.robots = {robot(0, 2, {0, 0}, {4, 2, 3}), robot(1, 2, {0, 0}, {4, 2, 3})};
  EXPECT_EQ(make_strategy("uncoordinated")->assign(in), (std::vector<int>{1, 1}));
}

TEST(Strategies, OptimizedFinishesTogetherWhereGreedyDoesNot) {
  // The wave-algorithm paper, Fig. 4: the greedy assignment takes the cheapest pair first (robot 2 -> a) and leaves
  // robot 1 the long way; squared costs prefer the assignment whose slowest robot is faster.
  AssignmentInput in;
  in.sensor_range_m = 1.0;  // targets far apart: no utility interplay
  in.targets = {target_at(0, 0), target_at(20, 0)};  // a, b
  in.robots = {robot(0, 2, {5, 0}, {2, 6}), robot(1, 2, {6, 0}, {1, 5})};
  EXPECT_EQ(make_strategy("coordinated")->assign(in), (std::vector<int>{1, 0}));
  EXPECT_EQ(make_strategy("optimized")->assign(in), (std::vector<int>{0, 1}));
}

TEST(Strategies, CoordinatedSpreadsRobotsOverTheSensorRange) {
  // Two targets 0.5 m apart near both robots, one far away. Once one near target is taken the
  // other one's utility drops (it will be seen anyway), so with a small beta the second robot goes far.
  AssignmentInput in;
  in.sensor_range_m = 4.0;
  in.targets = {target_at(0, 0), target_at(0.5, 0), target_at(10, 0)};
  in.robots = {robot(0, 2, {0, 1}, {1, 1, 3}), robot(1, 2, {0, 1}, {1, 1, 3})};
  const auto a = make_strategy("coordinated", {{"beta", "0.1"}})->assign(in);
  EXPECT_EQ(std::set<int>(a.begin(), a.end()).count(2), 1u) << "one robot should take the far target";
  // Uncoordinated robots both stay near.
  const auto u = make_strategy("uncoordinated")->assign(in);
  EXPECT_NE(u[0], 2);
  EXPECT_NE(u[1], 2);
}

TEST(Strategies, DirectionalRobotsPreferTheirOwnDirection) {
  // Robot 0 of 2 prefers east (0 rad), robot 1 west (pi); targets east and west cost the same.
  AssignmentInput in;
  in.targets = {target_at(-5, 0), target_at(5, 0)};
  in.robots = {robot(0, 2, {0, 0}, {5, 5}), robot(1, 2, {0, 0}, {5, 5})};
  EXPECT_EQ(make_strategy("directional")->assign(in), (std::vector<int>{1, 0}));
}

TEST(Strategies, MarketBalancesBundles) {
  // Four targets in a row; a min-max auction gives each of two robots its own side.
  AssignmentInput in;
  in.targets = {target_at(-6, 0), target_at(-3, 0), target_at(3, 0), target_at(6, 0)};
  in.robots = {robot(0, 2, {-1, 0}, {5, 2, 4, 7}), robot(1, 2, {1, 0}, {7, 4, 2, 5})};
  EXPECT_EQ(make_strategy("market")->assign(in), (std::vector<int>{1, 2}));
}

// Targets on a line between two robots: each drives to the near end of its own half, and the next
// round, with the targets each robot reached gone and the robots moved, the plan carries on.
TEST(Strategies, TourRobotsWorkTheirOwnHalfAndKeepTheirPlan) {
  const auto s = make_strategy("tour");
  const auto line = [](double from, double to) {
    AssignmentInput in;
    for (double x = from; x <= to + 1e-9; x += 1.0) in.targets.push_back(target_at(x, 0));
    return in;
  };
  const auto costs_from = [](const AssignmentInput& in, double x) {
    std::vector<double> c;
    for (const auto& t : in.targets) c.push_back(std::abs(t.goal_m.x() - x));
    return c;
  };
  AssignmentInput in = line(1, 10);
  in.robots = {robot(0, 2, {0, 0}, costs_from(in, 0)), robot(1, 2, {11, 0}, costs_from(in, 11))};
  EXPECT_EQ(s->assign(in), (std::vector<int>{0, 9}));  // x = 1 and x = 10
  // Both reached their first target (x = 1 and x = 10 are gone) and a target appeared in robot 0's
  // half (x = 4.6).
  AssignmentInput next = line(2, 9);
  next.targets.push_back(target_at(4.6, 0.5));
  next.robots = {robot(0, 2, {1, 0}, costs_from(next, 1)), robot(1, 2, {10, 0}, costs_from(next, 10))};
  EXPECT_EQ(s->assign(next), (std::vector<int>{0, 7}));  // x = 2 and x = 9: each carries on along its half
  // The same round again gives the same answer.
  EXPECT_EQ(s->assign(next), (std::vector<int>{0, 7}));
}

TEST(Strategies, TourUsesTheWaveCostsBetweenTargets) {
  // Targets 1 m apart in straight line, but 10 apart by the wave (a wall between them); the robot
  // reaches the first at 5 and the second at 2. Either tour crosses the wall once, so the robot
  // starts with the cheaper first leg: 2 + 10 against 5 + 10.
  const auto s = make_strategy("tour");
  AssignmentInput in;
  in.targets = {target_at(1, 0), target_at(2, 0)};
  in.robots = {robot(0, 1, {0, 0}, {5, 2})};
  in.target_costs_m = [] { return Eigen::MatrixXd{{0, 10}, {10, 0}}; };
  EXPECT_EQ(s->assign(in), (std::vector<int>{1}));
  EXPECT_EQ(target_costs(in)(0, 1), 10.0);
  in.target_costs_m = nullptr;
  EXPECT_DOUBLE_EQ(target_costs(in)(0, 1), 1.0);  // straight line without wave costs
}

TEST(Strategies, TourSendsARobotWithAnEmptyTourAheadWhereMostUnknownAreaLies) {
  // Robot 0 stands between two doorways 2 m away each; robot 1 is 30 m from both. Robot 0 reaches
  // both sooner than robot 1 reaches either, so robot 1's tour is empty; it does not wait but drives
  // toward the doorway with the larger room behind it (the one robot 0 visits second), where new
  // frontiers will open.
  AssignmentInput in;
  in.targets = {target_at(-2, 0), target_at(2, 0)};
  in.robots = {robot(0, 2, {0, 0}, {2, 2}), robot(1, 2, {30, 0}, {32, 30})};
  in.target_costs_m = [] { return Eigen::MatrixXd{{0, 4}, {4, 0}}; };
  for (const int large : {1, 0}) {
    in.target_gains_m2 = [large] { return large == 1 ? std::vector<double>{5.0, 6.0} : std::vector<double>{6.0, 5.0}; };
    const auto a = make_strategy("tour")->assign(in);
    EXPECT_EQ(a[1], large) << "the free robot drives ahead to the larger room";
    EXPECT_EQ(a[0], large) << "robot 0 visits the larger room first";
  }
  // With one target only, the far robot still goes there rather than stand still.
  in.targets.pop_back();
  in.robots = {robot(0, 2, {0, 0}, {2}), robot(1, 2, {30, 0}, {32})};
  in.target_costs_m = nullptr;
  in.target_gains_m2 = [] { return std::vector<double>{5.0}; };
  EXPECT_EQ(make_strategy("tour")->assign(in), (std::vector<int>{0, 0}));
}

TEST(Strategies, TourGoesFirstWhereMoreUnknownAreaLies) {
  // A robot at 0 between a sliver at x = -1 (nothing behind it) and a doorway at x = 2 with 20 m^2
  // of unseen room behind it: without the areas it takes the near sliver first, with them the door.
  AssignmentInput in;
  in.targets = {target_at(-1, 0), target_at(2, 0)};
  in.robots = {robot(0, 1, {0, 0}, {1, 2})};
  in.target_costs_m = [] { return Eigen::MatrixXd{{0, 3}, {3, 0}}; };
  EXPECT_EQ(make_strategy("tour")->assign(in), (std::vector<int>{0}));
  in.target_gains_m2 = [] { return std::vector<double>{0.0, 20.0}; };
  EXPECT_EQ(make_strategy("tour")->assign(in), (std::vector<int>{1}));
}

}  // namespace
}  // namespace fleetmap::exploration
