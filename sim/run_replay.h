#pragma once
// The browser replay of a run (viz/replay.h): recorded step by step from the simulation, like
// RunVideo, and turned into one self-contained HTML page at the end.
#include <string>
#include <vector>

#include "exploration/frontiers.h"
#include "sim/simulation.h"
#include "viz/replay.h"

namespace fleetmap::sim {

class RunReplay {
 public:
  // Call after the simulation is made (step 0) and after every step (Simulation::run's on_step).
  void add_step(const Simulation& sim);
  // The page: what was recorded, with the run's events and merge attempts from `result`.
  std::string html(const RunResult& result, const std::string& map_label) const;
  // Candidates kept per decision: the best ones by the strategy's score, and the chosen one.
  static constexpr int kCandidates = 8;
  int steps() const { return int(robots_.empty() ? 0 : robots_.front().truth.size()); }
  // The encoded maps so far (bytes of base64 text): the merged map and the robots' own maps.
  std::size_t map_bytes() const;

 private:
  // A map recorded as a replay layer, with what it held at the last step so that only the rows
  // whose log-odds changed are looked at again.
  struct Recorded {
    viz::ReplayLayer layer;
    core::GridGeometry geometry;
    std::vector<float> log_odds;
    std::vector<viz::ReplayCell> cells;
    // A robot's map on the merged map's grid is stored against it: AsMerged where they agree.
    std::vector<viz::ReplayCell> relative;
  };
  // Brings `r` up to `map`; returns the changed cells' indices.
  static std::vector<int> refresh(Recorded& r, const mapping::OccupancyGrid& map);
  // Marks the frontier cells of the merged map around the cells that changed.
  void mark_frontiers(const Simulation& sim, const std::vector<int>& changed, bool all);
  // Brings `own.relative` up to its cells against the merged map, looking again only at `changed`
  // cells of either unless `all`.
  void relate(Recorded& own, const std::vector<int>& own_changed, const std::vector<int>& merged_changed, bool all) const;

  // The decisions of the explorer's rounds since the last step, with their best candidates.
  void add_decisions(const Simulation& sim);

  exploration::FrontierOptions frontier_options_;
  int rounds_seen_ = 0;
  exploration::ScoreSheet sheet_;  // names of the strategy's score terms (no robots)
  Recorded merged_;
  std::vector<Recorded> own_;
  std::vector<viz::ReplayRobot> robots_;
  std::vector<std::vector<Eigen::Vector2d>> last_plan_;
  std::vector<std::size_t> given_up_seen_;
  std::vector<viz::ReplayEvent> given_up_;
};

}  // namespace fleetmap::sim
