#include "sim/run_metrics.h"

#include "sim/run_output.h"

namespace fleetmap::sim {

RunTotals run_totals(const RunResult& r) {
  RunTotals t;
  double rmse_sum = 0.0;
  for (const auto& robot : r.robots) {
    t.distance_m += robot.distance_m;
    t.blocked_moves += robot.blocked_moves;
    localization::LocalizationMetrics lm;
    for (std::size_t k = 0; k < robot.truth.size(); ++k) lm.add(robot.truth[k], robot.estimate[k], robot.covariance[k]);
    t.per_robot.push_back(lm.summary());
    rmse_sum += t.per_robot.back().position_rmse;
  }
  t.position_rmse_m = r.robots.empty() ? 0.0 : rmse_sum / double(r.robots.size());
  for (const auto& m : r.merges) (m.merged ? t.merges_made : t.merges_refused) += 1;
  return t;
}

std::string metrics_json_text(const RunResult& result, const std::string& map_label) {
  return metrics_json(result, map_label).dump(2) + "\n";
}

}  // namespace fleetmap::sim
