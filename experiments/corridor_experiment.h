#pragma once
// León et al.'s corridor comparison (§II.D, Table I) and its map merging by detection (§V).
//
// The world: a rectangular corridor loop whose outer free extent is length x height (21.3 m x 17 m)
// and whose corridors are long and featureless. One robot drives the loop's centre line laps times,
// counter-clockwise; its odometry has a scale error, a turn bias and noise; a front laser
// (SICK LMS200-like: 181 beams over 180 degrees, 8 m) reads the true walls. Each localizer drives
// the same drive on sim::Simulation (a sim::WaypointDriver steering on the true pose; the same seed
// gives the same odometry and scans), and the map each one builds is measured: the
// length and height of the smallest rectangle around its walls (cv::minAreaRect), against the real
// ones. The map is the robot's own grid at the estimated poses (odometry, scan-matching) or the
// localizer's own map (fastslam-grid, rbpf: the best particle's). Over several seeds, Table I
// gives the mean and the standard deviation of each cell.
//
// Merging by detection: two robots map halves of the loop with scan matching, each in its own
// frame; where they meet, the master measures range and bearing to the other and the other its
// bearing to the master (D'Alfonso et al., §3.2's rendezvous transform); the other's grid is placed into the
// master's frame with that relative pose and fused. An orientation error in the detection is added
// to the other robot's bearing, and what it does to the merged map is measured.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/params.h"
#include "core/transform2.h"
#include "mapping/occupancy_grid.h"
#include "sim/sensors.h"

namespace fleetmap::experiments {

struct OdometryErrorOptions {
  double scale_error = -0.02;        // reported distance = (1 + scale_error) x driven
  double turn_bias_deg_per_m = 0.1;  // a heading drift per metre driven, reported but not driven
  double speed_noise = 0.01;         // m/s, per step
  double turn_noise_deg = 0.2;       // deg/s, per step
};

struct CorridorOptions {
  double length_m = 21.3;            // outer free extent of the loop, x
  double height_m = 17.0;            // y
  double corridor_width_m = 2.0;
  double resolution_m = 0.1;
  std::vector<int> laps = {1, 3};    // maps are measured after each of these laps
  // `ideal` (the true pose) shows what the measurement itself gives on a perfect map; León et al.'s
  // three methods are scan-matching, fastslam-grid and rbpf.
  std::vector<std::string> methods = {"ideal", "odometry", "scan-matching", "fastslam-grid", "rbpf"};
  double speed_mps = 0.5;
  double period_s = 0.5;
  sim::RangeSensorOptions laser;          // set by default_laser()
  OdometryErrorOptions odometry;
  // Parameters of the localizers above, each given to those that declare it (e.g. `particles` of
  // rbpf and fastslam-grid, 30 by default as León et al.).
  core::Settings localizer_settings;
  std::uint64_t seed = 1;
  // Table I over the seeds seed .. seed + seeds - 1 (mean and standard deviation); the pictures and
  // the merge study use `seed`.
  int seeds = 1;
  // Merging by detection: orientation errors (degrees) added to the detected bearing.
  std::vector<double> detection_errors_deg = {0.0, 1.0, 2.0, 5.0, 10.0};
  bool merge_study = true;

  CorridorOptions();
};

// A front laser of 181 beams over 180 degrees, 8 m, 0.02 m noise.
sim::RangeSensorOptions default_laser();

// Parses the experiment's scenario file (scenarios/leon_corridor.yaml); every key checked, errors
// name the file, line and key. `source` names the text in errors.
CorridorOptions parse_corridor_options(const std::string& text, const std::string& source);
// True when a scenario's YAML names this experiment (`experiment: leon_corridor`).
bool is_corridor_scenario(const std::string& text, const std::string& source);

// The ground truth: a wall 0.3 m thick around the outer rectangle, a solid inner block, a margin
// of free cells outside. Cells: Occupied (walls) and Free (everything else).
mapping::OccupancyGrid corridor_world(const CorridorOptions& options);

// The loop's dimensions as a map shows them: the minimum-area rectangle through the centres of its
// occupied cells (specks of fewer than 10 cells left out), less one cell: the extent of the free
// space that the outermost walls bound. `found` is false for a map without walls.
struct MapDimensions {
  bool found = false;
  double length_m = 0.0;  // the longer side
  double height_m = 0.0;
};
MapDimensions measure_loop(const mapping::OccupancyGrid& map);

struct CorridorRun {
  std::string method;
  std::uint64_t seed = 0;
  int laps = 0;
  MapDimensions dimensions;
  double length_error = 0.0;  // |measured - real| / real
  double height_error = 0.0;
  double final_position_error_m = 0.0;  // estimate vs truth at the end of the laps
  double seconds = 0.0;                 // localizer and mapping time over these laps
  mapping::OccupancyGrid map;
  std::vector<core::Pose2> truth, estimate;
};

struct DetectionMerge {
  double orientation_error_deg = 0.0;
  double rotation_error_deg = 0.0;       // of the applied transform against the truth
  double far_end_error_m = 0.0;          // where the other robot's start lands vs. where it is
  double mean_wall_distance_m = 0.0;     // the other's walls in the merged map to the nearest true wall
  double misplaced_wall_share = 0.0;     // share of the other's wall cells farther than 0.3 m from a wall
  mapping::OccupancyGrid merged;         // in the world frame, covering both maps
};

struct CorridorResult {
  CorridorOptions options;
  mapping::OccupancyGrid truth;
  MapDimensions real;          // measured on the true walls' faces (the free space's extent)
  std::vector<CorridorRun> runs;
  std::vector<DetectionMerge> merges;
  mapping::OccupancyGrid master_map, other_map;        // each in its own frame, before merging
  std::vector<core::Pose2> master_path, other_path;  // true paths of the merge study, world frame
  core::Pose2 meeting_master, meeting_other;          // true poses at the meeting
};

// (done, total) work units, for a progress bar.
using CorridorProgress = std::function<void(int, int)>;

// Throws InputError for options that cannot be run (unknown method, corridor wider than the loop).
CorridorResult run_corridor_experiment(const CorridorOptions& options, const CorridorProgress& progress = {});

}  // namespace fleetmap::experiments
