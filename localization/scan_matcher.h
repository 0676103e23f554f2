#pragma once
// Scan-to-map matching: the pose that best explains a scan on a likelihood field, near a guess.
// 1. Correlative search (Olson 2009): every heading in [-search_theta, +search_theta] and every cell
//    offset within search_xy, scored by the likelihood field (nearest cell) plus a Gaussian prior
//    around the guess; the scores also give the match's covariance.
// 2. Local refinement from the best candidate: coordinate hill climbing on the bilinear field with
//    halving steps (as GMapping's scan matcher).
#include <Eigen/Core>

#include <optional>
#include <vector>

#include "core/transform2.h"
#include "localization/cow_grid.h"
#include "localization/likelihood_field.h"
#include "localization/localizer.h"

namespace fleetmap::localization {

struct ScanMatcherOptions {
  double search_xy_m = 0.3;         // half-width of the translation window
  double search_theta_rad = 0.12;   // half-width of the heading window (about 7 degrees)
  double angular_step_rad = 0.0;    // 0: the step that moves the farthest end point by one cell
  // The Gaussian prior around the guess (the odometry's uncertainty over a step); 0 disables it.
  double prior_xy_m = 0.15;
  double prior_theta_rad = 0.08;
  int beam_stride = 2;              // use every k-th beam with a return
  // Neighbouring beams see the same wall and are not independent: the log-likelihood is scaled to
  // this many independent beams against the prior (0: no scaling).
  double independent_beams = 10.0;
  int min_points = 20;              // fewer end points: no match
  int min_map_cells = 30;           // fewer occupied cells near the robot: no match
  int refine_iterations = 60;
  LikelihoodFieldOptions field;
};

struct ScanMatch {
  bool matched = false;
  core::Pose2 pose;                 // the best pose (the guess when not matched)
  double log_likelihood = 0.0;      // of the end points at `pose` (LikelihoodField::score)
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // from the correlative scores
  // log of the sum over the search window of (scaled) likelihood x prior: the normaliser eta of the
  // improved proposal (Grisetti et al. 2005, eq. (11)), up to a constant shared by every call.
  double log_normalizer = 0.0;
  int points = 0;
};

// The matcher's settings for a localizer on a grid of `resolution_m`: the field's spread from the
// range noise and the cell size, the prior three times the odometry noise of a step that turned
// `turn_rad` (whose heading part grows with the turn by turn_noise_per_rad), and the heading
// window widened by that growth's three standard deviations.
ScanMatcherOptions scan_matcher_options(const LocalizerOptions& options, double max_range_m, double resolution_m,
                                        double turn_rad = 0.0);

// The end points of a scan's returns in the robot frame, every `stride`-th return.
std::vector<Eigen::Vector2d> scan_end_points(const RangeScan& scan, int stride);

// The points brought into the world frame at `pose`.
std::vector<Eigen::Vector2d> transform_points(const core::Pose2& pose, const std::vector<Eigen::Vector2d>& points);

// Matches robot-frame end points against `field`, searching around `guess`, with the prior centred
// on `prior_mean` (the guess when not given).
ScanMatch match_scan(const LikelihoodField& field, const std::vector<Eigen::Vector2d>& points, const core::Pose2& guess,
                     const ScanMatcherOptions& options, const std::optional<core::Pose2>& prior_mean = std::nullopt);

// Matches a scan to a robot's (or a particle's) own grid: a likelihood field of the window within
// the scan's reach around the guess, from the grid's occupied cells and hit means, then match_scan.
ScanMatch match_scan_to_grid(const CowGrid& map, const RangeScan& scan, const core::Pose2& guess,
                             const ScanMatcherOptions& options, const std::optional<core::Pose2>& prior_mean = std::nullopt);


// Local refinement alone (step 2), from `start`; returns the refined pose and its log-likelihood.
std::pair<core::Pose2, double> refine_pose(const LikelihoodField& field, const std::vector<Eigen::Vector2d>& points,
                                           const core::Pose2& start, double xy_step_m, double theta_step_rad,
                                           int iterations);

}  // namespace fleetmap::localization
