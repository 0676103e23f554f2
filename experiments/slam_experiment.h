#pragma once
// D'Alfonso et al. §4's experiment: robots driven along precomputed paths (the commands are computed once,
// noise-free, from the waypoints), each running its SLAM method from its own origin
// (x_j,0 = [0 0 0] in R_j,0), exchanging maps when two robots see each other, and measured
// against the truth: mu (the paper's form and the standard NEES), nu, tau, bytes per rendezvous.
// A run is a sim::Simulation set up for it: each robot driven by its commands (sim::CommandScript),
// in its own frame, with the filter as its localizer; a meeting handler exchanges the polynomials.
// `method` picks the SLAM method by name from slam_method_registry(): `polynomial`, and any a
// program registers with register_slam_method, each built from the parameters it declares.
#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "core/registry.h"
#include "core/transform2.h"
#include "localization/localizer.h"
#include "localization/metrics.h"
#include "mapping/occupancy_grid.h"
#include "mapping/polynomial_map.h"
#include "experiments/slam_scenario.h"
#include "sim/world.h"

namespace fleetmap::experiments {

// The room as a grid: free inside the boundary and outside every obstacle (a cell is free when its
// centre is), with a blocked frame of one cell plus `margin_m` around it.
mapping::OccupancyGrid rasterize_room(const SlamRoom& room, double margin_m = 0.0);

// The commands that drive a robot from `start` along `path` at `speed`, one per step: heading for
// the next waypoint (turning at most max_turn_rate, in place when more than 60 degrees off), and
// (0, 0) once the last waypoint is reached. Noise-free, computed once (D'Alfonso et al., §4: "angular
// velocities precomputed").
std::vector<localization::Odometry> path_commands(const core::Pose2& start, const std::vector<Eigen::Vector2d>& path,
                                                  double speed, int steps, double period_s, double max_turn_rate);

// What every run of a scenario shares.
// One run of the team: the prepared scenario, the run index, exchange on or off, one robot by index
// or all with -1 (run_slam).
struct SlamSetup;
struct SlamRunResult;
using SlamRun = std::function<SlamRunResult(const SlamSetup&, int run, bool exchange, int only)>;

struct SlamSetup {
  SlamScenario scenario;
  SlamRun method;  // the scenario's method, built from its parameters
  sim::World world;
  std::vector<mapping::WallSegment> walls;
  std::vector<std::vector<localization::Odometry>> commands;  // per robot, per step
  std::vector<std::vector<core::Pose2>> planned;              // per robot, the noise-free poses, k = 0..steps
};

// Rasterises the room, precomputes the paths and builds the method. Throws InputError naming the
// robot when a start or a step of its noise-free path is within the robot's radius of a wall, and
// as make_slam_method for the method's parameters.
SlamSetup prepare_slam(const SlamScenario& scenario);

struct SlamRendezvous {
  int step = 0;
  int sender = -1;
  int receiver = -1;
  int polynomials = 0;            // polynomials sent
  std::int64_t bytes = 0;         // merging::message_bytes
  std::int64_t grid_bytes = 0;    // the equivalent occupancy-grid patch
};

struct SlamRobotResult {
  std::string name;
  std::vector<core::Pose2> truth;     // k = 0..steps, room frame
  std::vector<core::Pose2> estimate;  // the estimate brought into the room frame by the true start
  localization::LocalizationSummary localization;  // mu (dalfonso_mu), the standard NEES, RMSE
  // Dead reckoning on the same run: the odometry integrated from the filter's start estimate. The odometry is the
  // precomputed commands (the noise is the model's w_k, on the true motion), so this is the
  // noise-free path, unless a move was cut short by a wall.
  double dead_reckoning_rmse = 0.0;  // m
  mapping::MappingError mapping;      // nu
  double boundary_coverage = 0.0;     // share of the true walls within 0.1 m of the map
  double tau_s = 0.0;                 // mean SLAM time per step (predict, update, received maps)
  int polynomials = 0;
  std::vector<std::vector<Eigen::Vector2d>> map_curves;  // the map in the room frame, for pictures
  std::vector<std::pair<std::string, double>> counters;
};

struct SlamRunResult {
  int run = 0;
  bool exchange = true;
  std::vector<SlamRobotResult> robots;
  std::vector<SlamRendezvous> rendezvous;
};

// One run: the run index picks its random streams (per robot: motion, sensors, camera), so a run
// without exchange has the same noise as the same run with it. `only` restricts the team to one
// robot by index (-1: all), for the single-robot runs of D'Alfonso et al. Fig. 8.
SlamRunResult run_slam(const SlamSetup& setup, int run, bool exchange, int only = -1);

// A SLAM method: its runs made from its declared parameters' values. May throw InputError for
// values that do not fit together.
using SlamMethod = std::function<SlamRun(const core::Params&)>;
// Every SLAM method by name: the built-in `polynomial`, then those registered by the program.
core::Registry<SlamMethod>& slam_method_registry();
// Adds a method with the parameters it accepts (core/params.h): a scenario's `method:` (and
// `fleetmap slam`) then reaches it. Throws Error when the name is taken or unusable.
void register_slam_method(std::string name, std::string help, SlamMethod method, std::vector<core::ParamSpec> params = {});
// The registered names, in the order --help lists them.
std::vector<std::string> slam_method_names();
// The method's declared parameters with `settings` applied. Throws InputError for an unknown method
// (naming the valid ones), a setting it does not declare or a value it refuses.
core::Params slam_method_options(const std::string& name, const core::Settings& settings = {});
// The method built from them; throws as slam_method_options and as the method's factory.
SlamRun make_slam_method(const std::string& name, const core::Settings& settings = {});

}  // namespace fleetmap::experiments
