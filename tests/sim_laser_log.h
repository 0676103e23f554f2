#pragma once
// A CARMEN laser log written from the simulator's world, for the tests of SLAM on logs: a robot
// drives laps around the pillar of the asymmetric room (tests/localization/grid_slam_sim.h), each
// scan a FLASER line with the true laser pose in its pose field and drifting odometry (Gaussian
// noise on every step's motion) in its odometry field, as a real robot's log has them.
#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "core/angle.h"
#include "core/random.h"
#include "core/transform2.h"
#include "localization/relation_metric.h"
#include "tests/localization/grid_slam_sim.h"

namespace fleetmap::testing {

struct SimLaserLog {
  std::string text;                 // the CARMEN log
  std::vector<core::Pose2> truth;   // per scan, the laser's true pose
  std::vector<core::Pose2> odometry;  // per scan, the odometry written
  std::vector<std::string> timestamps;
  std::vector<double> times;
};

struct SimLaserLogOptions {
  int laps = 2;
  double step_m = 0.1;          // forward motion between scans
  double turn_step_rad = 0.25;  // turning in place at the corners
  double range_noise_m = 0.01;
  // Odometry noise per step, proportional to the motion (GMapping's srr / stt style).
  double odometry_translation_noise = 0.05;  // m per m
  double odometry_rotation_noise = 0.05;     // rad per rad turned, and 0.02 rad per m driven
  double max_range_m = 8.0;
  int beams = 181;
  std::uint64_t seed = 7;
};

inline SimLaserLog sim_laser_log(const SimLaserLogOptions& o = {}) {
  const mapping::OccupancyGrid room = localization::testing::asymmetric_room();
  core::Random rng(o.seed);
  // Laps of a rectangle around the pillar (at 3, 2.5), clear of the notch and the ledge.
  const std::vector<Eigen::Vector2d> corners{{1.2, 1.2}, {8.6, 1.2}, {8.6, 3.8}, {1.2, 3.8}};
  std::vector<core::Pose2> truth;
  core::Pose2 pose(1.2, 1.2, 0.0);
  truth.push_back(pose);
  for (int lap = 0; lap < o.laps; ++lap) {
    for (std::size_t c = 1; c <= corners.size(); ++c) {
      const Eigen::Vector2d target = corners[c % corners.size()];
      const double heading = std::atan2(target.y() - pose.y, target.x() - pose.x);
      while (std::abs(core::normalize_angle(heading - pose.theta)) > 1e-9) {
        const double d = core::normalize_angle(heading - pose.theta);
        pose.theta = core::normalize_angle(pose.theta + std::clamp(d, -o.turn_step_rad, o.turn_step_rad));
        truth.push_back(pose);
      }
      while ((target - pose.position()).norm() > 1e-9) {
        const double d = std::min(o.step_m, (target - pose.position()).norm());
        pose = core::Pose2(pose.x + d * std::cos(pose.theta), pose.y + d * std::sin(pose.theta), pose.theta);
        truth.push_back(pose);
      }
    }
  }
  SimLaserLog log;
  log.truth = truth;
  core::Pose2 odometry = truth.front();
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (i > 0) {
      const core::Pose2 step = truth[i - 1].inverse().compose(truth[i]);
      const double d = std::hypot(step.x, step.y), a = std::abs(step.theta);
      const core::Pose2 noisy(step.x + rng.normal(0.0, o.odometry_translation_noise * d),
                              step.y + rng.normal(0.0, o.odometry_translation_noise * d),
                              step.theta + rng.normal(0.0, o.odometry_rotation_noise * a + 0.02 * d));
      odometry = odometry.compose(noisy);
    }
    log.odometry.push_back(odometry);
    localization::RangeScan scan;
    std::string ranges;
    for (int b = 0; b < o.beams; ++b) {
      const double angle = -std::numbers::pi / 2 + std::numbers::pi * b / (o.beams - 1);
      auto r = mapping::cast_ray(room, truth[i].position(), truth[i].theta + angle, o.max_range_m);
      const double value = r ? std::clamp(*r + rng.normal(0.0, o.range_noise_m), 0.0, o.max_range_m - 0.01) : o.max_range_m;
      ranges += fmt::format(" {:.3f}", value);
    }
    const double t = 1000.0 + 0.2 * double(i);
    const std::string stamp = fmt::format("{:.6f}", t);
    log.timestamps.push_back(stamp);
    log.times.push_back(std::stod(stamp));
    log.text += fmt::format("FLASER {}{} {:.6f} {:.6f} {:.6f} {:.6f} {:.6f} {:.6f} {} sim {}\n", o.beams, ranges, truth[i].x,
                            truth[i].y, truth[i].theta, odometry.x, odometry.y, odometry.theta, stamp, stamp);
  }
  return log;
}

// Reference relations from the true poses: every consecutive pair, pairs 10 scans apart, and each
// scan of the first lap with the scan of the last lap nearest to it (the loop).
inline std::vector<localization::ReferenceRelation> sim_relations(const SimLaserLog& log) {
  std::vector<localization::ReferenceRelation> out;
  const std::size_t n = log.truth.size();
  auto add = [&](std::size_t i, std::size_t j) {
    out.push_back({log.times[i], log.times[j], 1e-4, 1e-4, log.truth[i].inverse().compose(log.truth[j])});
  };
  for (std::size_t i = 0; i + 1 < n; ++i) add(i, i + 1);
  for (std::size_t i = 0; i + 10 < n; i += 5) add(i, i + 10);
  for (std::size_t i = 0; i < n / 2; i += 5) {
    std::size_t best = n / 2;
    for (std::size_t j = n / 2; j < n; ++j) {
      if ((log.truth[j].position() - log.truth[i].position()).norm() < (log.truth[best].position() - log.truth[i].position()).norm()) best = j;
    }
    add(i, best);
  }
  return out;
}

// The same relations as a relations file (`t1 t2 x y z roll pitch yaw`).
inline std::string relations_text(const SimLaserLog& log) {
  std::string out;
  for (const auto& r : sim_relations(log)) {
    out += fmt::format("{:.6f} {:.6f} {:.6f} {:.6f} 0 0 0 {:.6f}\n", r.t1, r.t2, r.motion.x, r.motion.y, r.motion.theta);
  }
  return out;
}

}  // namespace fleetmap::testing
