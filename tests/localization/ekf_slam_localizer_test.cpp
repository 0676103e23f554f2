// `ekf-slam` (localization/ekf_slam_localizer.cpp), checked against localization_sim.h.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "localization/ekf_models.h"
#include "localization/localizer.h"
#include "localization/metrics.h"
#include "tests/localization/localization_sim.h"

namespace fleetmap::localization {
namespace {

using testing::ring_world;
using testing::simulate;
using testing::counter;

LocalizerOptions slam_options() {
  LocalizerOptions o;
  o.process_noise_xy = 0.03;
  o.process_noise_theta = 0.005;
  o.range_noise = 0.1;
  o.bearing_noise = 0.02;
  o.initial_xy = 0.0;  // the robot knows its start: the map frame is the world frame
  o.initial_theta = 0.0;
  return o;
}

std::unique_ptr<Localizer> make_slam(const LocalizerOptions& o, const core::Settings& settings = {}) {
  LocalizerContext c;
  c.initial_pose = testing::loop_start();
  c.options = o;
  c.params = localizer_options("ekf-slam", settings);
  return make_localizer("ekf-slam", c);
}

const Landmark* nearest(const testing::SimWorld& w, const Eigen::Vector2d& p) {
  const Landmark* best = nullptr;
  for (const Landmark& l : w.landmarks) {
    if (!best || (l.position - p).norm() < (best->position - p).norm()) best = &l;
  }
  return best;
}

// The squared Mahalanobis distance of the truth from a landmark estimate.
double landmark_d2(const Landmark& estimate, const Eigen::Vector2d& truth) {
  const Eigen::Vector2d e = truth - estimate.position;
  return e.dot(estimate.covariance.ldlt().solve(e));
}

TEST(EkfSlam, WithoutNoiseStaysOnTheTruthAndMapsTheLandmarksExactly) {
  const auto world = ring_world();
  for (bool known : {true, false}) {
    LocalizerOptions o;
    o.process_noise_xy = o.process_noise_theta = o.range_noise = o.bearing_noise = 0.0;
    o.initial_xy = o.initial_theta = 0.0;
    o.known_associations = known;
    auto slam = make_slam(o);
    core::Random rng(3);
    const testing::Trace t = simulate(*slam, world, o, testing::loop_start(), 250, rng);
    for (std::size_t k = 0; k < t.truth.size(); ++k) {
      ASSERT_LT(pose_error(t.truth[k], t.estimate[k]).norm(), 1e-9) << "step " << k << " known " << known;
    }
    const auto estimates = slam->landmark_estimates();
    EXPECT_EQ(estimates.size(), world.landmarks.size());  // two laps see every landmark, once each
    for (const Landmark& e : estimates) {
      EXPECT_LT((nearest(world, e.position)->position - e.position).norm(), 1e-9);
      if (known) {
        EXPECT_EQ(nearest(world, e.position)->id, e.id);
      }
    }
    EXPECT_EQ(counter(*slam, "rejected_associations"), 0.0);
  }
}

// D'Alfonso et al. eq. (4)-(5): a landmark enters at g(x_{k|k-1}, y_k) with covariance
// G_pose P_{k|k-1} G_pose^T + G_y V G_y^T.
TEST(EkfSlam, AddsALandmarkByTheAugmentationOfDAlfonso) {
  LocalizerOptions o = slam_options();
  o.initial_xy = 0.2;
  o.initial_theta = 0.05;
  auto slam = make_slam(o);
  const Odometry u{1.0, 0.2, 1.0};
  slam->predict(u);
  const core::Pose2 predicted = slam->pose();
  const Eigen::Matrix3d p = slam->covariance();
  const Eigen::Vector2d z(5.0, 0.4);
  slam->update_landmarks({{42, z(0), z(1)}});

  const auto estimates = slam->landmark_estimates();
  ASSERT_EQ(estimates.size(), 1u);
  EXPECT_EQ(estimates[0].id, 42);
  const LandmarkGenerationJacobians g = landmark_generation_jacobians(predicted, z);
  const Eigen::Matrix2d expected =
      g.pose * p * g.pose.transpose() + g.reading * measurement_noise(o) * g.reading.transpose();
  EXPECT_TRUE(estimates[0].covariance.isApprox(expected, 1e-12));
  EXPECT_TRUE(estimates[0].position.isApprox(landmark_from_reading(predicted, z), 1e-12));
  // A new landmark adds no information about the pose.
  EXPECT_EQ(slam->pose(), predicted);
  EXPECT_TRUE(slam->covariance().isApprox(p, 0.0));
  EXPECT_EQ(counter(*slam, "landmarks_in_state"), 1.0);
  EXPECT_EQ(counter(*slam, "landmarks_added"), 1.0);
}

// Over 30 Monte-Carlo runs of two laps, the landmark estimates hold the true positions within their
// 3-sigma ellipses (d^2 <= 9, probability 98.9% for a consistent 2D estimate): at least 95% of all
// estimates, and the worst one within 5 sigma.
TEST(EkfSlam, LandmarkEstimatesHoldTheTruthWithinTheirThreeSigmaEllipses) {
  const auto world = ring_world();
  for (bool known : {true, false}) {
    LocalizerOptions o = slam_options();
    o.known_associations = known;
    int total = 0, inside = 0;
    double worst = 0.0;
    for (int run = 0; run < 30; ++run) {
      core::Random rng = core::Random(99).fork(static_cast<std::uint64_t>(run));
      auto slam = make_slam(o);
      simulate(*slam, world, o, testing::loop_start(), 200, rng);
      const auto estimates = slam->landmark_estimates();
      EXPECT_EQ(estimates.size(), world.landmarks.size()) << "run " << run << " known " << known;
      for (const Landmark& e : estimates) {
        const double d2 = landmark_d2(e, nearest(world, e.position)->position);
        ++total;
        inside += d2 <= 9.0;
        worst = std::max(worst, d2);
      }
    }
    EXPECT_GE(static_cast<double>(inside) / total, 0.95) << inside << " of " << total << ", known " << known;
    EXPECT_LE(worst, 25.0) << "known " << known;
  }
}

TEST(EkfSlam, UnknownAssociationsGiveOneLandmarkPerTrueLandmark) {
  const auto world = ring_world();
  LocalizerOptions o = slam_options();
  o.known_associations = false;
  auto slam = make_slam(o);
  core::Random rng(8);
  core::Pose2 truth = testing::loop_start();
  double readings = 0.0;
  for (int k = 0; k < 200; ++k) {
    const Odometry u = testing::command(k, truth);
    truth = testing::move(truth, u, o, rng);
    slam->predict(u);
    const auto r = testing::read_landmarks(truth, world, o, rng);
    readings += static_cast<double>(r.size());
    slam->update_landmarks(r);
  }
  std::set<int> matched;
  for (const Landmark& e : slam->landmark_estimates()) matched.insert(nearest(world, e.position)->id);
  EXPECT_EQ(matched.size(), world.landmarks.size());
  EXPECT_EQ(slam->landmark_estimates().size(), world.landmarks.size());
  // Every reading was used, started a landmark, or was rejected; the 99% gate rejects about 1%.
  EXPECT_EQ(counter(*slam, "landmark_updates") + counter(*slam, "landmarks_added") +
                counter(*slam, "rejected_associations"),
            readings);
  EXPECT_LT(counter(*slam, "rejected_associations"), 0.03 * readings);
}

// With forget_after_steps, landmarks left behind leave the state; seen again, they return.
TEST(EkfSlam, TheStateShrinksWhenLandmarksAreNotSeenForLong) {
  const auto world = ring_world();
  LocalizerOptions o = slam_options();
  auto slam = make_slam(o, {{"forget_after_steps", "5"}});
  core::Random rng(4);
  core::Pose2 truth = testing::loop_start();
  std::map<int, int> last_seen;
  std::size_t largest = 0;
  for (int k = 0; k < 150; ++k) {
    const Odometry u = testing::command(k, truth);
    truth = testing::move(truth, u, o, rng);
    slam->predict(u);
    const auto readings = testing::read_landmarks(truth, world, o, rng);
    slam->update_landmarks(readings);
    for (const auto& r : readings) last_seen[r.id] = k;
    // Exactly the landmarks read in the last 6 steps are in the state.
    std::set<int> expected;
    for (const auto& [id, when] : last_seen) {
      if (k - when <= 5) expected.insert(id);
    }
    std::set<int> held;
    for (const Landmark& e : slam->landmark_estimates()) held.insert(e.id);
    ASSERT_EQ(held, expected) << "step " << k;
    largest = std::max(largest, held.size());
  }
  EXPECT_LT(largest, world.landmarks.size());
  EXPECT_GT(counter(*slam, "landmarks_removed"), 0.0);
  EXPECT_EQ(counter(*slam, "landmarks_added") - counter(*slam, "landmarks_removed"),
            counter(*slam, "landmarks_in_state"));
  // A full lap brought landmarks back after they had been forgotten.
  EXPECT_GT(counter(*slam, "landmarks_added"), static_cast<double>(world.landmarks.size()));
}

TEST(EkfSlam, RobotDetectionsUpdateThePoseWhenEnabled) {
  LocalizerOptions o = slam_options();
  o.initial_xy = 0.5;
  o.use_robot_detections = true;
  auto slam = make_slam(o);
  const double trace_before = slam->covariance().trace();
  RobotObservation d;
  d.other_pose = {testing::loop_start().x + 3.0, testing::loop_start().y, 0.0};
  d.other_covariance = Eigen::Matrix3d::Identity() * 1e-4;
  d.range = 3.0;
  d.bearing = -std::numbers::pi / 2.0;  // the robot heads along +y; +x is on its right
  slam->update_robot(d);
  EXPECT_EQ(counter(*slam, "robot_updates"), 1.0);
  EXPECT_LT(slam->covariance().trace(), trace_before);
}

}  // namespace
}  // namespace fleetmap::localization
