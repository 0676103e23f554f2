#pragma once
// A run as one self-contained HTML page a browser opens from disk: the merged map at every step
// with the robots, their trajectories, targets, paths and the frontier cells; each robot's own map;
// the coverage curve and the run's events on a timeline. The page holds its data as JSON and its
// own script (no network, no external files). Maps are stored as a first picture and then only the
// cells that changed at each step.
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/grid_geometry.h"
#include "core/transform2.h"
#include "viz/render.h"

namespace fleetmap::viz {

// What a replay cell shows. The page colours the first three as the map pictures do (colorize).
// In a layer stored relative to the merged map, the fourth code means "as the merged map".
enum class ReplayCell : std::uint8_t { Unknown = 0, Free = 1, Occupied = 2, Frontier = 3, AsMerged = 3 };

// A grid that changes step by step. Each step's cells are stored as the changes from the step
// before (cell, old code, new code: the page steps backward as well as forward); a step whose
// geometry differs from the last (a robot's map moved into another robot's frame) starts again
// from a whole picture, run-length encoded.
class ReplayLayer {
 public:
  ReplayLayer() = default;
  explicit ReplayLayer(std::string name) : name_(std::move(name)) {}
  // The layer at the next step (the first call is step 0): one code per cell of `geometry`, row-major
  // from the lower-left cell as OccupancyGrid indexes them. `relative`: the cells are stored against
  // the merged layer of the same step and geometry (AsMerged where they agree), which a robot's map
  // mostly does when the robots share their maps: its changes then cost little.
  void add_step(const core::GridGeometry& geometry, const std::vector<ReplayCell>& cells, bool relative = false);
  int steps() const { return steps_; }
  const std::string& name() const { return name_; }
  // {"name", "frames": [{"step", "width", "height", "resolution", "origin": [x, y, theta], "relative", "cells"}],
  //  "changes": [one base64 string per step, "" when nothing changed]}.
  nlohmann::json to_json() const;
  // The encoded bytes (base64 text) of every frame and change so far.
  std::size_t encoded_bytes() const { return bytes_; }

 private:
  std::string name_;
  core::GridGeometry geometry_;
  bool relative_ = false;
  std::vector<ReplayCell> cells_;
  int steps_ = 0;
  nlohmann::json frames_ = nlohmann::json::array(), changes_ = nlohmann::json::array();
  std::size_t bytes_ = 0;
};

// The encodings the page decodes (base64 of unsigned LEB128 varints):
// runs: per run of equal cells, (length << 2) | code;
// changes: per changed cell in index order, (gap << 4) | (old << 2) | new, gap = cells skipped since
// the last change.
std::string encode_runs(const std::vector<ReplayCell>& cells);
std::string encode_changes(const std::vector<ReplayCell>& before, const std::vector<ReplayCell>& after);
std::string base64(const std::vector<std::uint8_t>& bytes);

// One target a strategy weighed for a robot: where it is (world frame), its score terms and score.
struct ReplayCandidate {
  Eigen::Vector2d frontier_m = Eigen::Vector2d::Zero(), goal_m = Eigen::Vector2d::Zero();
  int cells = 0;              // frontier cells of its piece
  std::vector<double> terms;  // per ReplayScores::terms (NaN: none)
  double score = 0.0;         // NaN: not ranked for this robot
  int taken_by = -1;          // the robot (from 0) that got it in the same decision
};

// A robot's decision: the candidates it weighed, best first, and the one chosen.
struct ReplayDecision {
  int step = 0;
  int leader = 0;           // the robot whose map the group decided on
  std::vector<int> group;   // the robots that decided together
  std::vector<ReplayCandidate> candidates;  // the best few (and the chosen one)
  int weighed = 0;          // candidates the strategy weighed in all
  int chosen = -1;          // index into candidates
  std::optional<Eigen::Vector2d> goal_m;  // the target given (also when the strategy reported no scores)
  bool kept = false;        // no new target: it kept its own
  bool reported = false;    // the strategy reported its scores
  std::string note;
};

// What the strategy's scores mean, for the page's "why" panel.
struct ReplayScores {
  std::string strategy;
  std::vector<std::string> terms;
  std::string score;
  bool lower_is_better = true;
  std::string rule;
};

struct ReplayRobot {
  std::string name;
  Color color;
  // Per step, world frame: where it truly was, and where it believed it was.
  std::vector<core::Pose2> truth, estimate;
  // Per step: where its own map frame lies in the world (it changes when its map merges into
  // another robot's frame), so that its estimate and plans are drawn on its own map too.
  std::vector<core::Pose2> frame;
  // Its planned paths in its map frame (metres), each stored once; per step the plan followed
  // (-1: none) and how many of its points were already passed.
  std::vector<std::vector<Eigen::Vector2d>> plans;
  std::vector<int> plan, passed;
  std::vector<char> finished;  // per step: no reachable frontier left (for now)
  double distance_m = 0.0;     // the path length the run reports (metrics.json's distance_m)
  std::vector<ReplayDecision> decisions;  // oldest first
};

struct ReplayEvent {
  int step = 0;
  std::string kind;  // "meeting", "merge", "refused merge", "given up", "blocked", "finished"
  int robot = -1, other = -1;  // from 0; -1: none
  std::string text;
  // Where it happened (world frame), when it has a place (a given-up target).
  std::optional<Eigen::Vector2d> at_m;
};

struct Replay {
  std::string title;
  std::vector<std::pair<std::string, std::string>> facts;  // shown under the title
  double robot_radius_m = 0.2;
  double period_s = 1.0;
  bool estimates = false;  // draw the estimated trajectories too (not ideal localization)
  std::vector<double> coverage;  // per step
  ReplayLayer merged;            // world frame, frontier cells marked
  std::vector<ReplayLayer> robot_maps;  // each robot's own map, in its own frame
  std::vector<ReplayRobot> robots;
  std::vector<ReplayEvent> events;
  ReplayScores scores;
};

// The data the page reads (documented by replay_html's script).
nlohmann::json replay_json(const Replay& replay);
// The page. Its address may carry options after '#', joined by '&': step=K (open at step K),
// robot=R (the robot whose own map is shown, from 1), overlays=0 (the maps alone: no robots,
// paths or frontier colour), and for tests and pictures only=map (nothing but the whole merged
// grid, at scale=S pixels per cell, at the page's top-left corner) or only=robot (the same for
// robot R's own map).
std::string replay_html(const Replay& replay);

}  // namespace fleetmap::viz
