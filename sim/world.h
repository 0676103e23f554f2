#pragma once
// The simulated world: the ground-truth grid of a map and its point landmarks. Everything that is
// not free in the map blocks robots and sensors.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/random.h"
#include "mapping/occupancy_grid.h"

namespace fleetmap::sim {

using core::Cell;

class World {
 public:
  World(mapping::OccupancyGrid truth, std::vector<Eigen::Vector2d> landmarks);

  const mapping::OccupancyGrid& truth() const { return truth_; }
  const core::GridGeometry& geometry() const { return truth_.geometry(); }
  const std::vector<Eigen::Vector2d>& landmarks() const { return landmarks_; }

  bool blocked(const Cell& c) const { return !truth_.contains(c) || truth_.state(c) != mapping::CellState::Free; }
  // Distance in metres from `p` to the nearest blocked cell (its square, not its centre), looking no
  // farther than `horizon_m`; returns horizon_m when nothing is nearer.
  double clearance(const Eigen::Vector2d& p, double horizon_m) const;
  // A disc of radius r at p touches no blocked cell and lies inside the map.
  bool disc_free(const Eigen::Vector2d& p, double radius_m) const;

  // Free cells in the 4-connected free region(s) holding the given points: the space robots
  // starting there can explore. Coverage is measured against these cells.
  std::vector<int> reachable_free_cells(const std::vector<Eigen::Vector2d>& starts) const;

 private:
  mapping::OccupancyGrid truth_;
  std::vector<Eigen::Vector2d> landmarks_;
  std::vector<float> centre_clearance_m_;  // distance transform: cell centre to nearest blocked centre
};

// Point landmarks on free cells beside walls, about `per_metre` per metre of wall, seeded.
std::vector<Eigen::Vector2d> landmarks_along_walls(const mapping::OccupancyGrid& truth, double per_metre, core::Random& rng);

}  // namespace fleetmap::sim
