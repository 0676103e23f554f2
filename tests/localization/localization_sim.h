#pragma once
// A small simulation for the localization tests: a differential-drive robot on a known, wavy
// loop among point landmarks (the command steers from the true pose back onto the loop), with noise drawn exactly per the filters' model:
//   truth_{k+1} = integrate_motion(truth_k, u_k) + w_k,  w_k ~ N(0, diag(sxy^2, sxy^2, sth^2)),
//   range = |m - p| + N(0, sr^2),  bearing = wrap(atan2(m - p) - theta + N(0, sb^2)),
// every landmark within the sensor range is read each step, with its id when the options say
// associations are known. It is written independently of localization/ekf_models.
#include <Eigen/Core>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "core/angle.h"
#include "core/random.h"
#include "core/transform2.h"
#include "localization/localizer.h"

namespace fleetmap::localization::testing {

struct SimWorld {
  std::vector<Landmark> landmarks;
  double sensor_range = 8.0;  // m
};

// Two rings of landmarks around the loop (radii 10 m and 22 m, `per_ring` each).
inline SimWorld ring_world(int per_ring = 16) {
  SimWorld w;
  int id = 0;
  for (double radius : {10.0, 22.0}) {
    for (int i = 0; i < per_ring; ++i) {
      const double a = 2.0 * std::numbers::pi * (i + 0.5 * (radius > 15.0)) / per_ring;
      w.landmarks.push_back({id++, Eigen::Vector2d(radius * std::cos(a), radius * std::sin(a))});
    }
  }
  return w;
}

inline constexpr double kLoopRadius = 100.0 / (2.0 * std::numbers::pi);  // m: one lap per 100 s at 1 m/s

// The command at step k: 1 m/s counter-clockwise around the loop (radius kLoopRadius about the
// origin), with a wobble, steered from the true pose back onto the loop so that the process noise
// does not carry the robot away from the landmarks. The command is known exactly to the filters.
inline Odometry command(int k, const core::Pose2& truth) {
  const double base = 1.0 / kLoopRadius;
  const double tangent = std::atan2(truth.y, truth.x) + std::numbers::pi / 2.0;
  const double wanted = tangent + std::atan(0.3 * (truth.position().norm() - kLoopRadius));
  const double steer = std::clamp(0.5 * core::normalize_angle(wanted - truth.theta), -0.2, 0.2);
  return {1.0, base * (1.0 + 0.5 * std::cos(2.0 * std::numbers::pi * k / 37.0)) + steer, 1.0};
}

// Where the loop starts: on its circle, heading along it.
inline core::Pose2 loop_start() { return {kLoopRadius, 0.0, std::numbers::pi / 2.0}; }

inline std::vector<LandmarkObservation> read_landmarks(const core::Pose2& truth, const SimWorld& world,
                                                       const LocalizerOptions& noise, core::Random& rng) {
  std::vector<LandmarkObservation> out;
  for (const Landmark& l : world.landmarks) {
    const double dx = l.position.x() - truth.x, dy = l.position.y() - truth.y;
    const double range = std::hypot(dx, dy);
    if (range > world.sensor_range) continue;
    LandmarkObservation o;
    o.id = noise.known_associations ? l.id : -1;
    o.range = range + rng.normal(0.0, noise.range_noise);
    o.bearing = core::normalize_angle(std::atan2(dy, dx) - truth.theta + rng.normal(0.0, noise.bearing_noise));
    out.push_back(o);
  }
  return out;
}

inline core::Pose2 move(const core::Pose2& truth, const Odometry& u, const LocalizerOptions& noise, core::Random& rng) {
  const core::Pose2 next = integrate_motion(truth, u);
  return {next.x + rng.normal(0.0, noise.process_noise_xy), next.y + rng.normal(0.0, noise.process_noise_xy),
          core::normalize_angle(next.theta + rng.normal(0.0, noise.process_noise_theta))};
}

// A start pose drawn from the prior N(estimate, P0), so that the initial error matches P0.
inline core::Pose2 draw_start(const core::Pose2& estimate, const LocalizerOptions& o, core::Random& rng) {
  return {estimate.x + rng.normal(0.0, o.initial_xy), estimate.y + rng.normal(0.0, o.initial_xy),
          core::normalize_angle(estimate.theta + rng.normal(0.0, o.initial_theta))};
}

struct Trace {
  std::vector<core::Pose2> truth;
  std::vector<core::Pose2> estimate;
  std::vector<Eigen::Matrix3d> covariance;
};

// Runs `steps` steps (the trace holds step 0, the start, and one entry per step).
inline Trace simulate(Localizer& localizer, const SimWorld& world, const LocalizerOptions& noise,
                      const core::Pose2& true_start, int steps, core::Random& rng) {
  Trace t;
  core::Pose2 truth = true_start;
  localizer.observe_truth(truth);
  const auto record = [&] {
    t.truth.push_back(truth);
    t.estimate.push_back(localizer.pose());
    t.covariance.push_back(localizer.covariance());
  };
  record();
  for (int k = 0; k < steps; ++k) {
    const Odometry u = command(k, truth);
    truth = move(truth, u, noise, rng);
    localizer.predict(u);
    localizer.update_landmarks(read_landmarks(truth, world, noise, rng));
    localizer.observe_truth(truth);
    record();
  }
  return t;
}

// The localizer's counter `name`; a test failure naming it when the localizer has none.
inline double counter(const Localizer& l, const std::string& name) {
  for (const auto& [key, value] : l.counters()) {
    if (key == name) return value;
  }
  ADD_FAILURE() << "no counter " << name;
  return -1.0;
}

}  // namespace fleetmap::localization::testing
