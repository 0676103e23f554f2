#pragma once
// Open tours for a team of robots through a set of targets, so that the weighted sum of the times
// the targets are reached is as small as the search finds (the multi-robot minimum-latency problem;
// with each target's unknown area as its weight, the tours reveal the most soonest, as the
// multi-robot exploration planners of Cao et al. 2021 (TARE) and Zhou et al. 2023 (RACER) weigh
// their tours by gain): cheapest insertion, then local search with 2-opt, relocate and exchange
// moves.
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
  // A move must lower the weighted latency by more than this (in cost units): floating-point noise
  // never swaps two equal solutions.
  double tolerance = 1e-6;
};

// Per robot, its targets in visiting order (indices into the problem's targets).
using Tours = std::vector<std::vector<int>>;

// The length of robot `robot`'s open tour: to its first target, then from target to target
// (+inf when a leg is not possible).
double tour_length(const TourProblem& problem, int robot, const std::vector<int>& tour);

// Tours that reveal the most, soonest: the weighted sum, over the targets, of the time each is
// reached (its weight times the length of its robot's tour up to it) is made as small as the search
// finds. Every tour counts: a robot near a target takes it rather than a far one, and a robot with
// nothing near stays free. Every target some robot can reach is visited exactly once, by a robot
// that can reach it; targets no robot reaches are left out. `initial` (optional, one tour per
// robot) is the starting solution: its targets stay where they are unless a move improves the
// tours (targets out of range, repeated, or not reachable by their robot are dropped from it), and
// the targets it lacks are inserted. The same input gives the same tours. `weight` has one
// non-negative entry per target (empty: all 1).
Tours plan_latency_tours(const TourProblem& problem, const std::vector<double>& weight, const Tours& initial = {},
                         const TourOptions& options = {});

// The weighted latency of robot `robot`'s tour (+inf when a leg is not possible).
double tour_latency(const TourProblem& problem, const std::vector<double>& weight, int robot, const std::vector<int>& tour);

}  // namespace fleetmap::exploration
