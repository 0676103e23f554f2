#pragma once
// The map-alignment paper's experiments ("Networked robots path planning using SLAM ...", §V-VI):
// robots drive precomputed paths through a plane of point landmarks, each builds its own landmark
// map with FastSLAM 2.0 (Montemerlo et al. 2003) in its own frame (its start pose), and at a
// rendezvous the leader brings each follower's map into its frame, by RANSAC data association
// (eq. (2)-(6)) or by the inter-robot observation (eq. (7)-(9)), and fuses the two (eq. (10)-(13)).
//
// What is measured, against the true transform between the two robots' start poses:
//  - Table I: the transform error of both methods from the maximum-weight particle's map and from
//    the combination of all particles' maps (eq. (14)-(15));
//  - Tables II and III: the same for a little and a large overlap of the two maps, with the
//    fused map's landmark errors;
//  - Fig. 2: the transform error as the observation noise (range, of landmarks and of the other
//    robot) grows, the bearing noise kept;
//  - Fig. 3 and §VI: the method the leader chooses by the number of overlapping landmarks
//    (candidate matches by signature, threshold 10), for 2 robots meeting twice and 4 robots
//    meeting the leader, with the transforms as the paper prints them.
//
// A run is a sim::Simulation set up for it: each robot driven by its precomputed commands
// (sim::CommandScript) in its own frame, with the registered `fastslam2` localizer; an observer
// lets the leader gather the followers' reports at the case's rendezvous steps.
//
// Landmarks carry a signature (the paper's width, height): two numbers drawn once per landmark
// and read with a little noise, which is what candidate matches compare (th_s).
#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/transform2.h"
#include "experiments/landmark_scenario.h"
#include "merging/landmark_alignment.h"

namespace fleetmap::experiments {

// The true landmarks and their signatures, placed by the experiment's seed.
struct LandmarkWorld {
  std::vector<Eigen::Vector2d> landmarks;
  std::vector<Eigen::Vector2d> signatures;
};
LandmarkWorld make_landmark_world(const LandmarkExperimentOptions& options, const std::vector<LandmarkField>& fields);

// |estimate - truth| of a transform's parameters (d_x, d_y, Theta wrapped).
struct TransformError {
  double dx = 0.0, dy = 0.0, theta = 0.0;
  double translation() const;
};
TransformError transform_error(const core::Transform2& estimate, const core::Transform2& truth);

// The map of one robot as the alignment sees it, and which true landmark each entry is.
struct RobotLandmarkMap {
  merging::LandmarkMap map;
  std::vector<int> ids;
};

// One method from one kind of map: the transform (when it found one), its error, and the fused
// map's landmark errors (RMS of x and y against the truth, in the leader's frame).
struct MethodOutcome {
  std::optional<core::Transform2> transform;
  TransformError error;
  double landmark_rms_x = 0.0, landmark_rms_y = 0.0;
};

// A follower's report to the leader at a rendezvous.
struct FollowerReport {
  int step = 0;
  std::string leader, follower;
  core::Transform2 truth;        // the follower's frame into the leader's
  int overlap = 0;               // candidate matches by signature (Fig. 3's count)
  int shared = 0;                // landmarks both maps truly hold
  // [0]: the maximum-weight particle's maps and poses, [1]: the combined maps (eq. (14)-(15)) and
  // the weighted mean poses.
  MethodOutcome data_association[2], observation[2];
  merging::LandmarkMethodChoice choice;  // Fig. 3 on the combined maps
  int global_landmarks = 0;              // the leader's global map after fusing this follower
};

struct LandmarkCaseRun {
  std::string case_name;
  int run = 0;
  double range_noise = 0.0;  // m, landmarks and the other robot
  std::vector<FollowerReport> reports;
  std::vector<double> final_position_error;  // per robot, m, its own frame
  std::vector<double> odometry_position_error;  // per robot, dead reckoning on the same drive
  // The leader's global map at the last rendezvous (leader frame) with the robot each landmark came
  // from (-1: fused duplicate), and the truth in the leader's frame.
  merging::LandmarkMap global;
  std::vector<int> global_source;
  std::vector<Eigen::Vector2d> truth_in_leader;
  std::vector<std::vector<core::Pose2>> truth_paths;  // per robot, leader frame
};

// One run of a case in its world (its own fields, or the experiment's); `run` picks the random
// streams, `range_noise` (m) replaces the sensor's and the camera's range noise when set. Throws
// InputError when robots that should meet do not see each other.
LandmarkCaseRun run_landmark_case(const LandmarkExperimentOptions& options, const LandmarkCase& c, int run,
                                  std::optional<double> range_noise = std::nullopt);

struct NoiseLevel {
  double range_noise = 0.0;
  std::vector<LandmarkCaseRun> runs;
};

struct LandmarkExperimentResult {
  LandmarkExperimentOptions options;
  std::vector<LandmarkCaseRun> table1, little, large, small_overlap, large_overlap;
  std::vector<NoiseLevel> noise;
  std::vector<LandmarkCaseRun> merges;  // run 0 of each merge case
};

using LandmarkProgress = std::function<void(int, int)>;
// Every part the options name; `jobs` runs in parallel (results do not depend on it).
LandmarkExperimentResult run_landmark_experiment(const LandmarkExperimentOptions& options, int jobs = 1,
                                                 const LandmarkProgress& progress = {});

}  // namespace fleetmap::experiments
