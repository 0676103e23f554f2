// `mcl` (localization/mcl_localizer.cpp): global localization in a room without symmetry, and
// the collaborative form (León et al., eq. (15)).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numeric>

#include "core/angle.h"
#include "core/error.h"
#include "localization/localizer.h"
#include "mapping/ray_cast.h"
#include "tests/localization/grid_slam_sim.h"

namespace fleetmap::localization {
namespace {

using testing::asymmetric_room;
using testing::scan_at;

constexpr double kMotionNoiseXy = 0.005, kMotionNoiseTheta = 0.003;  // per step, in the truth and the model
constexpr double kMclRangeNoise = 0.02;

// Drives straight at 0.3 m/s, and turns in place while a wall is within 1 m ahead.
Odometry wander(const mapping::OccupancyGrid& room, const core::Pose2& truth) {
  if (mapping::cast_ray(room, truth.position(), truth.theta, 1.0)) return {0.0, 0.6, 1.0};
  return {0.3, 0.0, 1.0};
}

core::Pose2 move(const core::Pose2& truth, const Odometry& u, core::Random& rng) {
  const core::Pose2 n = integrate_motion(truth, u);
  return {n.x + rng.normal(0.0, kMotionNoiseXy), n.y + rng.normal(0.0, kMotionNoiseXy),
          core::normalize_angle(n.theta + rng.normal(0.0, kMotionNoiseTheta))};
}

LocalizerContext context(const std::shared_ptr<const mapping::OccupancyGrid>& map, const core::Pose2& start, bool lost,
                         std::uint64_t seed, int particles) {
  LocalizerContext c;
  c.initial_pose = start;
  c.known_map = map;
  c.global_localization = lost;
  c.seed = seed;
  c.options.process_noise_xy = kMotionNoiseXy;
  c.options.process_noise_theta = kMotionNoiseTheta;
  c.options.range_noise = kMclRangeNoise;
  c.options.initial_xy = 0.05;
  c.params = localizer_options("mcl", {{"particles", std::to_string(particles)}});
  return c;
}

// Localized: within 0.25 m and 10 degrees of the truth (several times the particle cloud's spread
// from the motion noise floor of 0.01 m + 5% per step).
bool localized(const Localizer& l, const core::Pose2& truth) {
  return (l.pose().position() - truth.position()).norm() < 0.25 &&
         std::abs(core::normalize_angle(l.pose().theta - truth.theta)) < core::deg2rad(10.0);
}

TEST(MclLocalizer, NeedsAKnownMap) {
  LocalizerContext c;
  EXPECT_THROW(make_localizer("mcl", c), InputError);
}

TEST(MclLocalizer, ConvergesFromAUniformBeliefInANonSymmetricRoom) {
  const auto room = std::make_shared<const mapping::OccupancyGrid>(asymmetric_room());
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    core::Random rng(seed);
    core::Pose2 truth(2.0 + seed, 1.2 + 0.5 * seed, 0.7 * seed);
    auto mcl = make_localizer("mcl", context(room, {}, true, seed, 3000));
    // A uniform belief: the first estimate is nowhere near the truth, and the spread is room-sized.
    EXPECT_GT(mcl->covariance()(0, 0), 1.0);
    int first_localized = -1;
    for (int k = 0; k < 40; ++k) {
      const Odometry u = wander(*room, truth);
      truth = move(truth, u, rng);
      mcl->predict(u);
      mcl->update_scan(scan_at(*room, truth, kMclRangeNoise, rng, 90, 8.0), *room);
      if (localized(*mcl, truth)) {
        if (first_localized < 0) first_localized = k;
      } else {
        first_localized = -1;  // must stay localized to the end
      }
    }
    EXPECT_GE(first_localized, 0) << "seed " << seed << ": ends at " << mcl->pose() << ", truth " << truth;
    EXPECT_LT((mcl->covariance().topLeftCorner<2, 2>().trace()), 0.1 * 0.1) << "seed " << seed;
  }
}

struct LostRun {
  int steps_to_localize = -1;  // -1: not within the limit
};

// Robot 2 knows its start; robot 1 is lost (uniform belief). With `collaborate`, every detection of
// robot 1 by robot 2 (range within 5 m, line of sight) updates robot 1's belief.
LostRun lost_robot_run(std::uint64_t seed, bool collaborate) {
  const auto room = std::make_shared<const mapping::OccupancyGrid>(asymmetric_room());
  core::Random rng(seed * 7919);
  core::Pose2 lost_truth(1.0 + 0.4 * double(seed % 4), 1.0 + 0.3 * double(seed % 3), 0.9 * double(seed));
  core::Pose2 guide_truth(lost_truth.x + 2.5, lost_truth.y + 1.5, -1.0);
  auto lost = make_localizer("mcl", context(room, {}, true, seed, 1500));
  auto guide = make_localizer("mcl", context(room, guide_truth, false, seed + 100, 300));
  constexpr int kLimit = 60;
  constexpr double kMaxRange = 2.0;  // a short laser: alone, the lost robot sees little of the room
  int streak_start = -1;
  for (int k = 0; k < kLimit; ++k) {
    const Odometry a = wander(*room, lost_truth), b = wander(*room, guide_truth);
    lost_truth = move(lost_truth, a, rng);
    guide_truth = move(guide_truth, b, rng);
    lost->predict(a);
    guide->predict(b);
    lost->update_scan(scan_at(*room, lost_truth, kMclRangeNoise, rng, 60, kMaxRange), *room);
    guide->update_scan(scan_at(*room, guide_truth, kMclRangeNoise, rng, 60, kMaxRange), *room);
    const Eigen::Vector2d d = lost_truth.position() - guide_truth.position();
    if (collaborate && d.norm() < 5.0 && mapping::line_of_sight(*room, guide_truth.position(), lost_truth.position())) {
      DetectedBy det;
      det.detector = 1;
      det.range = d.norm() + rng.normal(0.0, 0.02);
      det.bearing = core::normalize_angle(std::atan2(d.y(), d.x()) - guide_truth.theta + rng.normal(0.0, 0.01));
      det.range_noise = 0.02;
      det.bearing_noise = 0.01;
      det.detector_pose = guide->pose();
      det.detector_covariance = guide->covariance();
      lost->update_detected_by(det);
    }
    if (localized(*lost, lost_truth)) {
      if (streak_start < 0) streak_start = k;
    } else {
      streak_start = -1;
    }
  }
  return {streak_start < 0 ? -1 : streak_start + 1};
}

// Over seeded runs, a lost robot detected by one that knows where it is localizes in fewer steps
// than the same robot alone (same seeds, same paths, same sensors). A run that never localizes
// counts as the limit plus one.
TEST(MclLocalizer, CollaborationLocalizesTheLostRobotFasterThanAlone) {
  double alone_total = 0, together_total = 0;
  int together_failures = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const LostRun alone = lost_robot_run(seed, false), together = lost_robot_run(seed, true);
    alone_total += alone.steps_to_localize < 0 ? 61 : alone.steps_to_localize;
    together_total += together.steps_to_localize < 0 ? 61 : together.steps_to_localize;
    together_failures += together.steps_to_localize < 0;
    RecordProperty("seed" + std::to_string(seed), std::to_string(alone.steps_to_localize) + " alone, " +
                                                      std::to_string(together.steps_to_localize) + " together");
  }
  EXPECT_EQ(together_failures, 0);
  EXPECT_LT(together_total, 0.5 * alone_total) << "alone " << alone_total / 6 << " steps, together " << together_total / 6;
}

}  // namespace
}  // namespace fleetmap::localization
