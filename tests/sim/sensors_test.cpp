#include "sim/sensors.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "tests/sim/sim_test_maps.h"

namespace fleetmap::sim {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(RangeSensor, ZeroNoiseReadsExactDistances) {
  // Room 40 x 30 cells: free space x in [0.1, 3.9], y in [0.1, 2.9].
  const World world(testing::walled_room(40, 30), {});
  core::Random rng(1);
  RangeSensorOptions o;
  o.angles_rad = {0.0, kPi / 2, kPi, -kPi / 2, kPi / 4};  // five distance sensors (D'Alfonso et al.)
  o.max_range_m = 10.0;
  o.noise_m = 0.0;
  const core::Pose2 pose(1.0, 1.2, 0.0);
  const auto scan = read_ranges(world, pose, o, rng);
  ASSERT_EQ(scan.ranges.size(), 5u);
  EXPECT_NEAR(*scan.ranges[0], 3.9 - 1.0, 1e-9);
  EXPECT_NEAR(*scan.ranges[1], 2.9 - 1.2, 1e-9);
  EXPECT_NEAR(*scan.ranges[2], 1.0 - 0.1, 1e-9);
  EXPECT_NEAR(*scan.ranges[3], 1.2 - 0.1, 1e-9);
  EXPECT_NEAR(*scan.ranges[4], (2.9 - 1.2) * std::sqrt(2.0), 1e-9);  // hits the top wall first
  // Turned by 90 degrees, beam 0 looks up.
  const auto turned = read_ranges(world, core::Pose2(1.0, 1.2, kPi / 2), o, rng);
  EXPECT_NEAR(*turned.ranges[0], 2.9 - 1.2, 1e-9);
}

TEST(RangeSensor, MaxRangeAndNoiseSpread) {
  const World world(testing::walled_room(100, 20), {});
  core::Random rng(2);
  RangeSensorOptions o;
  o.angles_rad = {0.0};
  o.max_range_m = 2.0;
  o.noise_m = 0.02;
  EXPECT_FALSE(read_ranges(world, core::Pose2(1.0, 1.0, 0.0), o, rng).ranges[0].has_value());  // wall at 8.9 m
  o.max_range_m = 20.0;
  double sum = 0, sum2 = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const double r = *read_ranges(world, core::Pose2(1.0, 1.0, 0.0), o, rng).ranges[0];
    sum += r;
    sum2 += r * r;
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 8.9, 5 * 0.02 / std::sqrt(double(n)));
  EXPECT_NEAR(sd, 0.02, 0.002);
}

TEST(RangeSensor, LaserHasEvenlySpacedBeams) {
  RangeSensorOptions o;
  o.beams = 8;
  const auto a = beam_angles(o);
  ASSERT_EQ(a.size(), 8u);
  EXPECT_NEAR(a[2], kPi / 2, 1e-12);
}

TEST(LandmarkSensor, RangeBearingWithinRangeAndSight) {
  auto grid = testing::walled_room(60, 30);
  for (int y = 0; y < 20; ++y) grid.set_state({30, y}, mapping::CellState::Occupied);  // a wall at x = 3.0 m
  const World world(grid, {{2.0, 1.0}, {4.0, 1.0}, {1.0, 2.5}, {5.5, 2.5}});
  core::Random rng(3);
  LandmarkSensorOptions o;
  o.max_range_m = 3.0;
  o.range_noise_m = 0.0;
  o.bearing_noise_rad = 0.0;
  const auto obs = read_landmarks(world, core::Pose2(1.0, 1.0, kPi / 2), o, rng);
  // Landmark 0: 1 m ahead on the right (bearing -90 deg); 1: behind the wall; 2: 1.5 m straight ahead;
  // 3: out of range.
  ASSERT_EQ(obs.size(), 2u);
  EXPECT_EQ(obs[0].id, 0);
  EXPECT_NEAR(obs[0].range, 1.0, 1e-12);
  EXPECT_NEAR(obs[0].bearing, -kPi / 2, 1e-12);
  EXPECT_EQ(obs[1].id, 2);
  EXPECT_NEAR(obs[1].range, 1.5, 1e-12);
  EXPECT_NEAR(obs[1].bearing, 0.0, 1e-12);
  o.report_ids = false;
  EXPECT_EQ(read_landmarks(world, core::Pose2(1.0, 1.0, kPi / 2), o, rng)[0].id, -1);
}

TEST(RobotDetector, FieldOfViewRangeAndSight) {
  auto grid = testing::walled_room(80, 40);
  for (int y = 0; y < 30; ++y) grid.set_state({50, y}, mapping::CellState::Occupied);
  const World world(grid, {});
  core::Random rng(4);
  RobotDetectorOptions o;
  o.max_range_m = 3.0;
  o.fov_rad = kPi / 2;  // +-45 degrees
  o.range_noise_m = 0.0;
  o.bearing_noise_rad = 0.0;
  const std::vector<core::Pose2> robots = {{1.0, 1.0, 0.0},   // looks east
                                           {3.0, 1.0, 0.0},   // 2 m ahead: seen
                                           {1.0, 2.5, 0.0},   // 90 deg to the left: outside the view
                                           {6.0, 1.0, 0.0},   // behind the wall and too far
                                           {3.5, 2.2, 0.0}};  // 2.77 m at 25.6 deg: seen
  const auto d = detect_robots(world, 0, robots, o, rng);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].other, 1);
  EXPECT_NEAR(d[0].range, 2.0, 1e-12);
  EXPECT_NEAR(d[0].bearing, 0.0, 1e-12);
  EXPECT_EQ(d[1].other, 4);
  EXPECT_NEAR(d[1].bearing, std::atan2(1.2, 2.5), 1e-12);
}

}  // namespace
}  // namespace fleetmap::sim
