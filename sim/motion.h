#pragma once
// Differential-drive robots: a path-following controller and the motion itself, with process
// noise, stopped by walls and by other robots.
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "core/random.h"
#include "core/transform2.h"
#include "localization/localizer.h"
#include "mapping/occupancy_grid.h"
#include "sim/world.h"

namespace fleetmap::sim {

struct RobotOptions {
  double radius_m = 0.2;
  double max_speed_mps = 0.5;
  double max_turn_rate_rps = 1.5707963267948966;  // 90 deg/s
};

// Additive Gaussian process noise per step, world frame (D'Alfonso et al., eq. (1): 0.001 m, 0.01 deg).
struct MotionNoise {
  double position_m = 0.001;
  double heading_rad = 0.00017453292519943296;
};

// León et al.'s odometry (§II.D): the robot drives its command without process noise, and its
// wheel encoders misreport what it drove: a scale error, a turn bias per metre and noise.
struct OdometryError {
  double scale_error = 0.0;          // reported distance = (1 + scale_error) x driven
  double turn_bias_rad_per_m = 0.0;  // a heading drift per metre driven, reported but not driven
  double speed_noise_mps = 0.0;      // standard deviation, per step
  double turn_noise_rps = 0.0;       // standard deviation, per step
};

// What the encoders report for the motion `driven`: speed noise is drawn before turn noise.
localization::Odometry misreport_odometry(const localization::Odometry& driven, const OdometryError& error,
                                          core::Random& rng);

struct Command {
  double v = 0.0;
  double omega = 0.0;
};

// `command` as far as the robot's own map lets it drive: the forward speed lowered along the same
// turn (to 0.75, 0.5, 0.25, 0.1 of it, then turning in place) until the arc keeps the disc clear of
// every occupied cell of `own_map` (the walls it saw, or found by touching them), or no closer to
// one than it already is. The simulator would cut the move short there anyway; a robot that looks
// first does not drive into what it knows.
Command clear_on_map(Command command, const core::Pose2& estimate, const mapping::OccupancyGrid& own_map,
                     const RobotOptions& robot, double period_s);

// Pure pursuit: head for the farthest path point within `lookahead_m` that the robot's disc can
// reach in a straight line on its own map (so it never cuts a corner into a door jamb); turn in
// place when it is more than 60 degrees off, and slow down near the end of the path; then
// clear_on_map.
Command follow_path(const core::Pose2& estimate, const std::vector<Eigen::Vector2d>& path,
                    const mapping::OccupancyGrid& own_map, const RobotOptions& robot, double period_s, double lookahead_m);

// Recovery after blocked moves: drive 0.15 m straight (forwards or backwards, whichever heads more
// away) toward the direction of most clearance from the occupied cells of the robot's own map and
// from the discs (of `radius_m`) of the robots it bumped into (`bumped`, in its map's frame).
Command escape_command(const core::Pose2& estimate, const mapping::OccupancyGrid& own_map, double period_s,
                       const std::vector<Eigen::Vector2d>& bumped = {}, double radius_m = 0.0);

struct MoveResult {
  core::Pose2 pose;              // the new true pose
  localization::Odometry odometry;  // the motion actually executed (what wheel encoders report)
  bool blocked = false;          // the move was cut short by a wall or a robot
  double distance_m = 0.0;       // path length travelled
  // Where the robot's body touched a wall when the move was cut short by one (a bumper's contact,
  // world frame): the point of the blocked cell nearest to the disc where the full move first
  // failed. Empty when nothing was hit, or only another robot.
  std::optional<Eigen::Vector2d> contact;
  // The robot whose disc stopped the move, when another robot did (a bumper touching it).
  std::optional<int> robot;
};

// Executes `command` for one period along the exact arc, checked in small sub-steps against walls
// and other robots' discs. A blocked arc is retried at lower forward speeds with the same turn rate,
// down to turning in place; the odometry reports the arc actually driven. Process noise is added to
// the end pose only where it keeps the robot clear. A robot never ends a step inside a wall or
// overlapping another robot.
MoveResult move_robot(const World& world, int self, const std::vector<core::Pose2>& truths, const RobotOptions& robot,
                      const Command& command, double period_s, const MotionNoise& noise, core::Random& rng);

// True when robot `self`'s disc at `p` overlaps no other robot's disc.
bool clear_of_robots(int self, const Eigen::Vector2d& p, const std::vector<core::Pose2>& truths, double radius_m);

}  // namespace fleetmap::sim
