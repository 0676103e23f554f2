#pragma once
// The simulated world: the ground-truth grid of a map and its point landmarks. Everything that is
// not free in the map blocks robots and sensors.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/random.h"
#include "mapping/occupancy_grid.h"

namespace fleetmap::sim {

using core::Cell;

// What robots starting at given points can observe of a world (DESIGN.md §5). A pose is a cell
// centre where the robot fits (exploration::fitting_cells on the true map: farther than its radius
// from every cell that is not free) and that it can reach from a start (4-connected through such
// cells, as the explorer's waves go). A free cell is observable when it lies within the sensor range
// of a pose and in its line of sight (the traversal every beam takes). Cells seen through a gap
// the robot cannot pass count only as far as they can be seen from the reachable side.
struct ObservableSpace {
  std::vector<int> observable;   // sorted cell indices: coverage is the share of these observed
  std::vector<int> unreachable;  // the observable cells no robot's body can cover (outside every pose's disc)
  std::int64_t poses = 0;        // cells where a robot's centre can be
  std::int64_t free_cells = 0;   // every free cell of the map
  // Poses in the largest region a robot of this radius can reach (ReachableRegions), wherever the
  // starts are: `poses` below it means the robots start outside it.
  std::int64_t largest_region_poses = 0;
  int start_regions = 0;         // the regions the starts lie in: robots of two never meet
  double cell_area_m2 = 0.0;
};

// The places a robot's centre can be, split into the regions it can drive between: 4-connected
// components of the cells where it fits (exploration::fitting_cells on the true map, as
// ObservableSpace's poses are found).
struct ReachableRegions {
  std::vector<int> label;            // per cell: -1 where the robot does not fit, else its region
  std::vector<std::int64_t> cells;   // the size of each region, in cells
  int largest = -1;                  // the region with the most cells; -1 when the robot fits nowhere

  int at(int cell_index) const { return label[std::size_t(cell_index)]; }
};

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
  // The point of the blocked cells (their squares; the map's outside counts) nearest to p, within
  // horizon_m; nullopt when none is that near.
  std::optional<Eigen::Vector2d> nearest_blocked_point(const Eigen::Vector2d& p, double horizon_m) const;

  // Where a robot of radius `robot_radius_m` can be, region by region.
  ReachableRegions reachable_regions(double robot_radius_m) const;

  // The space exploration is measured on, for robots of radius `robot_radius_m` with a range sensor
  // of `sensor_range_m` starting at `starts` (see ObservableSpace). The one definition behind
  // coverage, the lower bound and the run's report.
  ObservableSpace observable_space(const std::vector<Eigen::Vector2d>& starts, double robot_radius_m,
                                          double sensor_range_m) const;

 private:
  mapping::OccupancyGrid truth_;
  std::vector<Eigen::Vector2d> landmarks_;
  std::vector<float> centre_clearance_m_;  // distance transform: cell centre to nearest blocked centre
};

// Point landmarks on free cells beside walls, about `per_metre` per metre of wall, seeded.
std::vector<Eigen::Vector2d> landmarks_along_walls(const mapping::OccupancyGrid& truth, double per_metre, core::Random& rng);

}  // namespace fleetmap::sim
