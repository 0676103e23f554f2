// `rbpf` and `fastslam-grid` (localization/rbpf_localizer.cpp) and their copy-on-write maps
// (localization/cow_grid.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <unordered_set>

#include "core/angle.h"
#include "mapping/range_scan.h"
#include "localization/cow_grid.h"
#include "localization/localizer.h"
#include "localization/rbpf_localizer.h"
#include "tests/localization/grid_slam_sim.h"

namespace fleetmap::localization {
namespace {

using testing::asymmetric_room;
using testing::scan_at;

TEST(CowGrid, CopiesShareTilesUntilTheFirstWrite) {
  CowGrid a(core::GridGeometry(0.05, 200, 200));
  a.integrate_ray({1.0, 1.0}, {9.0, 1.0}, true);  // one row of cells across 6 tiles
  EXPECT_EQ(a.tiles_allocated(), 6);
  CowGrid b = a;
  std::unordered_set<const CowGrid::Tile*> tiles;
  a.collect_tiles(tiles);
  b.collect_tiles(tiles);
  EXPECT_EQ(tiles.size(), 6u);  // shared
  const float before = a.log_odds(20, 20);
  b.integrate_ray({1.0, 1.0}, {1.2, 1.0}, true);  // writes inside the first tile only
  tiles.clear();
  a.collect_tiles(tiles);
  b.collect_tiles(tiles);
  EXPECT_EQ(tiles.size(), 7u);  // b now has its own copy of that one tile
  EXPECT_EQ(a.log_odds(20, 20), before);
  EXPECT_NE(b.log_odds(23, 20), a.log_odds(23, 20));
}

TEST(CowGrid, HoldsTheSameNumbersAsAnOccupancyGrid) {
  const auto room = asymmetric_room();
  core::Random rng(2);
  mapping::OccupancyGrid dense(room.geometry());
  CowGrid cow(room.geometry());
  for (const core::Pose2 p : {core::Pose2(2, 2, 0), core::Pose2(6, 3, 1), core::Pose2(8.5, 1.5, 2)}) {
    const auto scan = scan_at(room, p, 0.02, rng);
    mapping::insert_scan(dense, p, scan);
    for (std::size_t b = 0; b < scan.angles.size(); ++b) {
      const double r = scan.ranges[b].value_or(scan.max_range);
      cow.integrate_ray(p.position(), p.position() + r * Eigen::Vector2d(std::cos(p.theta + scan.angles[b]), std::sin(p.theta + scan.angles[b])),
                        scan.ranges[b].has_value());
    }
  }
  EXPECT_EQ(cow.to_occupancy_grid().log_odds_data(), dense.log_odds_data());
}

// With one particle and no noise drawn in its motion, the particle filter does what the scan
// matcher does: the same odometry step, the same match against the same map. Poses must agree to
// rounding, and the particle's map must hold the scan matcher's map cell for cell.
TEST(RbpfLocalizer, WithOneParticleAndNoNoiseEqualsTheScanMatcher) {
  const auto room = asymmetric_room();
  core::Random rng(11);
  LocalizerContext c;
  c.initial_pose = {1.5, 1.5, 0.2};
  c.options.process_noise_xy = 0.01;  // the model's odometry noise: the matcher's prior
  c.options.process_noise_theta = 0.005;
  c.options.range_noise = 0.01;
  auto sm = make_localizer("scan-matching", c);
  // Every scan matched, as the scan matcher does.
  c.params = localizer_options("rbpf", {{"particles", "1"}, {"sample_motion", "false"}, {"linear_update", "0"}});
  auto pf = make_localizer("rbpf", c);
  mapping::OccupancyGrid own(room.geometry());
  core::Pose2 truth = c.initial_pose;
  int moved_by_matching = 0;
  for (int k = 0; k < 25; ++k) {
    if (k > 0) {
      const Odometry driven{0.15, k % 10 < 5 ? 0.0 : 0.1, 1.0};
      truth = integrate_motion(truth, driven);
      const Odometry reported{0.14, driven.omega + 0.004, 1.0};  // biased: the matcher has work to do
      sm->predict(reported);
      pf->predict(reported);
    }
    const auto scan = scan_at(room, truth, 0.01, rng);
    const core::Pose2 guess = sm->pose();
    sm->update_scan(scan, own);
    pf->update_scan(scan, own);
    moved_by_matching += (sm->pose().position() - guess.position()).norm() > 1e-3;
    ASSERT_NEAR(pf->pose().x, sm->pose().x, 1e-9) << "step " << k;
    ASSERT_NEAR(pf->pose().y, sm->pose().y, 1e-9) << "step " << k;
    ASSERT_NEAR(pf->pose().theta, sm->pose().theta, 1e-9) << "step " << k;
    mapping::insert_scan(own, sm->pose(), scan);
  }
  EXPECT_GT(moved_by_matching, 10);  // the comparison is not between two dead reckonings
  const auto pf_map = pf->map_estimate();
  ASSERT_TRUE(pf_map);
  const auto sm_map = sm->map_estimate();
  ASSERT_TRUE(sm_map);
  EXPECT_EQ(pf_map->log_odds_data(), sm_map->log_odds_data());
  EXPECT_EQ(pf_map->log_odds_data(), own.log_odds_data());  // and the robot's own grid
}

// 30 particles with maps of 1000 x 1000 cells: dense copies would take 30 x 4 MB; resampled
// particles share every tile they have not written since, so the filter holds a small multiple of
// one map's observed part.
TEST(RbpfLocalizer, ParticleMapsShareMemoryCopyOnWrite) {
  const auto room = asymmetric_room();
  const core::GridGeometry big(0.05, 1000, 1000);  // 50 m x 50 m, the room in its lower-left corner
  mapping::OccupancyGrid own(big);
  core::Random rng(5);
  LocalizerContext c;
  c.initial_pose = {2.0, 2.0, 0.0};
  c.options.process_noise_xy = 0.01;
  c.options.process_noise_theta = 0.005;
  c.params = localizer_options("rbpf", {{"particles", "30"}, {"linear_update", "0"}});  // 12 scans, all processed
  c.seed = 9;
  RbpfLocalizer pf(c);
  core::Pose2 truth = c.initial_pose;
  for (int k = 0; k < 12; ++k) {
    if (k > 0) {
      const Odometry u{0.2, 0.05, 1.0};
      truth = integrate_motion(truth, u);
      pf.predict(u);
    }
    const auto scan = scan_at(room, truth, 0.01, rng);
    pf.update_scan(scan, own);
    mapping::insert_scan(own, pf.pose(), scan);
  }
  const auto m = pf.memory();
  EXPECT_EQ(m.unshared_bytes, std::size_t(30) * 1000 * 1000 * CowGrid::tile_bytes() / (32 * 32));
  int tiles_if_unshared = 0;
  for (const auto& p : pf.particles()) tiles_if_unshared += p.map.tiles_allocated();
  EXPECT_GT(pf.resamplings(), 0);
  EXPECT_LT(m.distinct_tiles, tiles_if_unshared);  // some tiles are shared
  // Between resamplings each particle copies only the tiles its scans write to: the filter holds
  // one map plus, per particle, at most the tiles one scan touches (dense copies: 420 MB).
  CowGrid one_scan(big);
  for (std::size_t b = 0; b < 360; ++b) {
    const double a = 2.0 * M_PI * double(b) / 360.0;
    one_scan.integrate_ray(truth.position(), truth.position() + 8.0 * Eigen::Vector2d(std::cos(a), std::sin(a)), false);
  }
  const std::size_t bound = 30 * one_scan.table_bytes() +
                            std::size_t(30 * one_scan.tiles_allocated() + pf.particles()[0].map.tiles_allocated()) *
                                CowGrid::tile_bytes();
  EXPECT_LE(m.shared_bytes, bound);
  EXPECT_LT(m.shared_bytes, m.unshared_bytes / 20);
  RecordProperty("shared_bytes", std::to_string(m.shared_bytes));
}

// An rbpf in the asymmetric room at (1.5, 1.5), with small process and range noise.
LocalizerContext room_context(const core::Settings& params, std::uint64_t seed) {
  LocalizerContext c;
  c.initial_pose = {1.5, 1.5, 0.0};
  c.options.process_noise_xy = 0.01;
  c.options.process_noise_theta = 0.005;
  c.options.range_noise = 0.01;
  c.params = localizer_options("rbpf", params);
  c.seed = seed;
  return c;
}

// On biased odometry (5% short, a small turn bias), the filter keeps its best particle near the
// truth like the scan matcher does, while dead reckoning drifts.
TEST(RbpfLocalizer, CorrectsBiasedOdometry) {
  const auto room = asymmetric_room();
  core::Random rng(4);
  const LocalizerContext c = room_context({{"particles", "10"}}, 3);
  auto pf = make_localizer("rbpf", c);
  mapping::OccupancyGrid own(room.geometry());
  core::Pose2 truth = c.initial_pose, odometry = c.initial_pose;
  for (int k = 0; k < 30; ++k) {
    if (k > 0) {
      const Odometry driven{0.1, k < 15 ? 0.0 : 0.05, 1.0};
      truth = integrate_motion(truth, driven);
      const Odometry reported{0.095, driven.omega + 0.003, 1.0};
      odometry = integrate_motion(odometry, reported);
      pf->predict(reported);
    }
    const auto scan = scan_at(room, truth, 0.01, rng);
    pf->update_scan(scan, own);
    mapping::insert_scan(own, pf->pose(), scan);
  }
  EXPECT_GT((odometry.position() - truth.position()).norm(), 0.12);
  EXPECT_LT((pf->pose().position() - truth.position()).norm(), 0.04);
}

// GMapping's linearUpdate: a scan is matched and mapped only once the odometry has moved
// linear_update since the last one. In between, the reported pose is the last one moved by the
// odometry, undrawn, and no particle's map changes.
TEST(RbpfLocalizer, MatchesAndMapsAScanOnlyOnceTheRobotMovedEnough) {
  const auto room = asymmetric_room();
  core::Random rng(6);
  const LocalizerContext c = room_context({{"particles", "5"}, {"linear_update", "0.5"}, {"angular_update", "0.25"}}, 8);
  RbpfLocalizer pf(c);
  mapping::OccupancyGrid own(room.geometry());
  core::Pose2 truth = c.initial_pose;
  int processed = 0;
  for (int k = 0; k < 21; ++k) {
    const core::Pose2 before = pf.pose();
    const Odometry reported{0.14, 0.004, 1.0};
    if (k > 0) {
      truth = integrate_motion(truth, {0.15, 0.0, 1.0});
      pf.predict(reported);
    }
    const auto map_before = pf.map_estimate();
    const auto scan = scan_at(room, truth, 0.01, rng);
    // 0.14 m a step: the fourth step since the last processed scan passes 0.5 m (turns stay small).
    const bool due = k % 4 == 0;
    if (!due) {
      const core::Pose2 odometry = integrate_motion(before, reported);
      EXPECT_NEAR(pf.pose().x, odometry.x, 1e-12) << "step " << k;
      EXPECT_NEAR(pf.pose().y, odometry.y, 1e-12) << "step " << k;
      EXPECT_NEAR(pf.pose().theta, odometry.theta, 1e-12) << "step " << k;
    }
    pf.update_scan(scan, own);
    if (!due) {
      ASSERT_TRUE(map_before);
      EXPECT_EQ(pf.map_estimate()->log_odds_data(), map_before->log_odds_data()) << "step " << k;
    } else {
      ++processed;
      if (map_before) {
        EXPECT_NE(pf.map_estimate()->log_odds_data(), map_before->log_odds_data()) << "step " << k;
      }
    }
    mapping::insert_scan(own, pf.pose(), scan);
  }
  double skipped = -1;
  for (const auto& [name, value] : pf.counters())
    if (name == "scans_skipped") skipped = value;
  EXPECT_EQ(processed, 6);
  EXPECT_EQ(skipped, 15);
  EXPECT_LT((pf.pose().position() - truth.position()).norm(), 0.05);  // the processed scans corrected the drift
}

// Grid FastSLAM has no scan-matching proposal: one particle with no process noise is dead
// reckoning, whatever the scans say (the same set-up as above makes the scan matcher move).
TEST(GridFastSlam, WithOneParticleAndNoNoiseIsDeadReckoning) {
  const auto room = asymmetric_room();
  core::Random rng(11);
  LocalizerContext c;
  c.initial_pose = {1.5, 1.5, 0.2};
  c.options.process_noise_xy = 0.0;
  c.options.process_noise_theta = 0.0;
  c.options.range_noise = 0.01;
  auto odo = make_localizer("odometry", c);
  c.params = localizer_options("fastslam-grid", {{"particles", "1"}});
  auto fs = make_localizer("fastslam-grid", c);
  EXPECT_EQ(fs->name(), "fastslam-grid");
  mapping::OccupancyGrid own(room.geometry());
  core::Pose2 truth = c.initial_pose;
  for (int k = 0; k < 25; ++k) {
    if (k > 0) {
      const Odometry driven{0.15, k % 10 < 5 ? 0.0 : 0.1, 1.0};
      truth = integrate_motion(truth, driven);
      const Odometry reported{0.14, driven.omega + 0.004, 1.0};
      fs->predict(reported);
      odo->predict(reported);
    }
    const auto scan = scan_at(room, truth, 0.01, rng);
    fs->update_scan(scan, own);
    ASSERT_NEAR(fs->pose().x, odo->pose().x, 1e-9) << "step " << k;
    ASSERT_NEAR(fs->pose().y, odo->pose().y, 1e-9) << "step " << k;
    ASSERT_NEAR(core::normalize_angle(fs->pose().theta - odo->pose().theta), 0.0, 1e-9) << "step " << k;
  }
  EXPECT_GT((fs->pose().position() - truth.position()).norm(), 0.1);  // the bias was there to correct
}

// Its particles are drawn from the motion model and weighed by their scans on their own maps: with
// enough of them the best one ends nearer the truth than dead reckoning.
TEST(GridFastSlam, WeighsParticlesByTheirScansAndBeatsDeadReckoning) {
  const auto room = asymmetric_room();
  core::Random rng(4);
  LocalizerContext c;
  c.initial_pose = {1.5, 1.5, 0.0};
  c.options.process_noise_xy = 0.01;
  c.options.process_noise_theta = 0.005;
  c.options.range_noise = 0.01;
  c.params = localizer_options("fastslam-grid", {{"particles", "40"}});
  c.seed = 3;
  auto fs = make_localizer("fastslam-grid", c);
  mapping::OccupancyGrid own(room.geometry());
  core::Pose2 truth = c.initial_pose, odometry = c.initial_pose;
  for (int k = 0; k < 30; ++k) {
    if (k > 0) {
      const Odometry driven{0.1, k < 15 ? 0.0 : 0.05, 1.0};
      truth = integrate_motion(truth, driven);
      const Odometry reported{0.095, driven.omega + 0.003, 1.0};
      odometry = integrate_motion(odometry, reported);
      fs->predict(reported);
    }
    fs->update_scan(scan_at(room, truth, 0.01, rng), own);
  }
  double resamplings = 0;
  for (const auto& [name, value] : fs->counters())
    if (name == "resamplings") resamplings = value;
  EXPECT_GT(resamplings, 0);  // the weights told the particles apart
  EXPECT_LT((fs->pose().position() - truth.position()).norm(), 0.5 * (odometry.position() - truth.position()).norm());
}

}  // namespace
}  // namespace fleetmap::localization
