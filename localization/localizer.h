#pragma once
// One interface for every way a robot knows where it is. The simulator calls, each step:
// predict(odometry) -> update_landmarks / update_scan / update_robot (when it has such readings)
// -> pose() / covariance(). Localizers are chosen by name (`--localization`, scenario files)
// through make_localizer(); tests iterate over localizer_names().
#include <Eigen/Core>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/random.h"
#include "core/registry.h"
#include "core/transform2.h"
#include "mapping/occupancy_grid.h"
#include "mapping/range_scan.h"

namespace fleetmap::localization {

// The odometry of one step: commanded (or wheel-measured) speeds over the period dt.
struct Odometry {
  double v = 0.0;      // m/s, forward
  double omega = 0.0;  // rad/s, counter-clockwise
  double dt = 1.0;     // s
};

// Differential-drive motion: the exact arc for (v, omega) over dt.
core::Pose2 integrate_motion(const core::Pose2& pose, const Odometry& u);

// A point landmark seen from the robot: range (m) and bearing (rad, robot frame).
struct LandmarkObservation {
  int id = -1;  // the landmark's identity when the sensor reports it, -1 when unknown
  double range = 0.0;
  double bearing = 0.0;
};

// A point landmark: of a known map, or an estimate held in a filter's state (landmark_estimates()).
struct Landmark {
  int id = 0;
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  // The estimate's covariance (m^2); zero for a landmark of a known map.
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
};

// A 2D laser scan in the robot frame.
using mapping::RangeScan;

// Another robot detected by this one, with what that robot believes of itself. other_pose and
// other_covariance must be expressed in this robot's map frame.
struct RobotObservation {
  int other = -1;
  double range = 0.0;
  double bearing = 0.0;  // rad, in this robot's frame
  core::Pose2 other_pose;             // the other robot's own estimate
  Eigen::Matrix3d other_covariance = Eigen::Matrix3d::Zero();
};

// This robot seen by another (León et al., §III.C, eq. (15)): the detector's range and bearing (rad, in
// the detector's frame) with their noise, and the detector's belief of its own pose, in this
// robot's map frame.
struct DetectedBy {
  int detector = -1;
  double range = 0.0;
  double bearing = 0.0;
  double range_noise = 0.0;
  double bearing_noise = 0.0;
  core::Pose2 detector_pose;
  Eigen::Matrix3d detector_covariance = Eigen::Matrix3d::Zero();
};

// Noise models and filter settings shared by the localizers; each uses what it needs.
struct LocalizerOptions {
  // Odometry noise per step (standard deviations), the model's Q: D'Alfonso et al. uses 0.001 m and 0.01 deg.
  double process_noise_xy = 0.001;         // m
  double process_noise_theta = 0.000174533;  // rad (0.01 deg)
  // Heading noise per radian the odometry reports turned in the step (the alpha_1 of Thrun et al.'s
  // odometry model): `scan-matching` adds it to process_noise_theta in its prior and widens its
  // heading window by three of it, `graph-slam` its local search's window. A real robot's
  // odometry errs in heading most while it turns (MIT CSAIL's lags the laser: 11 degrees rms on
  // steps of 20-90 degrees, 1.4 on steps under 2). 0: none.
  double turn_noise_per_rad = 0.0;
  // Translation noise per metre the odometry reports driven in the step (Thrun et al.'s alpha_3):
  // `graph-slam` widens its local search's translation window by three of it (a step of a log
  // that keeps scans 1 m apart errs by far more than one 0.2 m apart). 0: none.
  double drive_noise_per_m = 0.0;
  // Landmark sensor noise (standard deviations).
  double range_noise = 0.02;     // m
  double bearing_noise = 0.0175;  // rad
  // Range-scan noise (standard deviation of a beam's distance), for `polynomial`.
  double scan_range_noise = 0.02;  // m
  // Initial pose uncertainty (standard deviations); D'Alfonso et al.: P0 = diag(0.05^2, 0.05^2, 0.0175^2).
  double initial_xy = 0.05;
  double initial_theta = 0.017453292519943295;  // 1 deg (D'Alfonso et al., uses 0.0175 rad)
  // Data association: by the sensor's landmark identities, or by nearest neighbour with a
  // Mahalanobis gate (chi-square, 2 dof) when identities are unknown.
  bool known_associations = true;
  double association_gate = 9.21;  // chi2(2) at 99%
  // Robot-robot detections update the estimate (off by default).
  bool use_robot_detections = false;
};

// What a localizer may be given at the start.
struct LocalizerContext {
  core::Pose2 initial_pose;             // where the robot starts, in its map frame
  std::vector<Landmark> known_landmarks;  // for `ekf` (wave-algorithm paper, §V: fixed artificial landmarks)
  LocalizerOptions options;
  // The localizer's own declared parameters (localizer_registry(); `particles` of mcl, rbpf,
  // fastslam-grid and fastslam2, ...). Left empty, make_localizer gives the member's defaults.
  core::Params params;
  std::uint64_t seed = 0;
  // `mcl`: the known map, in the robot's map frame; `global_localization`: the robot does not know
  // initial_pose and starts from a uniform belief over the map's free cells (León et al., §IV).
  std::shared_ptr<const mapping::OccupancyGrid> known_map;
  bool global_localization = false;
};

class Localizer {
 public:
  virtual ~Localizer() = default;
  virtual std::string name() const = 0;

  virtual void predict(const Odometry& u) = 0;
  virtual void update_landmarks(const std::vector<LandmarkObservation>& /*observations*/) {}
  virtual void update_scan(const RangeScan& /*scan*/, const mapping::OccupancyGrid& /*own_map*/) {}
  virtual void update_robot(const RobotObservation& /*observation*/) {}
  // This robot was detected by another (collaborative localization, León et al. eq. (15)).
  virtual void update_detected_by(const DetectedBy& /*detection*/) {}
  // Only the `ideal` localizer uses the simulator's truth.
  virtual void observe_truth(const core::Pose2& /*truth*/) {}

  virtual core::Pose2 pose() const = 0;
  virtual Eigen::Matrix3d covariance() const = 0;

  // Re-expresses everything the localizer holds (pose, covariance, landmarks) in another frame:
  // x_new = new_from_old * x_old. Used when a robot adopts a teammate's map frame after a merge.
  // The default throws fleetmap::Error: a localizer that cannot be moved cannot join another frame.
  virtual void change_frame(const core::Transform2& new_from_old);

  // Counters for metrics.json. `ekf` and `ekf-slam`: "landmark_updates", "rejected_associations",
  // "robot_updates", "rejected_robot_detections"; `ekf-slam` also "landmarks_in_state",
  // "landmarks_added", "landmarks_removed".
  virtual std::vector<std::pair<std::string, double>> counters() const { return {}; }
  // Landmark estimates held in the state, if any (for pictures, metrics and `--merging landmarks`).
  virtual std::vector<Landmark> landmark_estimates() const { return {}; }
  // True when the localizer estimates landmarks (landmark_estimates() fills as it observes them).
  virtual bool estimates_landmarks() const { return false; }
  // True when update_scan does something: the localizer reads range scans.
  virtual bool uses_scans() const { return false; }
  // True when the localizer maps the scans itself and never reads update_scan's own_map, so that
  // the caller need not build one for it.
  virtual bool ignores_own_map() const { return false; }
  // Ends a run: a localizer that revises past poses (graph SLAM) optimizes a last time and returns
  // the pose of every scan given to update_scan, in order; the others return nullopt (the pose()
  // after each scan is their answer).
  virtual std::optional<std::vector<core::Pose2>> finish_trajectory() { return std::nullopt; }
  // The grid the localizer builds itself, if any (`rbpf`: the best particle's map).
  virtual std::optional<mapping::OccupancyGrid> map_estimate() const { return std::nullopt; }
};

using LocalizerFactory = std::function<std::unique_ptr<Localizer>(const LocalizerContext&)>;

// Every localizer by name: the built-in ones, then those registered by the program.
core::Registry<LocalizerFactory>& localizer_registry();
// Adds a localizer: `--localization NAME`, scenario files and the test harnesses reach it.
// Throws Error when the name is taken or unusable.
// `params` are the settings it accepts (core/params.h); its factory finds their values in the
// context's `params`.
void register_localizer(std::string name, std::string help, LocalizerFactory make,
                        std::vector<core::ParamSpec> params = {});

// The registered names, in the order --help lists them.
std::vector<std::string> localizer_names();
// One line per localizer, for --help and README.
std::string localizer_help();
// The localizer's declared parameters with `settings` applied. Throws InputError for an unknown
// localizer (listing the valid names), a setting it does not declare or a value out of its range.
core::Params localizer_options(const std::string& name, const core::Settings& settings = {});
// Throws InputError naming the valid names for an unknown one, and for context.params declared by
// another member.
std::unique_ptr<Localizer> make_localizer(const std::string& name, const LocalizerContext& context);

}  // namespace fleetmap::localization
