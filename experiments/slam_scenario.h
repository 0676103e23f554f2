#pragma once
// A SLAM experiment (`fleetmap slam`): robots driven along precomputed paths in a room given as
// polygons, sensing with distance sensors and a camera, each running a SLAM method on its own
// and exchanging maps when two see each other (D'Alfonso et al., §4). Loaded from YAML: every key checked,
// errors name the file, line and key. `method` picks the SLAM method and sets the parameters it
// declares (`method: {name: polynomial, order: 2}`); a block named after the method holds them too
// (`polynomial: {order: 2}`, as D'Alfonso et al.'s scenarios write them).
#include <Eigen/Core>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/params.h"
#include "core/range.h"
#include "core/transform2.h"
#include "mapping/polynomial_map.h"
#include "sim/motion.h"
#include "sim/sensors.h"

namespace fleetmap::experiments {

// The environment: free inside `boundary`, blocked outside it and inside every obstacle. Its
// edges are the true walls (drawn red, and what nu is measured against).
struct SlamRoom {
  std::vector<Eigen::Vector2d> boundary;                // a closed polygon (the last vertex joins the first)
  std::vector<std::vector<Eigen::Vector2d>> obstacles;  // closed polygons inside the boundary
  double resolution_m = 0.01;                           // the raster that sensors and motion use
};

// The room's edges as wall segments.
std::vector<mapping::WallSegment> room_walls(const SlamRoom& room);

struct SlamRobot {
  std::string name;
  core::Pose2 start;                   // true start in the room's frame
  std::vector<Eigen::Vector2d> path;   // waypoints after the start
  double speed_mps = 0.1;              // forward speed along the path
};

// Runs of a SLAM experiment (`fleetmap slam --runs`, the SLAM scenario's `runs`).
inline constexpr core::Range kSlamRunsRange{1, 1'000'000, true};

struct SlamScenario {
  std::string method = "polynomial";
  std::uint64_t seed = 1;
  int runs = 100;
  int steps = 200;       // k_f
  double period_s = 1.0;  // T
  SlamRoom room;
  std::vector<SlamRobot> robots;
  sim::RobotOptions robot;
  sim::MotionNoise noise;
  sim::RangeSensorOptions range;       // angles_rad: the distance sensors' headings beta_i
  sim::RobotDetectorOptions camera;
  double initial_sigma_xy = 0.05;        // P0 = diag(sxy^2, sxy^2, sth^2)
  double initial_sigma_heading = 0.0175;  // rad
  // True: each robot's initial estimate is off its true start by a draw from P0 (run k's own
  // stream), as the EKF assumes, so that the NEES measures consistency. False: it starts exactly at
  // the truth, as in D'Alfonso et al. §4; P0 then enters P but not the error, and the NEES is below 3.
  bool sampled_start = false;
  bool exchange = true;                   // maps are exchanged at rendezvous
  double segment_tolerance_m = 0.005;     // §3.2's piecewise-linear approximation
  double grid_patch_resolution_m = 0.05;  // the equivalent occupancy-grid patch's cells
  std::string single_robot;               // also run this robot alone (D'Alfonso et al., Fig. 8); "" for none
  bool paper_table = false;               // print D'Alfonso et al.'s Table 1 beside the results (its own experiment)
  // The method's own parameters as given (slam_method_options checks them), in the order given.
  core::Settings method_settings;
  // The filter's distance-reading noise V, m, when it differs from the sensors' (range.noise_m):
  // exact readings still need a V > 0. Not a scenario key.
  std::optional<double> filter_range_noise_m;
};

// Parses scenario YAML; `source` names it in errors.
SlamScenario parse_slam_scenario(const std::string& text, const std::string& source);
SlamScenario load_slam_scenario(const std::filesystem::path& path);
// Values that need no raster: counts, ranges, names, robots. Throws InputError naming the key.
void validate_slam_scenario(const SlamScenario& scenario);

}  // namespace fleetmap::experiments
