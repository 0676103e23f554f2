#pragma once
// Sensors read the true world (ray cast on the ground-truth grid) with Gaussian noise and a
// maximum range.
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "core/random.h"
#include "core/transform2.h"
#include "localization/localizer.h"
#include "sim/world.h"

namespace fleetmap::sim {

struct RangeSensorOptions {
  // Beam angles in the robot frame (D'Alfonso et al.: five distance sensors at beta_i). When empty,
  // a 360-degree laser of `beams` evenly spaced beams.
  std::vector<double> angles_rad;
  int beams = 360;
  double max_range_m = 4.0;
  double noise_m = 0.02;  // standard deviation
};

struct LandmarkSensorOptions {
  double max_range_m = 5.0;
  double range_noise_m = 0.02;
  double bearing_noise_rad = 0.017453292519943295;  // 1 degree
  bool report_ids = true;             // the sensor tells which landmark it sees
};

struct RobotDetectorOptions {  // D'Alfonso et al.'s camera, León et al.'s detection
  double max_range_m = 5.0;
  double fov_rad = 6.283185307179586;  // centred on the heading
  double range_noise_m = 0.02;
  double bearing_noise_rad = 0.017453292519943295;  // 1 degree
};

std::vector<double> beam_angles(const RangeSensorOptions& options);

// One scan from the true pose. Readings are clamped to [0, max_range]; a beam that meets nothing
// within max_range has no reading.
localization::RangeScan read_ranges(const World& world, const core::Pose2& truth, const RangeSensorOptions& options,
                                    core::Random& rng);

// Landmarks within range and line of sight.
std::vector<localization::LandmarkObservation> read_landmarks(const World& world, const core::Pose2& truth,
                                                              const LandmarkSensorOptions& options, core::Random& rng);

struct Detection {
  int other = -1;
  double range = 0.0;
  double bearing = 0.0;  // robot frame
};

// Other robots (by true pose) within range, field of view and line of sight.
std::vector<Detection> detect_robots(const World& world, int self, const std::vector<core::Pose2>& truths,
                                     const RobotDetectorOptions& options, core::Random& rng);

}  // namespace fleetmap::sim
