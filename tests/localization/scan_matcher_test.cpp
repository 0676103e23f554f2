// localization/scan_matcher.cpp and the `scan-matching` localizer, on a synthetic room.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "core/angle.h"
#include "mapping/range_scan.h"
#include "localization/likelihood_field.h"
#include "localization/localizer.h"
#include "localization/scan_matcher.h"
#include "tests/localization/grid_slam_sim.h"

namespace fleetmap::localization {
namespace {

using testing::asymmetric_room;
using testing::scan_at;

constexpr double kScanRangeNoise = 0.01;  // m

TEST(LikelihoodField, IsHighestOnWallsAndFallsWithDistance) {
  const auto room = asymmetric_room();
  const auto field = LikelihoodField::of_grid(room, window_around(room.geometry(), {5.0, 3.5}, 20.0));
  const auto& g = room.geometry();
  const double on_wall = field.log_likelihood_bilinear(g.world_to_grid({3.0, 2.5}));
  const double near = field.log_likelihood_bilinear(g.world_to_grid({3.0, 2.95}));
  const double far = field.log_likelihood_bilinear(g.world_to_grid({5.0, 3.5}));
  EXPECT_GT(on_wall, near);
  EXPECT_GT(near, far);
  EXPECT_FLOAT_EQ(far, field.far_log_likelihood());
}

// The correlative search reads the field a row at a time: the same values as cell by cell, the
// window's outside (rows and columns on either side) counting as far from every wall. The table's
// far cells are filled without computing their distance: they must hold what it would give.
TEST(LikelihoodField, RowsReadTheSameCellsAsOneByOne) {
  const auto room = asymmetric_room();
  const auto& g = room.geometry();
  const CellWindow window = window_around(g, {3.0, 2.0}, 1.5);
  const auto field = LikelihoodField::of_grid(room, window);
  int near_wall = 0, far = 0;
  for (int y = window.y0 - 3; y < window.y1 + 3; ++y) {
    std::vector<double> row(std::size_t(window.width() + 10), 1.0);
    field.add_nearest_row(window.x0 - 5, y, int(row.size()), row.data());
    for (int i = 0; i < int(row.size()); ++i) {
      const Eigen::Vector2d centre(window.x0 - 5 + i + 0.5, y + 0.5);
      const double nearest = field.log_likelihood_nearest(centre);
      ASSERT_EQ(row[std::size_t(i)], 1.0 + nearest) << i << " " << y;
      const bool inside = centre.x() > window.x0 && centre.x() < window.x1 && centre.y() > window.y0 && centre.y() < window.y1;
      if (!inside) continue;
      EXPECT_EQ(float(nearest), float(field.log_likelihood(centre))) << i << " " << y;
      (nearest > field.far_log_likelihood() ? near_wall : far)++;
    }
  }
  EXPECT_GT(near_wall, 100);  // both kinds of cells were compared
  EXPECT_GT(far, 100);
}

// The matcher must find a known offset from the guess on a map built the way a robot builds its
// own (scans integrated at known poses). With 180 end points of 0.01 m noise the estimate's own
// spread is a few millimetres; the tolerance is set by the 0.05 m cells: beams end on a wall's face
// while the map puts the wall at its cell's centre, half a cell (0.025 m) inside, and the nearer
// walls (more end points) pull the match by up to that much. Tolerance: 0.6 cell.
TEST(ScanMatcher, RecoversAKnownSmallPoseOffsetOnASyntheticRoom) {
  const auto room = asymmetric_room();
  mapping::OccupancyGrid map(room.geometry());
  core::Random map_rng(70);
  for (const core::Pose2 p : {core::Pose2(1.0, 1.0, 0.0), core::Pose2(5.0, 1.0, 1.0), core::Pose2(8.5, 1.0, 2.0),
                              core::Pose2(5.0, 5.5, 3.0), core::Pose2(1.0, 6.0, -1.0), core::Pose2(5.0, 3.5, 0.5)}) {
    mapping::insert_scan(map, p, scan_at(room, p, kScanRangeNoise, map_rng));
  }
  const auto field = LikelihoodField::of_grid(map, window_around(room.geometry(), {5.0, 3.5}, 20.0));
  core::Random rng(7);
  int checked = 0;
  for (const core::Pose2 truth : {core::Pose2(2.0, 1.5, 0.3), core::Pose2(5.5, 4.0, -2.0), core::Pose2(8.0, 2.0, 1.2)}) {
    for (const core::Pose2 offset : {core::Pose2(0.15, -0.10, 0.05), core::Pose2(-0.2, 0.12, -0.08)}) {
      const auto scan = scan_at(room, truth, kScanRangeNoise, rng);
      const core::Pose2 guess(truth.x + offset.x, truth.y + offset.y, truth.theta + offset.theta);
      ScanMatcherOptions o;
      o.field.max_range_m = scan.max_range;
      o.prior_xy_m = 0.0;  // no prior: the guess is deliberately off
      o.prior_theta_rad = 0.0;
      const ScanMatch m = match_scan(field, scan_end_points(scan, o.beam_stride), guess, o);
      ASSERT_TRUE(m.matched);
      EXPECT_LT((m.pose.position() - truth.position()).norm(), 0.6 * room.resolution()) << truth << " from " << guess << " got " << m.pose;
      EXPECT_LT(std::abs(core::normalize_angle(m.pose.theta - truth.theta)), core::deg2rad(0.5)) << m.pose;
      // The match covariance is positive definite and well inside the search window's (a uniform
      // spread over +-0.3 m has a variance of 0.03 m^2).
      EXPECT_GT(m.covariance.determinant(), 0.0);
      EXPECT_LT(m.covariance(0, 0), 0.25 * o.search_xy_m * o.search_xy_m / 3.0);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 6);
}

TEST(ScanMatcher, DoesNotMatchWithoutMapOrPoints) {
  const auto room = asymmetric_room();
  const mapping::OccupancyGrid empty(room.geometry());
  const auto field = LikelihoodField::of_grid(empty, window_around(room.geometry(), {5.0, 3.5}, 20.0));
  core::Random rng(1);
  const auto scan = scan_at(room, {5.0, 3.0, 0.0}, kScanRangeNoise, rng);
  const ScanMatch m = match_scan(field, scan_end_points(scan, 2), {5.1, 3.0, 0.0}, {});
  EXPECT_FALSE(m.matched);
  EXPECT_EQ(m.pose, core::Pose2(5.1, 3.0, 0.0));
}

// The localizer against dead reckoning: the robot drives with a biased odometry (it reports 5%
// less than it drives, and a small turn); scan matching on the robot's own map must keep the
// error within a map cell (0.05 m), while odometry drifts by the bias (5% of 3 m = 0.15 m).
TEST(ScanMatchingLocalizer, CorrectsBiasedOdometryOnItsOwnMap) {
  const auto room = asymmetric_room();
  core::Random rng(3);
  LocalizerContext c;
  c.initial_pose = {1.5, 1.5, 0.0};
  c.options.range_noise = kScanRangeNoise;
  c.options.process_noise_xy = 0.01;  // the odometry's error per step, as the model knows it
  c.options.process_noise_theta = 0.005;
  auto sm = make_localizer("scan-matching", c);
  auto odo = make_localizer("odometry", c);
  mapping::OccupancyGrid own(room.geometry());
  core::Pose2 truth = c.initial_pose;
  const auto first = scan_at(room, truth, kScanRangeNoise, rng);
  sm->update_scan(first, own);
  mapping::insert_scan(own, sm->pose(), first);
  for (int k = 0; k < 30; ++k) {
    const Odometry driven{0.1, k < 15 ? 0.0 : 0.05, 1.0};
    truth = integrate_motion(truth, driven);
    const Odometry reported{0.095, driven.omega + 0.003, 1.0};
    sm->predict(reported);
    odo->predict(reported);
    const auto scan = scan_at(room, truth, kScanRangeNoise, rng);
    sm->update_scan(scan, own);
    mapping::insert_scan(own, sm->pose(), scan);
  }
  const double sm_error = (sm->pose().position() - truth.position()).norm();
  const double odo_error = (odo->pose().position() - truth.position()).norm();
  EXPECT_GT(odo_error, 0.12);
  EXPECT_LT(sm_error, room.resolution());
  EXPECT_LT(std::abs(core::normalize_angle(sm->pose().theta - truth.theta)), core::deg2rad(1.0));
  double matches = 0;
  for (const auto& [k, v] : sm->counters()) if (k == "scan_matches") matches = v;
  EXPECT_EQ(matches, 30);
}

}  // namespace
}  // namespace fleetmap::localization
