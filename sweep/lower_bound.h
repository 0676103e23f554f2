#pragma once
// Exploration metrics that compare runs across maps and with other papers (DESIGN.md §5): a lower
// bound on the steps any team needs to observe a share of the observable free space, computed from
// the ground truth alone, and efficiency = lower bound / steps taken. README.md ("Benchmarking
// strategies") states the bound and why it holds.
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "sim/world.h"

namespace fleetmap::sweep {

struct LowerBoundOptions {
  double coverage = 0.99;        // the bound is on the steps until this share of the observable cells is known
  double sensor_range_m = 4.0;   // R: nothing farther than R from a robot is observed
  double step_length_m = 0.5;    // s: the farthest a robot moves in one step (max speed x period)
  double robot_radius_m = 0.2;   // where a robot fits, for the observable cells (World::observable_space)
};

struct ExplorationLowerBound {
  // Travel: among the observable cells, the one at the coverage quantile of the distance from
  // the nearest start (D: the 8-connected wave distance divided by kOctileStretch) must come within
  // R of a robot: ceil((D - R - sqrt(2) * cell) / s).
  int travel_steps = 0;
  // Area: a robot that moved k steps has observed at most pi R'^2 + 2 R' s k square metres of cells
  // (R' = R + sqrt(2) * cell), so n robots need ceil((coverage * A / n - pi R'^2) / (2 R' s)).
  int area_steps = 0;
  double quantile_distance_m = 0.0;  // D of the cell at the coverage quantile
  double free_area_m2 = 0.0;         // A: the observable cells' area
  int steps() const { return travel_steps > area_steps ? travel_steps : area_steps; }
};

// The most an 8-connected grid path (straight steps 1, diagonal steps sqrt(2)) can be longer than
// the straight line between its ends: sqrt(4 - 2 sqrt(2)) at 22.5 degrees.
inline constexpr double kOctileStretch = 1.0823922002923940;

// For robots starting at `starts` (metres) in `world`, on the cells coverage is measured on
// (World::observable_space with the options' radius and range).
ExplorationLowerBound exploration_lower_bound(const sim::World& world, const std::vector<Eigen::Vector2d>& starts,
                                              const LowerBoundOptions& options);
// The same on cells already computed by World::observable_space (sorted indices).
ExplorationLowerBound exploration_lower_bound(const sim::World& world, const std::vector<Eigen::Vector2d>& starts,
                                              const std::vector<int>& observable, const LowerBoundOptions& options);

// lower_bound_steps / steps_to, 1 when both are 0; nullopt when the level was never reached.
std::optional<double> exploration_efficiency(int lower_bound_steps, const std::optional<int>& steps_to);

}  // namespace fleetmap::sweep
