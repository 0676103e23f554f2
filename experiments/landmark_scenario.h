#pragma once
// The map-alignment paper's experiments as a scenario file (`experiment: landmark_alignment`,
// scenarios/landmark_alignment.yaml): the landmark fields, the robots' cases and which case each part
// of the paper uses. Parsed strictly: every key checked, errors name the file, line and key.
#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

#include "core/transform2.h"
#include "merging/landmark_alignment.h"
#include "sim/motion.h"
#include "sim/sensors.h"

namespace fleetmap::experiments {

// `count` landmarks uniform in the rectangle [lo, hi] (the world's seed places them).
struct LandmarkField {
  Eigen::Vector2d lo = Eigen::Vector2d::Zero(), hi = Eigen::Vector2d::Zero();
  int count = 0;
};

struct LandmarkRobot {
  std::string name;
  core::Pose2 start;                  // true start in the world; the robot's map frame
  std::vector<Eigen::Vector2d> path;  // waypoints after the start
};

// One set-up: robots (the first is the leader) and when they meet.
struct LandmarkCase {
  std::string name;
  int steps = 400;
  std::vector<LandmarkRobot> robots;
  std::vector<int> rendezvous;  // steps at which every follower reports to the leader; empty: the last step
  std::vector<LandmarkField> fields;  // this case's landmarks; empty: the experiment's
};

struct LandmarkExperimentOptions {
  std::uint64_t seed = 1;
  int runs = 10;
  double period_s = 0.5;
  double speed_mps = 1.0;
  sim::RobotOptions robot;
  sim::MotionNoise noise{0.02, 0.0052};  // m and rad per step, additive
  sim::LandmarkSensorOptions sensor;     // ids reported: FastSLAM 2.0 as Bailey's simulator runs it
  sim::RobotDetectorOptions camera;      // the inter-robot observation
  double signature_range = 100.0;        // signature components uniform in [0, this]
  double signature_noise = 0.05;         // standard deviation of a signature reading
  int particles = 100;
  merging::LandmarkAlignmentOptions alignment;
  std::vector<LandmarkField> fields;
  std::vector<LandmarkCase> cases;
  // Which case each part of the paper uses (by name); "" leaves the part out.
  std::string table1, little_overlap, large_overlap, overlap_small, overlap_large, noise_case;
  std::vector<double> noise_levels = {0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0};  // m, Fig. 2
  std::vector<std::string> merges;  // §VI's leader/follower merges
};

// True when a scenario's YAML names this experiment (`experiment: landmark_alignment`).
bool is_landmark_scenario(const std::string& text, const std::string& source);
// Parses the scenario (scenarios/landmark_alignment.yaml); every key checked, errors name the
// file, line and key; cases named by the parts must exist.
LandmarkExperimentOptions parse_landmark_options(const std::string& text, const std::string& source);

}  // namespace fleetmap::experiments
