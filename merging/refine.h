#pragma once
// Local refinement of an alignment to sub-cell and sub-degree accuracy: Gauss-Newton on the
// truncated distance between the walls of the two maps (chamfer matching, both ways), coarse to
// fine over the pyramid.
#include "core/transform2.h"
#include "merging/prepared_grid.h"

namespace fleetmap::merging {

struct RefineOptions {
  int iterations = 10;           // Gauss-Newton steps per level at most
  double converged_cells = 0.01; // stop when a step moves points by less than this (cells of the level)
  // ... on the levels above the finest: their answer is only where the next finer level starts,
  // within its reach whether a tenth of a cell off or a hundredth (the finest level sets the
  // accuracy). Gauss-Newton on the interpolated distances creeps there, a tenth of a cell per step
  // or more for many steps: on real 1000 x 1000-cell map pairs this stop halved the refinement's
  // work, with the same merges and errors (bench/README.md).
  double coarse_converged_cells = 0.2;
  double converged_radius = 100; // ... counting a rotation step at this distance from the centre
  double inlier_distance = 2.5;  // cells of the level: walls farther from the other map's walls are left out
  double contradiction_weight = 10.0;  // LevelFit::score = inliers - weight * outliers
};

struct LevelFit {
  core::Transform2 b_to_a;  // fine cells of b into fine cells of a
  int inliers = 0;          // wall points within 1 cell of the other map's walls (at the level)
  int outliers = 0;         // wall points on the other map's free space, 2.5+ cells from its walls
  double score = 0.0;       // inliers - contradiction_weight * outliers
};

// Refines `b_to_a` at one pyramid level.
LevelFit refine_at_level(const PreparedGrid& a, const PreparedGrid& b, const core::Transform2& b_to_a, int level,
                         const RefineOptions& options = {});

// Refines from `from_level` down to level 0.
LevelFit refine_alignment(const PreparedGrid& a, const PreparedGrid& b, const core::Transform2& b_to_a,
                          int from_level, const RefineOptions& options = {});

}  // namespace fleetmap::merging
