#pragma once
// Landmark maps (map-alignment paper, §III-IV): aligning two robots' landmark maps by RANSAC data association
// (eq. 2-6) or by inter-robot observation (eq. 7-9), choosing between them by the number of
// overlapping landmarks (Fig. 3), and fusing them: transform (eq. 10), find duplicates, fuse
// duplicates with covariance weighting (eq. 11-13).
#include <Eigen/Core>

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/random.h"
#include "core/transform2.h"
#include "merging/rendezvous.h"

namespace fleetmap::merging {

struct MapLandmark {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();            // m, in the map's frame
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity() * 0.01;  // m^2
  Eigen::VectorXd signature;  // what the sensor tells landmarks apart by (map-alignment paper: width, height); may be empty
};

struct LandmarkMap {
  std::vector<MapLandmark> landmarks;
};

struct LandmarkAlignmentOptions {
  double signature_threshold = 1.0;   // th_s: largest signature distance of a candidate match
  double geometric_threshold = 0.8;   // th_g, eq. (2): largest |(A^2 + B^2) - (C^2 + D^2)| of two pairs (m^2)
  double support_threshold = 1.0;     // th_p: largest distance of a supporting landmark after the transform (m)
  int min_supports = 3;               // fewer supports: no alignment
  int max_pair_trials = 20000;        // pairs of matches tried (all of them when there are fewer)
  bool refit_supports = true;         // least-squares refit on the winning supports (off: eq. 3-6 only)
  int overlap_threshold = 10;         // Fig. 3: data association from this many overlapping landmarks
  double duplicate_distance = 1.0;    // m: a transformed landmark this close to one of ours is the same one
};

// Step a of §III.A: every landmark of `other` with its signature-nearest landmark of `self`, when
// the distance is below th_s. Without signatures on either side, every pair is a candidate.
std::vector<std::pair<int, int>> candidate_matches(const LandmarkMap& self, const LandmarkMap& other,
                                                   const LandmarkAlignmentOptions& options);

// Eq. (3)-(6): the transform from two correspondences (x_i, y_i) <-> (x'_i, y'_i) and
// (x_j, y_j) <-> (x'_j, y'_j) (unprimed: self, primed: other), as a transform of other's frame into
// self's. The seed writes it as x = x' cos Theta + y' sin Theta + d_x (a rotation by -Theta).
core::Transform2 transform_from_two_pairs(const Eigen::Vector2d& self_i, const Eigen::Vector2d& other_i,
                                          const Eigen::Vector2d& self_j, const Eigen::Vector2d& other_j);

struct LandmarkAlignment {
  bool found = false;
  core::Transform2 transform;                 // other's frame into self's
  std::vector<std::pair<int, int>> supports;  // (self index, other index)
  int candidates = 0;                         // candidate matches from signatures
};

// §III.A: candidate matches, every (or up to max_pair_trials random) pair of them satisfying eq. (2),
// the transform of eq. (3)-(6), supports within th_p; the hypothesis with most supports wins.
LandmarkAlignment align_landmarks(const LandmarkMap& self, const LandmarkMap& other,
                                  const LandmarkAlignmentOptions& options, core::Random& random);

// Eq. (10): the landmarks of `map` moved by t, covariances as Sigma' = R Sigma R^T.
LandmarkMap transform_landmarks(const LandmarkMap& map, const core::Transform2& t);

// Eq. (11)-(13): fusing two estimates of one landmark (both in self's frame):
//   K = Sigma_self (Sigma_self + Sigma_other')^-1                       (11)
//   Sigma_merged = Sigma_self - K Sigma_self                            (12)
//   p_merged = p_self + K (p_other' - p_self)                           (13)
MapLandmark fuse_landmarks(const MapLandmark& self, const MapLandmark& other_transformed);

struct LandmarkMergeResult {
  LandmarkMap merged;   // self's landmarks (fused where duplicated), then other's new ones
  int duplicates = 0;   // landmarks of other fused into one of self's
  int added = 0;        // landmarks of other added as new
};

// §IV: transforms other into self's frame by other_to_self, pairs duplicates (nearest, one to
// one, within duplicate_distance and, with signatures, th_s) and fuses them; the rest is added.
LandmarkMergeResult merge_landmark_maps(const LandmarkMap& self, const LandmarkMap& other,
                                        const core::Transform2& other_to_self, const LandmarkAlignmentOptions& options);

// A rendezvous as the map-alignment paper, uses it: both robots' pose estimates and what they measured of each other.
struct Rendezvous {
  core::Pose2 self_pose;
  core::Pose2 other_pose;
  MutualObservation observation;
};

enum class AlignmentMethod { DataAssociation, InterRobotObservation, None };

struct LandmarkMethodChoice {
  AlignmentMethod method = AlignmentMethod::None;
  int overlapping_landmarks = 0;    // candidate matches by signature
  std::optional<core::Transform2> transform;  // other's frame into self's
  std::string message;              // the map-alignment paper's report: "Map alignment using data association", ...
  LandmarkAlignment ransac;         // when data association ran
};

// Fig. 3: data association when the overlapping landmarks reach overlap_threshold, inter-robot
// observation otherwise. When data association finds no alignment, the observation is used if
// there is one; without either, method is None.
LandmarkMethodChoice align_landmark_maps(const LandmarkMap& self, const LandmarkMap& other,
                                         const std::optional<Rendezvous>& rendezvous,
                                         const LandmarkAlignmentOptions& options, core::Random& random);

const char* to_string(AlignmentMethod method);

}  // namespace fleetmap::merging
