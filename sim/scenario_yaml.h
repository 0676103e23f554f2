#pragma once
// Readers of parts of a scenario file that other files with the same parts share (the SLAM
// scenario). Internal: they take yaml-cpp nodes, so this header is not installed.
#include "io/yaml_reader.h"
#include "sim/scenario.h"

namespace fleetmap::sim {

// The `noise:` mapping of a scenario ({position: m, heading_deg: deg} per step), keys not given
// taken from `fallback`. Throws InputError naming the key.
MotionNoise read_motion_noise(io::YamlMap noise, const MotionNoise& fallback);

// A detector mapping ({max_range, fov_deg, range_noise, bearing_noise_deg}: the scenario's
// `sensors.robots`, the SLAM scenario's `sensors.camera`), keys not given taken from `fallback`.
RobotDetectorOptions read_robot_detector(io::YamlMap detector, const RobotDetectorOptions& fallback);

}  // namespace fleetmap::sim
