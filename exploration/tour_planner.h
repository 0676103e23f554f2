#pragma once
// Open tours for a team of robots through a set of targets, split so that the longest tour is as
// short as it can be found (the min-max multiple travelling salesman problem with open tours, as
// the multi-robot exploration planners of Cao et al. 2021 (TARE) and Zhou et al. 2023 (RACER)
// pose it), or so that the weighted sum of the times the targets are reached is (the multi-robot
// minimum-latency problem): cheapest insertion, then local search with 2-opt, relocate and
// exchange moves.
// Pure data in, tours out: the costs come from waves over a robot's map (see tour_strategy.cpp).
#include <Eigen/Core>

#include <vector>

namespace fleetmap::exploration {

struct TourProblem {
  // Robots x targets: the cost from each robot to each target; +inf where the robot cannot go.
  Eigen::MatrixXd start_cost;
  // Targets x targets: the cost between two targets (symmetric); +inf between unconnected ones.
  Eigen::MatrixXd between;
};

struct TourOptions {
  // Local search passes (each tries every move once and makes every improving one); it stops
  // earlier when a pass improves nothing.
  int max_passes = 30;
  // A move must shorten the longest tour, or the tours' total with the longest no longer, by more
  // than this (in cost units): floating-point noise never swaps two equal solutions.
  double tolerance = 1e-6;
  // Every robot that can reach a target gets one while there are enough to go round (taken from a
  // tour of two or more where the longest tour grows least), and no move empties a tour: the
  // min-max split alone leaves a robot idle whenever it is farther from every target than the
  // longest tour, yet an exploring robot finds new frontiers on its way. plan_tours only: the
  // minimum-latency tours of plan_latency_tours leave a robot free only when that is better.
  bool every_robot_busy = true;
};

// Per robot, its targets in visiting order (indices into the problem's targets).
using Tours = std::vector<std::vector<int>>;

// The length of robot `robot`'s open tour: to its first target, then from target to target
// (+inf when a leg is not possible).
double tour_length(const TourProblem& problem, int robot, const std::vector<int>& tour);

// Tours in which every target some robot can reach is visited exactly once, by a robot that can
// reach it; targets no robot reaches are left out. `initial` (optional, one tour per robot) is the
// starting solution: its targets stay where they are unless a move improves the tours (targets
// out of range, repeated, or not reachable by their robot are dropped from it), and the
// targets it lacks are inserted, one at a time, farthest from every robot first, where the
// longest tour grows least (then the total); then idle robots are given a target (see
// every_robot_busy). The same problem and initial tours give the same
// tours. The objective, compared in this order: the longest tour, then the sum of the tours.
Tours plan_tours(const TourProblem& problem, const Tours& initial = {}, const TourOptions& options = {});

// Tours that reveal the most, soonest: the weighted sum, over the targets, of the time each is
// reached (its weight times the length of its robot's tour up to it) is made as small as the search
// finds (the multi-robot minimum-latency problem; with the unknown area behind each target as its
// weight, the area the team reveals over time, as TARE and RACER weigh tours by their gain).
// Unlike the min-max split, every tour counts: a robot near a target takes it rather than a far one,
// and a robot with nothing near stays free. Same input rules as plan_tours; `weight` has one
// non-negative entry per target (empty: all 1).
Tours plan_latency_tours(const TourProblem& problem, const std::vector<double>& weight, const Tours& initial = {},
                         const TourOptions& options = {});

// The weighted latency of robot `robot`'s tour (+inf when a leg is not possible).
double tour_latency(const TourProblem& problem, const std::vector<double>& weight, int robot, const std::vector<int>& tour);

}  // namespace fleetmap::exploration
