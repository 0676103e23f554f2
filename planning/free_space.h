#pragma once
// Where a disc robot may be on an occupancy grid: the configuration space every planner searches.
// Clearance comes from an exact Euclidean distance transform (OpenCV distanceTransform, the
// Felzenszwalb-Huttenlocher algorithm behind DIST_MASK_PRECISE); a position is valid when the
// clearance of its cell exceeds the robot radius.
#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <vector>

#include "core/grid_geometry.h"
#include "mapping/occupancy_grid.h"

namespace fleetmap::planning {

using core::Cell;
using core::GridGeometry;

// What a planner makes of cells nobody has seen.
enum class UnknownCells { Obstacle, Free };

struct FreeSpaceOptions {
  double robot_radius_m = 0.2;
  // Obstacle by default: a path through unseen space may hit a wall nobody has mapped.
  UnknownCells unknown = UnknownCells::Obstacle;
};

class FreeSpace {
 public:
  // Throws InputError when the radius is negative or not finite.
  explicit FreeSpace(const mapping::OccupancyGrid& grid, const FreeSpaceOptions& options = {});

  const GridGeometry& geometry() const { return geometry_; }
  const FreeSpaceOptions& options() const { return options_; }
  double robot_radius() const { return options_.robot_radius_m; }

  // An obstacle cell: Occupied, or Unknown when unknown cells are obstacles. Cells outside the
  // grid are obstacles too, so no robot leaves the map.
  bool is_obstacle(const Cell& c) const;
  // The grid's state of the cell (Unknown outside the grid).
  mapping::CellState cell_state(const Cell& c) const {
    return contains(c) ? static_cast<mapping::CellState>(state_[index(c)]) : mapping::CellState::Unknown;
  }
  // Metres from the cell's centre to the centre of the nearest obstacle cell (the map's outside
  // counts); 0 for obstacle cells and cells outside the grid.
  double clearance(const Cell& c) const;
  // The clearance of the cell holding `p` (0 outside the grid).
  double clearance_at(const Eigen::Vector2d& p) const;

  // The robot's centre may be in this cell: its clearance exceeds the robot radius.
  bool valid(const Cell& c) const { return contains(c) && valid_[index(c)] != 0; }
  bool valid(const Eigen::Vector2d& p) const;

  // Every cell the segment crosses is valid. The cells are enumerated exactly (Amanatides & Woo),
  // so a segment that clips the corner of an invalid cell is invalid: no path cuts a corner.
  bool segment_valid(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const;
  // Metres from `a` along the segment to where it enters its first invalid cell, or nullopt when
  // the whole segment is valid.
  std::optional<double> first_invalid_distance(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const;
  // Every waypoint and every segment between consecutive waypoints is valid (an empty path is not).
  bool path_valid(const std::vector<Eigen::Vector2d>& path) const;

  // Two valid cells lie in one connected region of valid cells (4-neighbourhood, which is exactly
  // how a continuous path moves between cells). False when either is invalid. A path between two
  // cells exists iff this holds, so a planner can answer "unreachable" at once.
  bool connected(const Cell& a, const Cell& b) const;
  // The region label of a valid cell (> 0), 0 for invalid cells.
  int region(const Cell& c) const { return contains(c) ? region_[index(c)] : 0; }

  std::int64_t valid_count() const { return valid_count_; }

 private:
  bool contains(const Cell& c) const { return geometry_.contains(c); }
  // GridGeometry::world_to_cell, without its sine and cosine when the map is not rotated.
  std::optional<Cell> locate(const Eigen::Vector2d& p) const;
  std::size_t index(const Cell& c) const { return static_cast<std::size_t>(geometry_.index(c)); }

  GridGeometry geometry_;
  FreeSpaceOptions options_;
  bool axis_aligned_ = true;  // the origin's rotation is 0
  std::vector<float> clearance_;  // metres, in GridGeometry::index order
  std::vector<std::uint8_t> state_;  // mapping::CellState values
  std::vector<std::uint8_t> obstacle_;
  std::vector<std::uint8_t> valid_;
  std::vector<int> region_;
  std::int64_t valid_count_ = 0;
};

}  // namespace fleetmap::planning
