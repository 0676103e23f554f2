#include "sim/run_metrics.h"

#include <fmt/format.h>

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

std::string reachable_space_warning(const RunResult& r) {
  const auto& sp = r.space;
  const double observable = double(sp.observable_cells) * sp.cell_area_m2, free = double(sp.free_cells) * sp.cell_area_m2;
  std::string why;
  if (sp.pose_cells < sp.largest_region_pose_cells) {
    why = fmt::format("the robots start outside the largest region a robot can reach (they can be on {:.1f} m2, it "
                      "holds {:.1f} m2)",
                      double(sp.pose_cells) * sp.cell_area_m2, double(sp.largest_region_pose_cells) * sp.cell_area_m2);
  }
  if (sp.start_regions > 1) {
    why += fmt::format("{}the robots start in {} regions they cannot drive between (each team explores only its own)", why.empty() ? "" : "; ", sp.start_regions);
  }
  if (observable < 0.5 * free) {
    why += fmt::format("{}they can observe {:.1f} m2 of the map's {:.1f} m2 of free space ({:.1f}%)", why.empty() ? "" : "; ",
                       observable, free, free > 0.0 ? 100.0 * observable / free : 0.0);
  }
  return why;
}

std::string metrics_json_text(const RunResult& result, const std::string& map_label) {
  return metrics_json(result, map_label).dump(2) + "\n";
}

}  // namespace fleetmap::sim
