#include "sweep/lower_bound.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "exploration/wave.h"

namespace fleetmap::sweep {

ExplorationLowerBound exploration_lower_bound(const sim::World& world, const std::vector<Eigen::Vector2d>& starts,
                                              const LowerBoundOptions& options) {
  const std::vector<int> observable =
      world.observable_space(starts, options.robot_radius_m, options.sensor_range_m).observable;
  return exploration_lower_bound(world, starts, observable, options);
}

ExplorationLowerBound exploration_lower_bound(const sim::World& world, const std::vector<Eigen::Vector2d>& starts,
                                              const std::vector<int>& observable, const LowerBoundOptions& options) {
  ExplorationLowerBound b;
  const auto& g = world.geometry();
  const double cell = g.resolution();
  const std::int64_t n_cells = std::int64_t(observable.size());
  if (n_cells == 0 || starts.empty()) return b;
  // At least this many cells are known when coverage >= options.coverage.
  const std::int64_t needed = std::clamp<std::int64_t>(
      std::int64_t(std::ceil(options.coverage * double(n_cells) - 1e-9)), 0, n_cells);
  b.free_area_m2 = double(n_cells) * cell * cell;
  const double s = options.step_length_m;
  if (needed == 0 || !(s > 0.0)) return b;

  std::vector<std::uint8_t> passable(std::size_t(g.cell_count()));
  for (int i = 0; i < int(passable.size()); ++i) passable[std::size_t(i)] = !world.blocked(g.cell_of_index(i));
  std::vector<core::Cell> sources;
  for (const auto& p : starts) sources.push_back(g.world_to_cell_unbounded(p));
  exploration::WaveOptions wo;
  wo.eight_connected = true;
  const auto wave = exploration::compute_wave({g.width(), g.height(), passable, {}, {}}, sources, wo);

  // Distances of the observable cells; the `needed`-th smallest bounds the farthest cell a robot
  // must have come near. Every observable cell is reached by the wave: a line of sight runs through
  // 4-connected free cells.
  std::vector<double> distance;
  distance.reserve(observable.size());
  for (int idx : observable) distance.push_back(double(wave.cost_at(idx)) * cell / kOctileStretch);
  const auto nth = distance.begin() + (needed - 1);
  std::nth_element(distance.begin(), nth, distance.end());
  b.quantile_distance_m = *nth;
  const double R = options.sensor_range_m, slack = std::sqrt(2.0) * cell;
  const double travel = b.quantile_distance_m - R - slack;
  b.travel_steps = travel > 0.0 ? int(std::ceil(travel / s - 1e-9)) : 0;

  const double R_cells = R + slack;
  const double per_robot = double(needed) * cell * cell / double(starts.size()) - M_PI * R_cells * R_cells;
  b.area_steps = per_robot > 0.0 ? int(std::ceil(per_robot / (2.0 * R_cells * s) - 1e-9)) : 0;
  return b;
}

std::optional<double> exploration_efficiency(int lower_bound_steps, const std::optional<int>& steps_to) {
  if (!steps_to) return std::nullopt;
  if (*steps_to <= 0 && lower_bound_steps <= 0) return 1.0;
  return double(lower_bound_steps) / double(std::max(1, *steps_to));
}

}  // namespace fleetmap::sweep
