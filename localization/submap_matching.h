#pragma once
// Matching a scan's points against a submap grid (Hess et al. 2016, sec. IV-V): Olson's (2009)
// real-time correlative search over a small window, a branch-and-bound correlative search over a
// large window for loop closures, and a least-squares refinement (Ceres) of either.
#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <vector>

#include "core/transform2.h"
#include "localization/submap_grid.h"

namespace fleetmap::localization {

using PointCloud = std::vector<Eigen::Vector2d>;

struct MatchResult {
  core::Pose2 pose;    // of the scan's frame in the grid's frame
  double score = 0.0;  // mean occupancy probability at the points, in [0, 1]
};

// The angular step at which no point moves by more than a cell: acos(1 - r^2 / (2 d^2)) for the
// farthest point at d (Olson 2009, sec. IV-C; Hess et al. 2016, eq. (7)), with d the 95th
// percentile of the points' distances.
double angular_search_step(const PointCloud& points, double resolution_m);

// The points kept one per `cell_m` square (the first in scan order): thins dense close-up returns
// so that every part of the room weighs alike.
PointCloud voxel_filter(const PointCloud& points, double cell_m);

struct CorrelativeOptions {
  double linear_window_m = 0.1;
  double angular_window_rad = 0.2;
  // A candidate's score is multiplied by exp(-(d * translation_weight + |a| * rotation_weight)^2)
  // for its distance d (m) and turn a (rad) from the prior, so that ties go to the prior.
  double translation_weight = 0.1;
  double rotation_weight = 0.1;
  // Score by the grid's hit field (SubmapGrid::hit_field, the mean over the points) instead of
  // its probabilities; the grid must keep one.
  bool hit_field = false;
};

// Real-time correlative scan matching (Olson 2009): every pose of the window around `prior` at
// the grid's resolution and the angular step. The result's score is the one the options chose.
MatchResult correlative_match(const SubmapGrid& grid, const PointCloud& points, const core::Pose2& prior,
                              const CorrelativeOptions& options = {});

// A finished submap prepared for branch and bound: level h holds, at each cell, the largest
// probability of the 2^h x 2^h cells from it upward (Hess et al. 2016, sec. V-C, eq. (14)).
class PrecomputedGrids {
 public:
  PrecomputedGrids(const SubmapGrid& grid, int depth);
  int depth() const { return int(levels_.size()) - 1; }
  double resolution() const { return resolution_; }
  // Probability x 255 at a cell of level h; outside the grid the unknown value.
  // Level h's cells, row by row, and the bounds every level shares.
  const std::uint8_t* level_data(int level) const { return levels_[std::size_t(level)].data(); }
  int min_x() const { return min_x_; }
  int min_y() const { return min_y_; }
  int width() const { return width_; }
  int height() const { return height_; }
  // The largest value of every level (and outside).
  int max_value() const { return max_value_; }
  std::uint8_t value(int level, int x, int y) const {
    const int ix = x - min_x_, iy = y - min_y_;
    if (ix < 0 || iy < 0 || ix >= width_ || iy >= height_) return unknown_;
    return levels_[std::size_t(level)][std::size_t(iy) * std::size_t(width_) + std::size_t(ix)];
  }

 private:
  double resolution_ = 0.05;
  int min_x_ = 0, min_y_ = 0, width_ = 0, height_ = 0;
  std::uint8_t unknown_ = 0;
  int max_value_ = 0;
  std::vector<std::vector<std::uint8_t>> levels_;
};

struct BranchAndBoundOptions {
  double linear_window_m = 7.0;
  double angular_window_rad = 0.52;  // 30 degrees
  double min_score = 0.55;
  // As CorrelativeOptions: a pose's score is multiplied by exp(-(d * translation_weight + |a| *
  // rotation_weight)^2) for its distance d (m) and turn a (rad) from the centre; 0: no prior.
  double translation_weight = 0.0;
  double rotation_weight = 0.0;
  // Poses whose translation lies within exclude_radius_m of exclude_center (grid frame) are not
  // answers: the search for a rival of a match found before, somewhere else.
  std::optional<Eigen::Vector2d> exclude_center;
  double exclude_radius_m = 0.0;
};

// The best pose within the window around `center` whose score exceeds min_score, found by branch
// and bound over the precomputed grids (Hess et al. 2016, Algorithm 3); nullopt when none does.
std::optional<MatchResult> branch_and_bound_match(const PrecomputedGrids& grids, const PointCloud& points,
                                                  const core::Pose2& center, const BranchAndBoundOptions& options = {});

struct RefineOptions {
  // Cartographer's local defaults: the points' misfit (1 - probability, weighted / sqrt(n)), and
  // the pull toward the initial estimate's translation (per metre) and rotation (per radian).
  double occupied_weight = 1.0;
  double translation_weight = 10.0;
  double rotation_weight = 40.0;
  int max_iterations = 20;
  // When >= 0, the translation's pull is this in the direction the points fix best and
  // translation_weight in a direction they leave free, blended along each eigenvector of the
  // score's curvature at `initial` (score_curvature) by the square root of its eigenvalue over the
  // largest: the scan decides where it can, the prediction holds a corridor's length. The pull's
  // anchor is blended alike, `initial`'s translation where the points fix the pose, `target`'s
  // where they leave it free (refine_match). Below 0: translation_weight everywhere, toward
  // `target`.
  double fixed_translation_weight = -1.0;
  // Fit the grid's surface field (SubmapGrid::hit_field) instead of its probabilities, the
  // curvature too; the grid must keep one.
  bool hit_field = false;
};

// How well a placement fixes the scan's position in each direction: the curvature of the mean
// probability at the points (read through the bicubic interpolation refine_match uses) at `pose`
// over translations (the heading held), the quadratic form u' A u fitted to its drop when the
// scan moves by +-`step_m` (best below a cell) along eight directions u (per m^2; eigenvalues
// clamped at 0). Olson 2009 (sec. IV-D) reads a match's covariance off the same score surface: along a
// corridor whose ends are out of range the score hardly drops, across it it drops fast.
// hit_field: of the grid's surface field instead.
Eigen::Matrix2d score_curvature(const SubmapGrid& grid, const PointCloud& points, const core::Pose2& pose, double step_m,
                                bool hit_field = false);

// Least-squares refinement (Ceres, bicubic interpolation of the grid) from `initial`, its
// translation pulled toward `target`'s and its rotation toward `initial`'s (as Cartographer: the
// odometry's prediction anchors the translation, so that a corridor whose walls do not fix the
// position along it keeps the odometry's). With fixed_translation_weight >= 0 the translation is
// pulled toward `initial`'s in the directions the points fix: `initial` is then a search's answer
// that already weighed the prediction.
core::Pose2 refine_match(const SubmapGrid& grid, const PointCloud& points, const core::Pose2& initial,
                         const core::Pose2& target, const RefineOptions& options = {});

// The mean probability of the grid at the points placed by `pose`.
double match_score(const SubmapGrid& grid, const PointCloud& points, const core::Pose2& pose);
// How much better the points fit at `a` than at `b`, point by point: the mean of the differences
// of the probabilities at each point, in standard errors of that mean (the differences' spread /
// sqrt(points)). Two placements that explain the scan alike differ by a few errors at most.
double score_advantage(const SubmapGrid& grid, const PointCloud& points, const core::Pose2& a, const core::Pose2& b);

}  // namespace fleetmap::localization
