#pragma once
// The step loop (DESIGN.md §3): move, sense, localise, map, talk, decide, measure.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/random.h"
#include "exploration/team_explorer.h"
#include "localization/localizer.h"
#include "mapping/map_quality.h"
#include "mapping/occupancy_grid.h"
#include "merging/map_aligner.h"
#include "sim/communication.h"
#include "sim/driver.h"
#include "sim/placement.h"
#include "sim/scenario.h"
#include "sim/world.h"

namespace fleetmap::sim {

struct Event {
  int step = 0;
  std::string kind;  // "meeting", "blocked", "finished"
  int robot = -1;
  int other = -1;
  std::string detail;
};

struct RobotTrack {
  std::vector<core::Pose2> truth;     // one pose per step, from step 0
  std::vector<core::Pose2> estimate;
  std::vector<Eigen::Matrix3d> covariance;
  std::vector<localization::Odometry> odometry;  // what its encoders reported, one per step from step 1
  double distance_m = 0.0;
  int blocked_moves = 0;
  int contacts_marked = 0;  // walls the robot found by touching them, marked on its map
  double localization_s = 0.0;  // the localizer's time: predict and every update

  std::vector<std::pair<std::string, double>> localizer_counters;
};

// One attempt to bring a teammate's map into a robot's frame (merging: rendezvous or overlap).
struct MergeRecord {
  int step = 0;
  int receiver = -1;  // the robot whose frame the sender's group adopted
  int sender = -1;
  std::string method;  // "rendezvous", or the merge method that found the overlap
  bool merged = false;
  double confidence = 0.0;
  std::string reason;  // why not merged
  // Against the truth (merged only): the rotation error, and how far the sender's position lands
  // from where it truly is in the receiver's frame.
  double rotation_error_deg = 0.0;
  double position_error_m = 0.0;
};

struct Timings {  // seconds
  double total = 0, motion = 0, sensing = 0, localization = 0, mapping = 0, communication = 0, exploration = 0,
         metrics = 0;
};

// The space a run is measured on (World::observable_space), and what of it was left.
struct CoverageSpace {
  std::int64_t observable_cells = 0;   // coverage is the share of these the merged map observed
  std::int64_t unreachable_cells = 0;  // observable, but outside every reachable pose's disc
  std::int64_t pose_cells = 0;         // cells where a robot's centre can be
  std::int64_t free_cells = 0;         // every free cell of the true map
  std::int64_t largest_region_pose_cells = 0;  // poses of the largest region a robot can reach, wherever it starts
  int start_regions = 0;               // the regions the robots start in (more than one: some never meet)
  double cell_area_m2 = 0.0;
  std::vector<int> seen_unreachable;   // cell indices: the unreachable cells the merged map observed
};

// A connected part of the observable space the merged map has not observed at the end of a run,
// and why exploration left it.
struct UnexploredRegion {
  double area_m2 = 0.0;
  Eigen::Vector2d centre_m = Eigen::Vector2d::Zero();  // mean of its cell centres, world frame
  std::string reason;
};

struct RunResult {
  Scenario scenario;                 // as run: starts resolved, landmarks placed
  int steps = 0;                     // steps taken
  bool finished = false;             // every robot ran out of reachable frontiers (or came to the end of its drive)
  // coverage[k] after step k (k = 0: the first scan, before moving): the share of the observable
  // cells of the ground truth (World::observable_space) that the merged map has observed.
  std::vector<double> coverage;
  std::optional<int> steps_to_95, steps_to_99;
  double redundancy = 0.0;           // of the observable cells sensed, the share sensed by 2+ robots
  std::int64_t bytes_sent = 0;
  int meetings = 0;
  CoverageSpace space;
  // 8-connected regions of unobserved observable cells, largest first.
  std::vector<UnexploredRegion> unexplored;
  std::vector<RobotTrack> robots;     // truth and estimates in the world frame
  std::vector<core::Transform2> robot_frames;  // where each robot's map frame lies in the world, at the end
  std::vector<MergeRecord> merges;
  std::vector<Event> events;
  std::vector<Eigen::Vector2d> landmarks;
  mapping::OccupancyGrid merged;     // every robot's readings at its estimated pose
  std::vector<mapping::OccupancyGrid> robot_maps;
  // Against the ground truth: the merged map, and each robot's map placed by its true frame.
  mapping::MapQuality map_quality;
  std::vector<mapping::MapQuality> robot_map_quality;
  exploration::TeamExplorer::Stats exploration;
  Timings timing;
};

// The explorer's options for the robots and sensor of `scenario` (their radius, the sensor range).
exploration::ExplorationOptions explorer_options(const Scenario& scenario);

// Called after every step with (step, step limit, coverage).
using ProgressCallback = std::function<void(int, int, double)>;

class Simulation;

// How an experiment sets up a robot beyond what a scenario says. Every member may stay empty.
struct RobotSetup {
  // Drives the robot instead of the exploration.
  std::shared_ptr<Driver> driver;
  // Makes its localizer from the context the simulator built (start, seed, noise from the
  // scenario, the parameters of the scenario's localizer), e.g. a registered localizer with the
  // experiment's own noise model. Empty: the scenario's `localization` from the registry.
  localization::LocalizerFactory localizer;
  // Its random streams (motion noise, range and landmark sensors, robot detector). Empty: its own,
  // forked from the scenario's seed, the detector reading from the sensors' stream. One stream may
  // serve several (motion and sensors; two runs one after the other).
  std::shared_ptr<core::Random> motion_rng, sensor_rng, detector_rng;
  // León et al.'s odometry: no process noise on the motion, errors in what the encoders report.
  std::optional<OdometryError> odometry_error;
  // The grid of its own map, in its map frame (a robot in its own frame; default: large enough to
  // hold the whole world around its start, however the frame is turned).
  std::optional<core::GridGeometry> map_geometry;
};

// Two robots (a < b) whose link has just come up: an experiment's own exchange of what they know
// (D'Alfonso et al.'s polynomials), which then replaces the frame alignment and the grid exchange.
using MeetingHandler = std::function<void(Simulation&, int a, int b)>;

// One attempt to align two robots' frames (merging modes that search, e.g. overlap), with the two
// maps exactly as the aligner saw them, each in its robot's own map frame: for debugging a wrong or
// refused merge outside the run (`fleetmap explore --merge-attempts DIR` writes them as map files).
using MergeAttemptHandler = std::function<void(const MergeRecord&, const mapping::OccupancyGrid& receiver_map,
                                               const mapping::OccupancyGrid& sender_map)>;

struct SimulationSetup {
  std::vector<RobotSetup> robots;  // by robot index; robots beyond the list get the defaults
  // Coverage of the observable space, measured every step. Experiments that measure their own
  // outputs switch it off (it needs the observable space of the whole map).
  bool measure_coverage = true;
  MeetingHandler on_meeting;
  MergeAttemptHandler on_merge_attempt;
};

class Simulation {
 public:
  // Places the robots and takes the first readings. Throws InputError for starts in a wall,
  // outside the map, on another robot, or when the robots cannot all be placed.
  Simulation(const Scenario& scenario, mapping::OccupancyGrid truth, SimulationSetup setup = {});
  ~Simulation();

  // At the step limit, or every robot finished (out of reachable frontiers, or at the end of its drive).
  bool done() const;
  void step();
  // Steps to the end; `progress` and `on_step` (for pictures, an experiment's outputs) may be empty.
  void run_to_end(const ProgressCallback& progress = {}, const std::function<void(const Simulation&)>& on_step = {});
  // Runs to the end and returns the result.
  RunResult run(const ProgressCallback& progress = {}, const std::function<void(const Simulation&)>& on_step = {});

  int step_count() const { return step_; }
  const World& world() const { return world_; }
  const Scenario& scenario() const { return scenario_; }
  const mapping::OccupancyGrid& merged_map() const { return merged_; }
  const mapping::OccupancyGrid& robot_map(int i) const { return robots_[std::size_t(i)].map; }
  std::vector<core::Pose2> true_poses() const;
  std::vector<core::Pose2> estimated_poses() const;
  const RobotTrack& track(int i) const { return robots_[std::size_t(i)].track; }
  const localization::Localizer& localizer(int i) const { return *robots_[std::size_t(i)].localizer; }
  localization::Localizer& localizer(int i) { return *robots_[std::size_t(i)].localizer; }
  // The robots robot i detected this step.
  const std::vector<Detection>& detections(int i) const { return robots_[std::size_t(i)].detections; }
  // Robot i's detection of robot `other` this step, or null when i did not see it.
  const Detection* detection(int i, int other) const;
  std::vector<Eigen::Vector2d> path(int i) const { return explorer_.path(i); }
  // Robot i ran out of reachable frontiers (for now: it resumes when its map grows), or its driver
  // has no command left.
  bool finished(int i) const;
  // The targets robot i gave up so far, goals in its map frame at the time.
  const std::vector<exploration::TeamExplorer::GivenUp>& given_up(int i) const { return explorer_.given_up(i); }
  // What the strategy weighed in the last decision round (recorded when the scenario asks for the
  // replay page), positions in the frame of each decision's leader's map.
  const exploration::TeamExplorer& explorer() const { return explorer_; }
  // The events so far (meetings, merges, blocked moves, finished robots), oldest first.
  const std::vector<Event>& events() const { return events_; }
  const std::vector<MergeRecord>& merges() const { return merges_; }
  double coverage() const { return coverage_.empty() ? 0.0 : coverage_.back(); }
  // Where robot i's map frame lies in the world (identity with merging: known).
  const core::Transform2& frame_origin(int i) const { return frame_origin_[std::size_t(robots_[std::size_t(i)].frame)]; }

  RunResult result() const;
  // The observable cells the merged map has not observed, in regions, with the reason each was left.
  std::vector<UnexploredRegion> unexplored_regions() const;

 private:
  void sense_and_map();
  void communicate();
  void try_merge(int i, int j);
  // Every robot in `from` frame moves into `to` frame; `t` maps from-frame metres into to-frame metres.
  void adopt_frame(int from, int to, const core::Transform2& t);
  core::Pose2 in_world(int i, const core::Pose2& frame_pose) const;
  void decide();
  void measure();
  bool all_finished() const;

  // One robot of the run: where it truly is, what it knows (estimate, map in its map frame), its
  // random streams, and what the run records about it.
  struct Robot {
    core::Pose2 truth;
    std::unique_ptr<localization::Localizer> localizer;
    mapping::OccupancyGrid map;
    // Its map and pose estimate are in map frame `frame`, which lies at frame_origin_[frame] in the
    // world (known to the simulator only, for evaluation). With merging: known every robot is in
    // frame 0, the world's.
    int frame = 0;
    std::shared_ptr<core::Random> motion_rng, sensor_rng, detector_rng;
    std::shared_ptr<Driver> driver;        // null: the explorer drives
    std::optional<Command> command;        // the driver's for the next step; none: its drive is over
    std::optional<OdometryError> odometry_error;
    std::vector<Detection> detections;  // this step's
    RobotTrack track;
    bool was_finished = false;
    int blocked_streak = 0;  // consecutive blocked moves
    // Robots it bumped into: the step, and where the other stood in this robot's map frame.
    std::vector<std::pair<int, Eigen::Vector2d>> bumped;
  };
  // What stopped robot's move at `contact` (world frame) becomes a wall on its own map.
  void mark_contact(Robot& robot, const Eigen::Vector2d& contact);

  Scenario scenario_;
  SimulationSetup setup_;
  bool explored_ = true;  // some robot is driven by the explorer
  World world_;
  core::Random rng_;
  std::vector<Robot> robots_;
  mapping::OccupancyGrid merged_;
  MapExchange exchange_;
  exploration::TeamExplorer explorer_;
  std::unique_ptr<merging::MapAligner> aligner_;  // how robots in different frames align them
  std::vector<std::vector<char>> links_, previous_links_;
  ObservableSpace observable_;         // the cells coverage is measured on
  std::vector<std::uint64_t> sensed_by_;  // per cell, a bit per robot
  std::vector<double> coverage_;
  std::vector<Event> events_;
  // Map frame f lies at frame_origin_[f] in the world, with a grid of frame_geometry_[f].
  std::vector<core::Transform2> frame_origin_;
  std::vector<core::GridGeometry> frame_geometry_;
  std::vector<std::vector<int>> last_attempt_;  // overlap: step of the last attempt per pair
  std::vector<MergeRecord> merges_;
  std::int64_t bytes_sent_ = 0;
  int meetings_ = 0;
  int step_ = 0;
  Timings timing_;
};

}  // namespace fleetmap::sim
