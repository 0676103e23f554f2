#pragma once
// Coordination strategies: which robot goes to which frontier target. One interface, chosen by
// name (`--strategy`, scenario files) through make_strategy(); tests iterate strategy_names().
#include <Eigen/Core>

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/registry.h"
#include "exploration/frontiers.h"

namespace fleetmap::exploration {

// A strategy's parameters with their values: those it declared when it was registered, each at
// its default unless a scenario file, `--set strategy.KEY=VALUE` or a sweep axis set it.
using StrategyOptions = core::Params;
// Settings by name, as written in a scenario file ({beta: "0.5"}), applied over the defaults of
// whichever strategy is made: a sweep gives each run's strategy those it declares.
using StrategySettings = core::Settings;

// What a strategy weighed when it chose targets, for a replay to show why (a robot's candidates and
// their score terms). Strategies fill it only when AssignmentInput::scores asks: no cost otherwise.
struct CandidateScore {
  int target = -1;            // index into AssignmentInput::targets
  std::vector<double> terms;  // one value per ScoreSheet::terms
  double score = 0.0;         // what the strategy ranked this candidate by (ScoreSheet::score)
};

struct RobotScores {
  std::vector<CandidateScore> candidates;  // the targets it weighed for this robot (reachable ones)
  std::string note;                        // the strategy's words on this robot's decision
};

struct ScoreSheet {
  std::vector<std::string> terms;  // names of the score terms, with units, e.g. "wave cost (m)"
  std::string score;               // the name of what candidates are ranked by
  bool lower_is_better = true;
  std::string rule;                // how the strategy decides, one sentence
  std::vector<RobotScores> robots; // per robot of the input; empty: the strategy reported nothing
};

struct AssignmentRobot {
  int team_index = 0;  // this robot's place in the team, 0..team_size-1
  int team_size = 1;
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  double heading_rad = 0.0;    // where the robot faces, in (-pi, pi], counter-clockwise from +x
  std::vector<double> cost_m;  // wave cost to each target's goal, metres; +inf when unreachable
};

struct AssignmentInput {
  std::vector<Target> targets;
  std::vector<AssignmentRobot> robots;       // the robots to assign now
  std::vector<Eigen::Vector2d> claimed;      // goals other robots already drive to (known by talking)
  double sensor_range_m = 4.0;               // utility of targets near an assigned one drops within it
  // Wave costs between the targets' goals in metres (targets x targets, +inf between goals that are
  // not connected), for strategies that plan tours through several targets; computed only when
  // called, during assign(). Empty: target_costs() uses straight lines.
  std::function<Eigen::MatrixXd()> target_costs_m;
  // Per target, the never-observed area in square metres it would reveal (unknown_area_behind), for
  // strategies that weigh targets by it; computed only when called. Empty: every target counts alike.
  std::function<std::vector<double>()> target_gains_m2;
  // When set, the strategy may describe its decision here (every built-in one does; one that does
  // not leaves it empty). Null in ordinary runs.
  ScoreSheet* scores = nullptr;
};

class CoordinationStrategy {
 public:
  virtual ~CoordinationStrategy() = default;
  virtual std::string name() const = 0;
  // Joint strategies reassign every robot they can talk to whenever one needs a new target;
  // the others assign only the robot that needs one.
  virtual bool joint() const = 0;
  // Per robot of the input: the index of its target, or -1 for none. Joint strategies give each
  // target to one robot at most; with more robots than targets the others get -1 and wait (a team
  // that sends its spare robots after taken targets jams in the last corridor). Exception: `tour`
  // sends a robot with an empty tour ahead to a target on another robot's tour (two at most).
  virtual std::vector<int> assign(const AssignmentInput& input) const = 0;
};

using StrategyFactory = std::function<std::unique_ptr<CoordinationStrategy>(const StrategyOptions&)>;

// Every coordination strategy by name: the built-in ones, then those registered by the program.
core::Registry<StrategyFactory>& strategy_registry();
// Adds a strategy: `--strategy NAME`, scenario files, sweeps and the test harnesses reach it.
// Throws Error when the name is taken or unusable.
// `params` are the settings the strategy accepts (core/params.h); its factory gets their values.
void register_strategy(std::string name, std::string help, StrategyFactory make,
                       std::vector<core::ParamSpec> params = {});

std::vector<std::string> strategy_names();
// One line per strategy with its source, for --help and README.
std::string strategy_help();
// The strategy's declared parameters with `settings` applied. Throws InputError for an unknown
// strategy (listing the valid names), a setting it does not declare or a value out of its range.
StrategyOptions strategy_options(const std::string& name, const StrategySettings& settings = {});
// The settings among `settings` that strategy `name` declares (a sweep's runs of several strategies).
StrategySettings declared_settings(const std::string& name, const StrategySettings& settings);
// Throws as strategy_options().
std::unique_ptr<CoordinationStrategy> make_strategy(const std::string& name, const StrategySettings& settings = {});

// ---- helpers shared by the strategies ----

// Burgard's visibility model: the chance that a target at distance d from an assigned one is
// explored by it, 1 - d / range inside the sensor range and 0 beyond.
double visibility_overlap(double distance_m, double sensor_range_m);
// Utilities start at 1 and drop by visibility_overlap for every claimed goal.
std::vector<double> initial_utilities(const AssignmentInput& input);
// The largest finite cost in the input (1 when there is none), to scale costs into [0, 1].
double cost_scale(const AssignmentInput& input);
// input.target_costs_m() when the input has it, else the straight-line distances between the goals.
Eigen::MatrixXd target_costs(const AssignmentInput& input);
// Each robot without a target takes its cheapest reachable one (taken or not).
void nearest_targets(const AssignmentInput& input, std::vector<int>& assignment);
// Fills input.scores, when asked, with one candidate per robot and reachable target: `score(i, t)`
// gives robot i's candidate t (its terms and score). Header fields come from `sheet`.
void report_scores(const AssignmentInput& input, ScoreSheet sheet,
                   const std::function<CandidateScore(std::size_t robot, std::size_t target)>& score);

}  // namespace fleetmap::exploration
