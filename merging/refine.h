#pragma once
// Local refinement of an alignment to sub-cell and sub-degree accuracy: Gauss-Newton on the
// truncated distance between the walls of the two maps (chamfer matching, both ways), coarse to
// fine over the pyramid.
#include <Eigen/Core>

#include <functional>
#include <optional>

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

// The covariance of the parameters (tx, ty, theta) of `b_to_a` (cells, cells, radians) that the
// fit of the walls at full resolution determines: the Gauss-Newton model of refine_at_level at
// b_to_a (level 0, the same residuals: distances of each map's walls to the other's, both ways,
// within inlier_distance, Huber-weighted), Sigma = s^2 H^-1 with H = sum w J^T J and
// s^2 = sum w d^2 / (n - 3) the residuals' own noise, at least 1/12 cell^2 (a grid places a wall
// only to within a cell: uniform, variance 1/12). Every matched wall gives one residual from each
// map, so H counts each wall twice: Sigma is doubled. Residuals are taken as independent; on real
// laser maps the errors of right merges fall within Sigma as a Gaussian's should, on ideal
// rasterised plans it is too small (bench/README.md, "Merging's decision model"). A long straight
// wall alone constrains nothing along itself, and the variance along it is then large. nullopt
// with fewer than 4 residuals. Directions the walls do not constrain at all get a variance of 1e12 (cells^2 or rad^2).
std::optional<Eigen::Matrix3d> fit_covariance(const PreparedGrid& a, const PreparedGrid& b, const core::Transform2& b_to_a,
                                              const RefineOptions& options = {});

// The covariance of f(T)'s parameters (tx, ty, theta) given that of T's, to first order: J C J^T
// with J the Jacobian of f at `at` (central differences). For moving a transform between frames
// (cuts, resolutions, metres): f composes it with fixed transforms.
Eigen::Matrix3d propagate_covariance(const Eigen::Matrix3d& covariance, const core::Transform2& at,
                                     const std::function<core::Transform2(const core::Transform2&)>& f);
// Of (f(T, U)) for independent T and U: J_T C_T J_T^T + J_U C_U J_U^T (a placement through a chain of pairs).
Eigen::Matrix3d propagate_covariance(const Eigen::Matrix3d& covariance_t, const core::Transform2& t,
                                     const Eigen::Matrix3d& covariance_u, const core::Transform2& u,
                                     const std::function<core::Transform2(const core::Transform2&, const core::Transform2&)>& f);

}  // namespace fleetmap::merging
