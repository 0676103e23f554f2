#pragma once
// The totals of a run that metrics.json, results.csv and the run summary all report, computed in
// one place from the run's record.
#include <string>
#include <vector>

#include "localization/metrics.h"
#include "sim/simulation.h"

namespace fleetmap::sim {

struct RunTotals {
  double distance_m = 0.0;       // true path length of all robots
  int blocked_moves = 0;
  double position_rmse_m = 0.0;  // mean over robots of each robot's position RMSE
  int merges_made = 0, merges_refused = 0;
  std::vector<localization::LocalizationSummary> per_robot;  // from truth, estimate and covariance
};

RunTotals run_totals(const RunResult& result);

// Why a run's coverage may mislead, in one line, or "" when it need not: the robots start outside
// the largest region a robot can reach, in several regions, or can observe less than half of the
// map's free space (a start in a pocket explores the pocket "completely").
std::string reachable_space_warning(const RunResult& result);

// The text of metrics.json as `fleetmap explore` writes it (indented JSON), for programs that link
// fleetmap; `map_label` is the map's name in it.
std::string metrics_json_text(const RunResult& result, const std::string& map_label);

}  // namespace fleetmap::sim
