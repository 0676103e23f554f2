// `fastslam2` (localization/fastslam2.cpp), checked against localization_sim.h: the FastSLAM 2.0
// filter of Montemerlo et al. 2003 and the map-alignment paper's two maps of it (eq. (14)-(15)).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "localization/ekf_models.h"
#include "localization/fastslam2.h"
#include "localization/localizer.h"
#include "localization/metrics.h"
#include "tests/localization/localization_sim.h"

namespace fleetmap::localization {
namespace {

// Two rings of 24 landmarks and a 12 m sensor: about ten readings per step.
testing::SimWorld dense_world() {
  testing::SimWorld w = testing::ring_world(24);
  w.sensor_range = 12.0;
  return w;
}

LocalizerOptions fastslam_options() {
  LocalizerOptions o;
  o.process_noise_xy = 0.03;
  o.process_noise_theta = 0.005;
  o.range_noise = 0.1;
  o.bearing_noise = 0.02;
  o.initial_xy = 0.0;  // the robot knows its start: the map frame is the world frame
  o.initial_theta = 0.0;
  return o;
}

FastSlam2 make_filter(const LocalizerOptions& o, std::uint64_t seed) {
  FastSlam2Options f;
  f.particles = 50;
  f.process_noise = process_noise(o);
  f.measurement_noise = measurement_noise(o);
  f.known_associations = o.known_associations;
  return FastSlam2(testing::loop_start(), initial_covariance(o), f, seed);
}

struct Outcome {
  double mean_error_slam = 0.0;      // m, position error over the run
  double mean_error_odometry = 0.0;
  double final_heading_error = 0.0;  // rad
  std::vector<Landmark> max_weight, combined;
  long resamples = 0;
};

// One run of the loop with the filter and with dead reckoning on the same drive.
Outcome run(const LocalizerOptions& o, std::uint64_t seed, int steps) {
  const auto world = dense_world();
  core::Random rng = core::Random(31).fork(seed);
  FastSlam2 filter = make_filter(o, seed);
  core::Pose2 truth = testing::loop_start(), odometry = truth;
  Outcome out;
  for (int k = 0; k < steps; ++k) {
    const Odometry u = testing::command(k, truth);
    truth = testing::move(truth, u, o, rng);
    odometry = integrate_motion(odometry, u);
    filter.predict(u);
    filter.update(testing::read_landmarks(truth, world, o, rng));
    out.mean_error_slam += (filter.pose().position() - truth.position()).norm() / steps;
    out.mean_error_odometry += (odometry.position() - truth.position()).norm() / steps;
  }
  out.final_heading_error = std::abs(core::normalize_angle(filter.pose().theta - truth.theta));
  out.max_weight = filter.map(ParticleMap::MaxWeight);
  out.combined = filter.map(ParticleMap::Combined);
  out.resamples = filter.resamples();
  return out;
}

double map_rms(const std::vector<Landmark>& map) {
  const auto world = dense_world();
  double sum = 0.0;
  for (const Landmark& l : map) sum += (l.position - world.landmarks[std::size_t(l.id)].position).squaredNorm();
  return map.empty() ? 0.0 : std::sqrt(sum / double(map.size()));
}

// Without noise every particle stays on the truth and maps every landmark where it is.
TEST(FastSlam2, WithoutNoiseStaysOnTheTruthAndMapsTheLandmarksExactly) {
  LocalizerOptions o = fastslam_options();
  o.process_noise_xy = o.process_noise_theta = o.range_noise = o.bearing_noise = 0.0;
  const Outcome r = run(o, 1, 120);
  EXPECT_LT(r.mean_error_slam, 1e-6);
  EXPECT_EQ(r.combined.size(), dense_world().landmarks.size());
  EXPECT_LT(map_rms(r.combined), 1e-6);
}

// Over seeded runs of two laps the filter's pose error stays a fraction of dead reckoning's and
// about the noise of one reading (0.1 m range, 0.02 rad bearing at up to 12 m: up to 0.25 m), the
// landmarks converge to within that too, and both maps hold every landmark.
TEST(FastSlam2, BeatsOdometryAndItsParticleMapsConverge) {
  const LocalizerOptions o = fastslam_options();
  double slam = 0.0, odometry = 0.0, rms_best = 0.0, rms_combined = 0.0;
  long resamples = 0;
  const int runs = 4;
  for (int seed = 0; seed < runs; ++seed) {
    const Outcome r = run(o, std::uint64_t(seed), 200);
    slam += r.mean_error_slam / runs;
    odometry += r.mean_error_odometry / runs;
    EXPECT_EQ(r.max_weight.size(), dense_world().landmarks.size());
    EXPECT_EQ(r.combined.size(), dense_world().landmarks.size());
    EXPECT_LT(r.final_heading_error, 0.1) << "seed " << seed;
    rms_best += map_rms(r.max_weight) / runs;
    rms_combined += map_rms(r.combined) / runs;
    resamples += r.resamples;
  }
  EXPECT_LT(slam, 0.35);
  EXPECT_LT(slam, 0.3 * odometry) << "odometry " << odometry;
  EXPECT_LT(rms_best, 0.4);
  EXPECT_LT(rms_combined, 0.4);
  EXPECT_GT(resamples, 0);  // the weights did tell the particles apart
}

// On the same readings as `ekf-slam` (one Gaussian over pose and map, the reference for this
// linear-ish problem), FastSLAM 2.0 with 50 particles keeps its pose error within twice the EKF's
// on average and never far off: before the loop closes both drift as landmarks pass out of reach
// (the EKF's own worst is 0.9 m on these seeds). The NEES is not tested: FastSLAM with finitely
// many particles grows overconfident as resampling thins the particles' diversity (Bailey,
// Nieto & Nebot 2006); README gives the measured value.
TEST(FastSlam2, PoseErrorStaysCloseToEkfSlamsOnTheSameReadings) {
  LocalizerOptions o = fastslam_options();
  const auto world = dense_world();
  double mean_fastslam = 0.0, mean_ekf = 0.0, worst = 0.0;
  const int runs = 3, steps = 100;
  for (int seed = 0; seed < runs; ++seed) {
    LocalizerContext c;
    c.initial_pose = testing::loop_start();
    c.options = o;
    c.seed = 100 + std::uint64_t(seed);
    c.params = localizer_options("fastslam2", {{"particles", "50"}});
    auto fastslam = make_localizer("fastslam2", c);
    c.params = {};
    auto ekf = make_localizer("ekf-slam", c);
    core::Random rng = core::Random(77).fork(std::uint64_t(seed));
    core::Pose2 truth = testing::loop_start();
    for (int k = 0; k < steps; ++k) {
      const Odometry u = testing::command(k, truth);
      truth = testing::move(truth, u, o, rng);
      const auto readings = testing::read_landmarks(truth, world, o, rng);
      for (auto* l : {fastslam.get(), ekf.get()}) {
        l->predict(u);
        l->update_landmarks(readings);
      }
      const double e = (fastslam->pose().position() - truth.position()).norm();
      mean_fastslam += e / (runs * steps);
      mean_ekf += (ekf->pose().position() - truth.position()).norm() / (runs * steps);
      worst = std::max(worst, e);
    }
  }
  EXPECT_LT(mean_fastslam, 2.0 * mean_ekf) << "ekf-slam " << mean_ekf;
  EXPECT_LT(worst, 1.5);
}

// Without the sensor's ids, each particle associates by Mahalanobis distance and still finds one
// landmark per true landmark.
TEST(FastSlam2, UnknownAssociationsGiveOneLandmarkPerTrueLandmark) {
  LocalizerOptions o = fastslam_options();
  o.known_associations = false;
  LocalizerContext c;
  c.initial_pose = testing::loop_start();
  c.options = o;
  c.seed = 4;
  c.params = localizer_options("fastslam2", {{"particles", "50"}});
  auto slam = make_localizer("fastslam2", c);
  core::Random rng(8);
  testing::simulate(*slam, dense_world(), o, testing::loop_start(), 150, rng);
  const auto world = dense_world();
  std::set<int> matched;
  for (const Landmark& e : slam->landmark_estimates()) {
    int best = 0;
    for (const Landmark& l : world.landmarks) {
      if ((l.position - e.position).norm() < (world.landmarks[std::size_t(best)].position - e.position).norm()) best = l.id;
    }
    EXPECT_LT((world.landmarks[std::size_t(best)].position - e.position).norm(), 1.0);
    matched.insert(best);
  }
  EXPECT_EQ(matched.size(), world.landmarks.size());
  EXPECT_EQ(slam->landmark_estimates().size(), world.landmarks.size());
}

// Moving the filter into another frame moves its pose and map rigidly.
TEST(FastSlam2, ChangeFrameMovesThePoseAndTheMap) {
  const LocalizerOptions o = fastslam_options();
  FastSlam2 filter = make_filter(o, 3);
  core::Random rng(5);
  core::Pose2 truth = testing::loop_start();
  for (int k = 0; k < 20; ++k) {
    const Odometry u = testing::command(k, truth);
    truth = testing::move(truth, u, o, rng);
    filter.predict(u);
    filter.update(testing::read_landmarks(truth, dense_world(), o, rng));
  }
  const core::Transform2 t(4.0, -2.0, 0.7);
  const core::Pose2 before = filter.pose();
  const auto map_before = filter.map(ParticleMap::Combined);
  filter.change_frame(t);
  const core::Pose2 expected = core::Pose2::from_transform(t * before.as_transform());
  EXPECT_NEAR(filter.pose().x, expected.x, 1e-9);
  EXPECT_NEAR(filter.pose().y, expected.y, 1e-9);
  EXPECT_NEAR(core::normalize_angle(filter.pose().theta - expected.theta), 0.0, 1e-9);
  const auto map_after = filter.map(ParticleMap::Combined);
  ASSERT_EQ(map_after.size(), map_before.size());
  for (std::size_t i = 0; i < map_after.size(); ++i) {
    EXPECT_LT((map_after[i].position - t.apply(map_before[i].position)).norm(), 1e-9);
  }
}

}  // namespace
}  // namespace fleetmap::localization
