// The registry (localization/localizer_registry.cpp) and one harness run over every localizer.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "core/error.h"
#include "localization/localizer.h"
#include "localization/metrics.h"
#include "tests/localization/localization_sim.h"

namespace fleetmap::localization {
namespace {

TEST(LocalizerRegistry, ListsTheLocalizersInHelpOrder) {
  const std::vector<std::string> names = localizer_names();
  EXPECT_EQ(names, (std::vector<std::string>{"ideal", "odometry", "ekf", "ekf-slam", "polynomial", "scan-matching", "mcl", "rbpf", "fastslam-grid", "graph-slam", "fastslam2"}));
  const std::string help = localizer_help();
  for (const auto& n : names) EXPECT_NE(help.find("  " + n + ": "), std::string::npos) << n;
}

TEST(LocalizerRegistry, AnUnknownNameIsAnInputErrorListingTheValidNames) {
  try {
    make_localizer("kalman", LocalizerContext{});
    FAIL() << "no exception";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("'kalman'"), std::string::npos) << message;
    for (const auto& n : localizer_names()) EXPECT_NE(message.find(n), std::string::npos) << message;
  }
}

// A 120 m square of free space centred on the loop, for the localizers that need a known map.
std::shared_ptr<const mapping::OccupancyGrid> open_known_map() {
  auto g = std::make_shared<mapping::OccupancyGrid>(core::GridGeometry(1.0, 120, 120, core::Pose2(-60.0, -60.0, 0.0)));
  for (int y = 0; y < 120; ++y)
    for (int x = 0; x < 120; ++x) g->set_state({x, y}, mapping::CellState::Free);
  return g;
}

class EveryLocalizer : public ::testing::TestWithParam<std::string> {};

// Every localizer, on a short noisy run with known landmarks and a robot detection each step,
// keeps a finite pose within a metre of the truth (odometry's drift after 80 steps has a standard
// deviation of about 0.15 m) and a finite symmetric covariance.
TEST_P(EveryLocalizer, FollowsTheRobotWithAFinitePoseAndCovariance) {
  const auto world = testing::ring_world();
  LocalizerOptions o;
  o.process_noise_xy = 0.01;
  o.process_noise_theta = 0.0003;
  o.range_noise = 0.05;
  o.bearing_noise = 0.01;
  o.use_robot_detections = true;
  LocalizerContext c;
  c.initial_pose = testing::loop_start();
  c.known_landmarks = world.landmarks;
  c.options = o;
  c.seed = 5;
  c.known_map = open_known_map();  // for `mcl`: free space around the loop
  auto localizer = make_localizer(GetParam(), c);
  EXPECT_EQ(localizer->name(), GetParam());

  core::Random rng(17);
  core::Pose2 truth = testing::loop_start();
  for (int k = 0; k < 80; ++k) {
    const Odometry u = testing::command(k, truth);
    truth = testing::move(truth, u, o, rng);
    localizer->predict(u);
    localizer->update_landmarks(testing::read_landmarks(truth, world, o, rng));
    // Another robot 3 m ahead, whose own estimate is good to 5 cm.
    const core::Pose2 other = truth.compose({3.0, 0.0, 0.0});
    RobotObservation d;
    d.other = 1;
    d.range = 3.0 + rng.normal(0.0, o.range_noise);
    d.bearing = rng.normal(0.0, o.bearing_noise);
    d.other_pose = {other.x + rng.normal(0.0, 0.05), other.y + rng.normal(0.0, 0.05), other.theta};
    d.other_covariance = Eigen::Matrix3d::Identity() * 0.05 * 0.05;
    localizer->update_robot(d);
    localizer->observe_truth(truth);

    const core::Pose2 p = localizer->pose();
    ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.theta)) << "step " << k;
    const Eigen::Matrix3d cov = localizer->covariance();
    ASSERT_TRUE(cov.allFinite()) << "step " << k;
    ASSERT_TRUE(cov.isApprox(cov.transpose(), 1e-12) || cov.isZero()) << "step " << k;
    ASSERT_LT(pose_error(truth, p).head<2>().norm(), 1.0) << "step " << k;
  }
  for (const auto& [name, value] : localizer->counters()) EXPECT_TRUE(std::isfinite(value)) << name;
  for (const Landmark& l : localizer->landmark_estimates()) EXPECT_TRUE(l.position.allFinite());
}

INSTANTIATE_TEST_SUITE_P(Registry, EveryLocalizer, ::testing::ValuesIn(localizer_names()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string s = info.param;
                           std::replace(s.begin(), s.end(), '-', '_');
                           return s;
                         });

}  // namespace
}  // namespace fleetmap::localization
