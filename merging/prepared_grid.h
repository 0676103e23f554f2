#pragma once
// A grid prepared for alignment: a pyramid of cell masks, the wall cells a range sensor sees,
// distance fields to them, and their local structure. Every merge method and the common
// refine / score / decide steps work on two PreparedGrids.
//
// This header is the installed face: what a merge method a program registers can read (the grid,
// its wall cells with their local structure). The pyramid levels are OpenCV images and stay inside
// the library (merging/grid_level.h), so that installed headers speak fleetmap's own types.
#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "core/transform2.h"
#include "mapping/occupancy_grid.h"

namespace fleetmap::merging {

// One pyramid level (merging/grid_level.h).
struct GridLevel;

// Local shape of the walls around a fine wall point: S = I - C / trace(C), with C the covariance of
// the wall cells within 3 cells. S is n n^T on a straight wall (n its normal) and I / 2 at a corner
// or a blob: the directions in which the point pins an alignment down.
struct WallPoint {
  Eigen::Vector2f position = Eigen::Vector2f::Zero();
  Eigen::Matrix2f structure = Eigen::Matrix2f::Identity() * 0.5f;
  Eigen::Vector2f normal = Eigen::Vector2f::Zero();  // toward the side it was seen from (merging/grid_level.h)
  bool clutter = false;                              // part of a small obstacle (PrepareOptions::clutter_size_m)
  bool furniture = false;                            // part of an obstacle standing alone (PrepareOptions::furniture_size_m)
};

struct PrepareOptions {
  // Occupied specks smaller than this (8-connected cells) are noise: left out as unknown. Both
  // robots see a real obstacle; a speck seen by one only would count against a right alignment.
  int min_obstacle_cells = 3;
  // An unknown cell between a wall and free space (touching both) is free: the laser crossed it to
  // the wall, and the map's thresholds left it unknown (map_server reads cells of middling
  // probability as unknown; a real laser map at 2.5 cm often has such a seam along its walls).
  // Without free space beside it an occupied cell is no wall to align: seen on a real map,
  // 62% of the wall cells stood behind such a one-cell seam, and corridors sharing 30-50% of two
  // windows were refused for too little evidence. One cell only: a wider gap is what the robot
  // did not see.
  bool close_seams = true;
  int min_level_size = 24;         // stop the pyramid when the larger side would drop below this
  int max_refine_points = 3000;    // wall points kept per level for refinement (evenly subsampled)
  // Clutter: obstacles whose occupied cells, joined across gaps of up to clutter_gap_m (at least 2
  // cells: the dotted walls of far or grazing beams, thin walls resampled on a turned grid), span
  // at most clutter_size_m. Metres, from the grid's resolution.
  double clutter_size_m = 0.5;
  double clutter_gap_m = 0.1;
  // Obstacles standing alone (joined the same way) up to this size: desks, cabinets, pillars. They
  // match and contradict as walls do, but never stand in the other map's open space
  // (AlignmentQuality::open_space_walls): furniture moves between two visits. (The end wall of a
  // real corridor, with gaps at its corners, spanned 1.5-2 m: a wall, not furniture.)
  double furniture_size_m = 1.2;
  // Distances to walls (GridLevel::wall_distance) are exact up to this many cells of each level and
  // this value beyond: the merge compares them with a few cells only, and a capped field costs a
  // third of a full distance transform. MergeOptions need at least needed_wall_distance(options).
  double max_wall_distance = 6.0;
};

// Keeps a reference to `grid`, which must outlive it.
class PreparedGrid {
 public:
  explicit PreparedGrid(const mapping::OccupancyGrid& grid, const PrepareOptions& options = {});
  // Defined where GridLevel is complete.
  PreparedGrid(const PreparedGrid& other);
  PreparedGrid(PreparedGrid&& other) noexcept;
  PreparedGrid& operator=(const PreparedGrid& other);
  PreparedGrid& operator=(PreparedGrid&& other) noexcept;
  ~PreparedGrid();

  // Cells of the finest level (the grid's, or the box of a masked part: merging/grid_level.h).
  int width() const { return width_; }
  int height() const { return height_; }
  int level_count() const { return static_cast<int>(level_count_); }
  // Level k has cells of 2^k x 2^k fine cells; level 0 is the grid itself.
  const GridLevel& level(int k) const;
  // Every wall cell at full resolution, with its local structure (for scoring).
  const std::vector<WallPoint>& walls() const { return walls_; }
  std::int64_t known_cells() const { return known_cells_; }
  // PrepareOptions::max_wall_distance it was prepared with.
  double max_wall_distance() const { return max_wall_distance_; }
  const mapping::OccupancyGrid& grid() const { return *grid_; }

  // The finest level whose larger side is at most `cells` (the coarsest level if none is).
  int level_for_size(int cells) const;

 private:
  friend struct PreparedGridParts;  // builds masked parts (merging/grid_level.h)
  explicit PreparedGrid(const mapping::OccupancyGrid* grid);
  void set_sizes();

  const mapping::OccupancyGrid* grid_;
  std::vector<GridLevel> levels_;
  std::vector<WallPoint> walls_;
  std::int64_t known_cells_ = 0;
  double max_wall_distance_ = 0.0;
  int width_ = 0, height_ = 0;
  std::size_t level_count_ = 0;
};

// A transform between fine cell coordinates expressed between the cells of level `factor`
// (centre of coarse cell X is fine coordinate factor * X + (factor - 1) / 2), and back.
core::Transform2 to_level(const core::Transform2& fine, int factor);
core::Transform2 from_level(const core::Transform2& coarse, int factor);

}  // namespace fleetmap::merging
