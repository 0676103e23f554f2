#include "localization/relation_metric.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/angle.h"

namespace fleetmap::localization {

namespace {

// The pose nearest to `t` within `tolerance`, if any.
std::optional<core::Pose2> pose_at(const std::vector<TimedPose>& trajectory, double t, double tolerance) {
  const auto after = std::lower_bound(trajectory.begin(), trajectory.end(), t,
                                      [](const TimedPose& p, double time) { return p.time_s < time; });
  std::optional<core::Pose2> best;
  double best_gap = tolerance;
  for (auto it : {after, after == trajectory.begin() ? trajectory.end() : std::prev(after)}) {
    if (it == trajectory.end()) continue;
    const double gap = std::abs(it->time_s - t);
    if (gap <= best_gap) best_gap = gap, best = it->pose;
  }
  return best;
}

void mean_and_std(const std::vector<double>& v, double& mean, double& std) {
  mean = std = 0.0;
  if (v.empty()) return;
  for (double x : v) mean += x;
  mean /= double(v.size());
  for (double x : v) std += (x - mean) * (x - mean);
  std = std::sqrt(std / double(v.size()));
}

}  // namespace

RelationErrors relation_errors(const std::vector<TimedPose>& trajectory, const std::vector<ReferenceRelation>& relations) {
  RelationErrors out;
  out.relations = relations.size();
  std::vector<double> translation, rotation;
  for (const auto& r : relations) {
    const auto a = pose_at(trajectory, r.t1, r.t1_tolerance), b = pose_at(trajectory, r.t2, r.t2_tolerance);
    out.matched_each.push_back(a && b);
    if (!a || !b) continue;
    const core::Pose2 est = a->inverse().compose(*b);
    translation.push_back((est.position() - r.motion.position()).norm());
    rotation.push_back(std::abs(core::normalize_angle(est.theta - r.motion.theta)));
  }
  out.matched = translation.size();
  mean_and_std(translation, out.translation_mean_m, out.translation_std_m);
  mean_and_std(rotation, out.rotation_mean_rad, out.rotation_std_rad);
  return out;
}

}  // namespace fleetmap::localization
