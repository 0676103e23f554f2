#include "sim/sensors.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/angle.h"
#include "mapping/ray_cast.h"

namespace fleetmap::sim {

std::vector<double> beam_angles(const RangeSensorOptions& o) {
  if (!o.angles_rad.empty()) return o.angles_rad;
  std::vector<double> a(std::size_t(std::max(0, o.beams)));
  for (std::size_t i = 0; i < a.size(); ++i) a[i] = core::normalize_angle(2.0 * std::numbers::pi * double(i) / double(a.size()));
  return a;
}

localization::RangeScan read_ranges(const World& world, const core::Pose2& truth, const RangeSensorOptions& o,
                                    core::Random& rng) {
  localization::RangeScan scan;
  scan.angles = beam_angles(o);
  scan.max_range = o.max_range_m;
  scan.ranges.reserve(scan.angles.size());
  for (double a : scan.angles) {
    const auto d = mapping::cast_ray(world.truth(), truth.position(), truth.theta + a, o.max_range_m);
    if (!d) {
      scan.ranges.emplace_back(std::nullopt);
      continue;
    }
    scan.ranges.emplace_back(std::clamp(rng.normal(*d, o.noise_m), 0.0, o.max_range_m));
  }
  return scan;
}

std::vector<localization::LandmarkObservation> read_landmarks(const World& world, const core::Pose2& truth,
                                                              const LandmarkSensorOptions& o, core::Random& rng) {
  std::vector<localization::LandmarkObservation> out;
  const Eigen::Vector2d p = truth.position();
  for (std::size_t i = 0; i < world.landmarks().size(); ++i) {
    const Eigen::Vector2d d = world.landmarks()[i] - p;
    const double r = d.norm();
    if (r > o.max_range_m || !mapping::line_of_sight(world.truth(), p, world.landmarks()[i])) continue;
    localization::LandmarkObservation obs;
    obs.id = o.report_ids ? int(i) : -1;
    obs.range = std::max(0.0, rng.normal(r, o.range_noise_m));
    obs.bearing = core::normalize_angle(rng.normal(std::atan2(d.y(), d.x()) - truth.theta, o.bearing_noise_rad));
    out.push_back(obs);
  }
  return out;
}

std::vector<Detection> detect_robots(const World& world, int self, const std::vector<core::Pose2>& truths,
                                     const RobotDetectorOptions& o, core::Random& rng) {
  std::vector<Detection> out;
  const core::Pose2& me = truths[std::size_t(self)];
  for (std::size_t j = 0; j < truths.size(); ++j) {
    if (int(j) == self) continue;
    const Eigen::Vector2d d = truths[j].position() - me.position();
    const double r = d.norm();
    const double bearing = core::normalize_angle(std::atan2(d.y(), d.x()) - me.theta);
    if (r > o.max_range_m || std::abs(bearing) > 0.5 * o.fov_rad + 1e-12) continue;
    if (!mapping::line_of_sight(world.truth(), me.position(), truths[j].position())) continue;
    out.push_back({int(j), std::max(0.0, rng.normal(r, o.range_noise_m)),
                   core::normalize_angle(rng.normal(bearing, o.bearing_noise_rad))});
  }
  return out;
}

}  // namespace fleetmap::sim
