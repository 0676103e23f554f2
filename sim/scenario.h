#pragma once
// A scenario: everything that defines a run. Loaded from YAML (every key checked, errors name the
// file, line and key), written back to YAML, and overridden by command-line flags.
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/transform2.h"
#include "core/yaml_reader.h"
#include "exploration/team_explorer.h"
#include "localization/localizer.h"
#include "sim/communication.h"
#include "sim/motion.h"
#include "sim/sensors.h"

namespace fleetmap::sim {

enum class Placement { Cluster, Random, List };

struct Scenario {
  std::string map = "office";       // built-in name, or a PNG/PGM/YAML path
  std::filesystem::path base_dir;   // relative map paths are resolved here (the scenario's folder)
  std::uint64_t seed = 1;
  int steps = 2000;                 // step limit
  double period_s = 1.0;            // sampling period T

  int robot_count = 4;
  Placement placement = Placement::Cluster;  // cluster: packed around `cluster_at` (default: map centre)
  std::vector<core::Pose2> starts;           // Placement::List
  std::optional<Eigen::Vector2d> cluster_at;
  double min_separation_m = 0.6;             // between robot centres, for cluster and random
  RobotOptions robot;
  MotionNoise noise;

  RangeSensorOptions range;
  LandmarkSensorOptions landmark_sensor;
  RobotDetectorOptions detector;
  std::vector<Eigen::Vector2d> landmarks;    // fixed artificial landmarks (seed 003 §V)
  double landmarks_along_walls = 0.0;        // plus this many per metre of wall, placed with the seed

  std::string localization = "ideal";
  localization::LocalizerOptions localization_options;
  // Robots (numbered from 1) that do not know where they start: `mcl` starts them from a uniform
  // belief over the map (global localization, seed 002 §IV).
  std::vector<int> lost_robots;
  CommunicationOptions communication;
  exploration::ExplorationOptions exploration;
  // How robots bring others' maps into their frame: "known" (every robot knows its start pose in a
  // common frame), "rendezvous" (each robot maps in its own frame; robots that detect each other
  // compute the relative transform from the detection, seed 000 §3.2) or "overlap" (robots that can
  // talk search their maps for the best overlap, merging/).
  std::string merging = "known";
  std::string merge_method = "auto";         // overlap: a method of `fleetmap merge`
  double merge_min_confidence = 0.5;         // overlap: below, no merge
  int merge_attempt_every = 20;              // overlap: steps between attempts of the same pair
  double lookahead_m = 0.5;                  // path following
  // How robots get a path to their target: "wave" (the wave's steepest descent) or a planner of
  // planning/ by name (astar, rrtconnect, rrtstar, ...), given `planner_time_s` per path.
  std::string path_planner = "wave";
  double planner_time_s = 0.1;
};

std::vector<std::string> merging_names();
// "wave" and every planner of planning/.
std::vector<std::string> path_planner_names();

// Parses scenario YAML; `source` names it in errors and `base_dir` anchors relative map paths.
// The `noise:` mapping of a scenario ({position: m, heading_deg: deg} per step), keys not given
// taken from `fallback`. Throws InputError naming the key.
MotionNoise read_motion_noise(core::YamlMap noise, const MotionNoise& fallback);

// A detector mapping ({max_range, fov_deg, range_noise, bearing_noise_deg}: the scenario's
// `sensors.robots`, the SLAM scenario's `sensors.camera`), keys not given taken from `fallback`.
RobotDetectorOptions read_robot_detector(core::YamlMap detector, const RobotDetectorOptions& fallback);

Scenario parse_scenario(const std::string& text, const std::string& source, const std::filesystem::path& base_dir);
Scenario load_scenario(const std::filesystem::path& path);
// Every setting, explicitly, in the layout parse_scenario reads.
std::string scenario_to_yaml(const Scenario& scenario);

// Checks values that need no map (counts, ranges, noise, names). Throws InputError naming the key.
void validate_scenario(const Scenario& scenario);

}  // namespace fleetmap::sim
