#pragma once
// Who decides where a robot goes. By default the exploration drives every robot (frontiers, the
// wave, a planner's path); an experiment may drive a robot by a script instead: commands given in
// advance (D'Alfonso et al. §4's precomputed velocities) or waypoints steered on the true pose
// (León et al. §II.D's laps of a corridor loop).
#include <Eigen/Core>

#include <optional>
#include <vector>

#include "core/transform2.h"
#include "sim/motion.h"

namespace fleetmap::sim {

// What a driver knows of its robot at the end of a step.
struct DriverView {
  int step = 0;          // the step just taken (0: the start, before moving)
  core::Pose2 truth;     // world frame
  core::Pose2 estimate;  // the localizer's, in the robot's map frame
};

class Driver {
 public:
  virtual ~Driver() = default;
  // The command for the next step, or nullopt when the drive is over: the robot then stands still
  // and counts as finished.
  virtual std::optional<Command> next(const DriverView& view) = 0;
};

// Plays the commands, one per step, then stops.
class CommandScript final : public Driver {
 public:
  explicit CommandScript(std::vector<Command> commands) : commands_(std::move(commands)) {}
  std::optional<Command> next(const DriverView& view) override;

 private:
  std::vector<Command> commands_;
};

struct WaypointDrive {
  std::vector<Eigen::Vector2d> waypoints;
  // A closed drive is a loop that starts on its first waypoint and is driven `laps` times; an open
  // one ends at its last waypoint.
  bool closed = false;
  int laps = 1;
  double speed_mps = 0.5;
  double max_turn_rate_rps = 0.7853981633974483;  // 45 deg/s
  double turn_in_place_rad = 0.5235987755982988;  // more off than 30 degrees: turn before driving
  double reached_m = 0.3;                          // a waypoint this close is passed
};

// Steers the true pose toward the next waypoint (a line follower's drive: the robot never strays
// from its course, whatever its localizer believes).
class WaypointDriver final : public Driver {
 public:
  WaypointDriver(WaypointDrive drive, double period_s);
  std::optional<Command> next(const DriverView& view) override;
  // The steps at which each lap ended (closed), or the last waypoint was reached (open).
  const std::vector<int>& lap_ends() const { return lap_ends_; }

 private:
  WaypointDrive drive_;
  double period_s_;
  std::size_t next_;
  int laps_ = 0;
  bool over_ = false;
  std::vector<int> lap_ends_;
};

}  // namespace fleetmap::sim
