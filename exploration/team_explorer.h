#pragma once
// Frontier exploration for a team: keeps each robot's target and path, notices when a target is
// reached, explored, blocked or hopeless, and asks the coordination strategy for new targets.
// Robots that can talk decide together (on the map of the robot that needs a target); a robot
// that talks to nobody decides alone on its own map.
#include <Eigen/Core>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "exploration/frontiers.h"
#include "exploration/strategy.h"
#include "exploration/traversability.h"
#include "exploration/wave.h"
#include "mapping/occupancy_grid.h"

namespace fleetmap::exploration {

struct ExplorationOptions {
  std::string strategy = "directional";
  StrategySettings strategy_settings;  // over the strategy's declared defaults
  WaveOptions wave;
  TargetOptions targets;
  TraversabilityOptions traversability;
  double sensor_range_m = 4.0;      // for the utility reduction around assigned targets
  double reach_tolerance_m = 0.25;  // a goal closer than this is reached
  int stall_steps = 20;             // steps without progress along the path before giving a target up
  int path_check_cells = 30;        // path cells ahead checked each step against new obstacles
  // A failed approach (stalled, cut off, or reached without seeing the unseen cell) is not tried
  // again from the same goal until the robot's map holds this many more observed cells, or the robot
  // has nothing else to do; other goals for the same frontier are tried meanwhile. After
  // `max_attempts` failed approaches to one frontier, it is left for good.
  int retry_after_new_cells = 400;
  int max_attempts = 3;
  // Entering a cell where the robot fits but without radius + margin of known free space around
  // it (Passage::Fits) costs this many times a Clear cell's step.
  int tight_cost_factor = 3;
  // A robot that made no progress for this many steps plans a detour around the robots it knows of.
  int detour_after_steps = 4;
  // The explorer decides (traversability, frontiers, waves, paths) on cells of at least this size:
  // a map finer than this is seen through cells a whole number of times larger (mapping::coarsen),
  // so a 5 mm map costs what a 5 cm map costs. 0: always on the map's own cells.
  double planning_resolution_m = 0.05;
};

// What the explorer sees of one robot in a round.
struct ExplorerRobot {
  const mapping::OccupancyGrid* map = nullptr;  // the robot's own map
  core::Pose2 pose;                             // its estimated pose in that map's frame
  // Where robots it has just bumped into stand, in that map's frame (a bumper's contact, whether
  // or not it can talk to them): a detour plans around them as around the robots it knows of.
  std::vector<Eigen::Vector2d> bumped_robots;
};

// Plans a path on a robot's map from `from` to `to` (metres), or returns nothing. The simulator
// supplies one backed by a sampling or grid planner; without one, robots follow the wave.
using PathProvider = std::function<std::vector<Eigen::Vector2d>(const mapping::OccupancyGrid& map,
                                                                const Eigen::Vector2d& from, const Eigen::Vector2d& to)>;

class TeamExplorer {
 public:
  // Throws InputError for an unknown strategy name.
  TeamExplorer(int robots, const ExplorationOptions& options);

  // New targets and replanned paths come from `provider` when it finds a path the robot can
  // follow (every cell on it clear); otherwise from the wave. Detours around robots use the wave.
  void set_path_provider(PathProvider provider) { provider_ = std::move(provider); }

  // One decision round. `links[i][j]` is true when robots i and j can talk now. Maps finer than
  // the planning resolution are coarsened first; the path provider then gets the coarse map.
  void update(const std::vector<ExplorerRobot>& robots, const std::vector<std::vector<char>>& links);

  // The rest of robot i's path in metres (cell centres from the next one to the goal); empty when
  // it has no target.
  std::vector<Eigen::Vector2d> path(int i) const;
  std::optional<Eigen::Vector2d> goal(int i) const;
  // No reachable frontier is left for the robot (on its map); it may resume when its map grows.
  bool finished(int i) const { return robots_[std::size_t(i)].finished; }
  bool all_finished() const;
  // Forgets robot i's target, path and failed approaches (its map moved to another frame).
  void reset_robot(int i) { robots_[std::size_t(i)] = RobotState{}; }

  // A frontier robot i left when it last ran out of targets, in its map's frame, and why.
  struct LeftFrontier {
    Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
    std::string reason;
  };
  const std::vector<LeftFrontier>& left_frontiers(int i) const { return robots_[std::size_t(i)].left; }

  // A target robot i gave up (stalled, or cut off by new obstacles), in its map's frame at the time.
  struct GivenUp {
    Eigen::Vector2d goal_m = Eigen::Vector2d::Zero();
    std::string reason;
  };
  // Every target robot i gave up so far, oldest first (kept across reset_robot).
  const std::vector<GivenUp>& given_up(int i) const { return given_up_[std::size_t(i)]; }

  // What the strategy weighed for one robot in one decision round, and what it chose: recorded
  // only after record_decisions(true) (a replay shows them as the robot's reasons).
  struct Candidate {
    Eigen::Vector2d frontier_m = Eigen::Vector2d::Zero();  // the target's frontier cell, leader's map frame
    Eigen::Vector2d goal_m = Eigen::Vector2d::Zero();      // where the robot would drive
    int cells = 0;                                         // frontier cells of the target's piece
    std::vector<double> terms;                             // per ScoreSheet::terms of decision_sheet()
    double score = 0.0;
    int taken_by = -1;  // another robot (team index) of the group got this target in the same round
  };
  struct Decision {
    int round = 0;   // the update() call that made it, from 1
    int robot = 0;   // team index
    int leader = 0;  // the group decided on this robot's map: positions are in its map's frame
    std::vector<int> group;             // the robots that decided together (team indices)
    std::vector<Candidate> candidates;  // empty when the strategy reported nothing
    int chosen = -1;                    // index into candidates; -1: none (or not reported)
    std::optional<Eigen::Vector2d> goal_m;  // the target given, reported or not
    bool kept = false;  // no new target: the robot keeps the one it drives to
    bool reported = false;
    std::string note;
  };
  void record_decisions(bool on) { record_ = on; }
  // The decisions of the last update() (empty unless recording).
  const std::vector<Decision>& decisions() const { return decisions_; }
  int rounds() const { return rounds_; }
  // The names of the strategy's score terms (ScoreSheet without robots) from its last report;
  // empty terms: it reported nothing.
  const ScoreSheet& decision_sheet() const { return sheet_; }

  struct Stats {
    int assignment_rounds = 0;
    int waves = 0;
    int targets_reached = 0;
    int targets_given_up = 0;     // stalled or cut off; the counts below split them
    int given_up_stalled = 0;
    int given_up_unreachable = 0;
    int unobservable = 0;  // reached, yet the unseen cell stayed unseen: another approach is tried
    int frontiers_abandoned = 0;  // max_attempts approaches failed: left for good
    int paths_replanned = 0;
    int detours = 0;
    int yields = 0;  // finished robots that moved out of another's way
    int provider_paths = 0;     // paths from the path provider
    int provider_fallbacks = 0;  // the provider found none: the wave's path was used
  };
  const Stats& stats() const { return stats_; }
  const CoordinationStrategy& strategy() const { return *strategy_; }

 private:
  enum class Failure { Stalled, Unreachable, Unobservable };
  struct FailedApproach {
    Cell frontier, goal;
    std::int64_t known_cells = 0;  // the robot's observed-cell count when it failed
    Failure why = Failure::Stalled;
    bool for_good = false;  // part of max_attempts failures at one frontier: never retried
  };
  struct RobotState {
    bool has_task = false;
    bool yielding = false;  // the task is only to get out of another robot's way
    Cell frontier, unknown, goal;
    std::uint8_t kind = FrontierMask::kWide;  // the target's frontier kind
    std::vector<Cell> path;
    std::vector<char> was_clear;  // per path cell: the robot fitted there when the path was planned
    std::size_t next = 0;  // first path cell not yet passed
    std::size_t best_remaining = 0;  // fewest path cells left to the goal so far (replans included)
    int steps_since_progress = 0;
    bool finished = false;
    std::int64_t known_when_finished = 0;
    std::vector<FailedApproach> failed;
    std::vector<LeftFrontier> left;
    core::GridGeometry geometry;  // of the robot's map, to turn cells into metres
  };

  // The round on maps at the planning resolution.
  void decide(const std::vector<ExplorerRobot>& robots, const std::vector<std::vector<char>>& links);
  // false: the task was dropped.
  bool check_task(int i, const std::vector<ExplorerRobot>& robots, const std::vector<std::vector<char>>& links);
  // Robot i's approach to its target failed; with `tell`, the robots it talks to learn it too.
  void fail_approach(int i, Failure why, std::int64_t known_cells, const std::vector<std::vector<char>>* tell = nullptr);
  void assign_group(const std::vector<int>& members, int leader, const std::vector<ExplorerRobot>& robots,
                    const std::vector<int>& claim_holders);
  // The goal is an approach that failed for this frontier, or the frontier is left for good.
  bool blocked(const RobotState& r, const Cell& frontier, const Cell& goal, double resolution) const;
  // Passable cells (Fits or Clear) of passage_cells and their wave step factors.
  void passage_grid(const std::vector<std::uint8_t>& passage, std::vector<std::uint8_t>& passable,
                    std::vector<std::uint8_t>& factor) const;
  // Moves r.next past the path cells the robot has reached; counts steps without progress.
  static void track_progress(RobotState& r, const mapping::OccupancyGrid& map, const Eigen::Vector2d& p);
  // New obstacles on robot i's path ahead: a new path to the same goal, or the task given up
  // (false).
  bool replan_around_new_obstacles(int i, const ExplorerRobot& robot);
  // A wave on `map` from `from` into `out`, over the passage grid opened around `from` (after
  // `block` closed what it wants closed, e.g. the cells around other robots). Returns the grid's
  // passable cells.
  std::vector<std::uint8_t> wave_from(const mapping::OccupancyGrid& map, const Cell& from, WaveField& out,
                                      const std::function<void(std::vector<std::uint8_t>&)>& block = {},
                                      const std::function<void(std::vector<std::uint8_t>&)>& block_after_open = {});
  void set_path(RobotState& r, std::vector<Cell> path, const mapping::OccupancyGrid& map) const;
  // The provider's path to the goal as cells, or the wave's when the provider has none.
  std::vector<Cell> plan(const mapping::OccupancyGrid& map, const ExplorerRobot& robot, const Cell& goal,
                         const WaveField& wave);
  // Keeps what the strategy reported for the group's decision (decisions_).
  void record(const std::vector<int>& members, int leader, const mapping::OccupancyGrid& map,
              const std::vector<Target>& targets, const std::vector<int>& choice, ScoreSheet& sheet);
  // Finished robots standing on the path of robot `stuck` move to the nearest place clear of it.
  void make_way(int stuck, const std::vector<ExplorerRobot>& robots, const std::vector<std::vector<char>>& links);

  ExplorationOptions options_;
  std::unique_ptr<CoordinationStrategy> strategy_;
  PathProvider provider_;
  std::vector<RobotState> robots_;
  std::vector<std::vector<GivenUp>> given_up_;  // per robot
  WaveField wave_;  // reused storage
  std::vector<mapping::OccupancyGrid> coarse_;  // per robot: its map at the planning resolution
  Stats stats_;
  bool record_ = false;
  int rounds_ = 0;
  std::vector<Decision> decisions_;
  ScoreSheet sheet_;
};

}  // namespace fleetmap::exploration
