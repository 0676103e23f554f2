#pragma once
// Rigid (rotation + translation, no scale) fits of point correspondences.
#include <Eigen/Core>

#include <optional>
#include <vector>

#include "core/random.h"
#include "core/transform2.h"

namespace fleetmap::merging {

struct PointPair {
  Eigen::Vector2d from;  // in the frame being moved
  Eigen::Vector2d to;    // in the target frame
  double weight = 1.0;
};

// The rigid transform minimising sum w |T(from) - to|^2 (2D Kabsch / Umeyama without scale).
// nullopt for fewer than two pairs or coincident points.
std::optional<core::Transform2> fit_rigid(const std::vector<PointPair>& pairs);

struct RigidRansacOptions {
  double inlier_distance = 3.0;  // |T(from) - to| below this is an inlier
  int iterations = 2000;         // random two-pair samples
  int min_inliers = 6;
};

struct RigidRansacResult {
  core::Transform2 transform;
  std::vector<int> inliers;  // indices into the pairs, best model refitted on them
};

// RANSAC over two-pair samples with a rigid model, then a least-squares refit on the inliers.
// A sample whose two distances differ by more than 2 * inlier_distance is skipped: a rigid motion
// keeps distances (unlike OpenCV's estimateAffinePartial2D, which also fits a scale).
// `skip` marks pairs to leave out (e.g. inliers of a model found before). nullopt when no model
// reaches min_inliers.
std::optional<RigidRansacResult> ransac_rigid(const std::vector<PointPair>& pairs, const RigidRansacOptions& options,
                                              core::Random& random, const std::vector<bool>& skip = {});

}  // namespace fleetmap::merging
