#pragma once
// A scenario: everything that defines a run. Loaded from YAML (every key checked, errors name the
// file, line and key), written back to YAML, and overridden by command-line flags.
#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/transform2.h"
#include "exploration/team_explorer.h"
#include "localization/localizer.h"
#include "merging/merge.h"
#include "planning/planner.h"
#include "sim/communication.h"
#include "sim/motion.h"
#include "sim/sensors.h"

namespace fleetmap::sim {

enum class Placement { Cluster, Random, List };

// The values every number of a scenario accepts. The scenario parser, validate_scenario and the
// command-line flags all use these, so a flag accepts exactly what a scenario file accepts and a
// saved scenario.yaml always loads again.
namespace limits {
using core::Range;
inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr Range kSteps{1, 10'000'000, true};
inline constexpr Range kPeriod{1e-6, 3600};
inline constexpr Range kRobots{1, 64, true};
inline constexpr Range kSeparation{0, 1e6};
inline constexpr Range kRadius{1e-3, 100};
inline constexpr Range kSpeed{0, 100};
inline constexpr Range kTurnRateDeg{0, 36000};
inline constexpr Range kNoiseMetres{0, 100};
inline constexpr Range kAngleDeg{0, 360};
inline constexpr Range kBeams{1, 100'000, true};
inline constexpr Range kSensorRange{1e-3, 1e6};
inline constexpr Range kDetectorRange{0, 1e6};
inline constexpr Range kLandmarksPerMetre{0, 100};
inline constexpr Range kGate{0, 1e6};
inline constexpr Range kInitialSigma{0, 1e3};
inline constexpr Range kMclParticles{1, 1'000'000, true};
inline constexpr Range kRbpfParticles{1, 10'000, true};
inline constexpr Range kCommRange{0, kInf, false, true};
inline constexpr Range kWeight{0, 1e6};
inline constexpr Range kCount{1, 1'000'000, true};
inline constexpr Range kLength{1e-3, 1e6};
inline constexpr Range kMargin{0, 100};
inline constexpr Range kPlannerTime = planning::kTimeBudgetRange;
inline constexpr Range kPlannerIterations{1, 100'000'000, true};
inline constexpr Range kConfidence = merging::kConfidenceRange;
inline constexpr Range kLookahead{0, 1e6};
}  // namespace limits

struct Scenario {
  std::string map = "office";       // built-in name, or a PNG/PGM/YAML path
  std::filesystem::path base_dir;   // relative map paths are resolved here (the scenario's folder)
  double map_resolution_m = 0.05;   // metres per cell of a bare image map (a map_server YAML has its own)
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
  std::vector<Eigen::Vector2d> landmarks;    // fixed artificial landmarks (wave-algorithm paper, §V)
  double landmarks_along_walls = 0.0;        // plus this many per metre of wall, placed with the seed

  std::string localization = "ideal";
  localization::LocalizerOptions localization_options;
  // The localizer's own parameters, as given (`localization: {name: rbpf, particles: 50}`, `--set
  // localization.particles=50`); checked against its declaration by validate_scenario.
  core::Settings localization_settings;
  // Robots (numbered from 1) that do not know where they start: `mcl` starts them from a uniform
  // belief over the map (global localization, León et al. §IV).
  std::vector<int> lost_robots;
  CommunicationOptions communication;
  exploration::ExplorationOptions exploration;
  // How robots bring others' maps into their frame, a merging::MapAligner by name: "known" (every
  // robot knows its start pose in a common frame), "rendezvous" (each robot maps in its own frame;
  // robots that detect each other compute the relative transform from the detection, D'Alfonso et
  // al. §3.2), "overlap" (robots that can talk search their maps for the best overlap, merging/) or
  // "landmarks" (they associate their estimated landmark maps by RANSAC).
  std::string merging = "known";
  // The aligner's own parameters, as given (`merging: {mode: overlap, method: features}`, `--set
  // merging.min_confidence=0.7`; overlap: method, min_confidence; landmarks: min_confidence,
  // support_distance); checked against its declaration by validate_scenario.
  core::Settings merging_settings;
  // The merge methods' own parameters, for an aligner that runs them (overlap's `method`), by
  // method: `merging: {mode: overlap, method: auto, features: {ratio: 0.7}}`, `--set
  // merging.features.ratio=0.7`.
  merging::MergeMethodSettings merge_method_settings;
  int merge_attempt_every = 20;              // overlap, landmarks: steps between attempts of the same pair
  double lookahead_m = 0.5;                  // path following
  // How robots get a path to their target: "wave" (the wave's steepest descent) or a planner of
  // planning/ by name (astar, rrtconnect, rrtstar, ...). A sampling planner stops after
  // `planner_iterations` iterations, so that a run is the same on every machine; `planner_time_s`
  // only caps a path's wall time (a run whose planner hits it may not repeat exactly).
  std::string path_planner = "wave";
  core::Settings planner_settings;  // the planner's own parameters (`path_planner: {name: reactive, step: 0.1}`)
  double planner_time_s = 10.0;
  int planner_iterations = 2000;
  // Outputs beyond the standard ones (`outputs:` in a scenario file): replay.html, the run in the
  // browser (`fleetmap explore --html`).
  bool html_replay = false;
};

// Every registered merging::MapAligner: known, rendezvous, overlap, landmarks, and any added since.
std::vector<std::string> merging_names();
// "wave" and every planner of planning/.
std::vector<std::string> path_planner_names();
// The path planner's declared parameters at their defaults (none for "wave"); throws InputError for
// an unknown name.
core::Params path_planner_options(const std::string& name);

// Parses scenario YAML; `source` names it in errors and `base_dir` anchors relative map paths.
Scenario parse_scenario(const std::string& text, const std::string& source, const std::filesystem::path& base_dir);
Scenario load_scenario(const std::filesystem::path& path);
// The map to load: a built-in name as is (unless a file of that name is in the scenario's folder),
// else the file path, relative paths taken from the scenario's folder (base_dir), or from the
// working directory when the scenario came from flags.
std::string map_source(const Scenario& scenario);
// Every setting, explicitly, in the layout parse_scenario reads, for a file in `file_dir`: a map
// file is written relative to that folder (or absolute when it has no relative path), so the
// file finds its map from wherever it is run.
std::string scenario_to_yaml(const Scenario& scenario, const std::filesystem::path& file_dir = {});

// Checks values that need no map (counts, ranges, noise, names, a merging whose needs the
// localizer meets). Throws InputError naming the key.
void validate_scenario(const Scenario& scenario);

// A family whose members declare parameters that a scenario sets: its name in `--set` and `--vary`
// (strategy, localization, planner, merging, and merging.METHOD for each merge method the overlap
// aligner may run), the member the scenario chose and the settings given to it.
struct ParameterFamily {
  std::string name;
  std::string group;  // the scenario key whose mapping holds the member's name and parameters, dotted
  std::function<std::string(const Scenario&)> member;
  std::function<core::Settings&(Scenario&)> settings;
  // The member's parameters at their defaults; throws InputError for an unknown name.
  std::function<core::Params(const std::string& member)> params;
  // Every parameter some member declares, for "did you mean" and to accept a sweep axis.
  std::function<std::vector<std::string>()> parameter_names;
};
// Every family, the merge methods registered so far included; references stay valid as more are
// registered.
const std::deque<ParameterFamily>& parameter_families();
// The family named `name`, or null.
const ParameterFamily* parameter_family(const std::string& name);

// `--set FAMILY.KEY=VALUE`: one declared parameter of the scenario's member of that family, kept
// until the member is made (so that a sweep checks it against each of its members). Throws
// InputError naming `what` for an unknown family or a malformed assignment; the key and value are
// checked by validate_scenario (or validate_sweep).
void set_parameter(Scenario& scenario, const std::string& assignment, const std::string& what);

// The message for a merging that aligns estimated landmarks (MapAligner::needs_landmark_estimates)
// with a localizer that estimates none, naming the localizers that do.
std::string landmark_merging_problem(const Scenario& scenario);

}  // namespace fleetmap::sim
