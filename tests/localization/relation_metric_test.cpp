#include "localization/relation_metric.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace fleetmap::localization {
namespace {

// A path of 20 poses along a square-ish loop, one a second.
std::vector<TimedPose> loop() {
  std::vector<TimedPose> out;
  core::Pose2 p;
  for (int k = 0; k < 20; ++k) {
    out.push_back({double(k), p});
    p = p.compose({0.5, 0.0, k % 5 == 4 ? M_PI / 2 : 0.1});
  }
  return out;
}

std::vector<ReferenceRelation> relations_of(const std::vector<TimedPose>& truth, int gap) {
  std::vector<ReferenceRelation> out;
  for (std::size_t i = 0; i + std::size_t(gap) < truth.size(); ++i) {
    const auto& a = truth[i];
    const auto& b = truth[i + std::size_t(gap)];
    out.push_back({a.time_s, b.time_s, 0.005, 0.005, a.pose.inverse().compose(b.pose)});
  }
  return out;
}

TEST(RelationMetric, TheTrueTrajectoryHasNoErrorWhereverItLies) {
  const auto truth = loop();
  // The same trajectory moved and turned as a whole: relations do not see the frame.
  std::vector<TimedPose> moved = truth;
  const core::Pose2 frame(3.0, -2.0, 1.2);
  for (auto& p : moved) p.pose = frame.compose(p.pose);
  const auto e = relation_errors(moved, relations_of(truth, 3));
  EXPECT_EQ(e.matched, 17u);
  EXPECT_NEAR(e.translation_mean_m, 0.0, 1e-9);
  EXPECT_NEAR(e.rotation_mean_rad, 0.0, 1e-9);
}

TEST(RelationMetric, AKnownErrorIsMeasuredAsIs) {
  const auto truth = loop();
  std::vector<TimedPose> est = truth;
  // Every pose from k = 10 on is 0.2 m farther along its own x and turned 0.05 rad: only the
  // relation from 9 to 10 crosses the jump (gap 1).
  for (std::size_t k = 10; k < est.size(); ++k) est[k].pose = est[k].pose.compose({0.2, 0.0, 0.05});
  const auto e = relation_errors(est, relations_of(truth, 1));
  ASSERT_EQ(e.matched, 19u);
  // One relation of 19 is off by 0.2 m and 0.05 rad; the others after it are not (both ends moved alike
  // in their own frames... the relation from k to k+1 for k >= 10 changes too).
  double t_sum = 0.0, r_sum = 0.0;
  for (std::size_t k = 0; k + 1 < truth.size(); ++k) {
    const core::Pose2 e_est = est[k].pose.inverse().compose(est[k + 1].pose);
    const core::Pose2 e_true = truth[k].pose.inverse().compose(truth[k + 1].pose);
    t_sum += (e_est.position() - e_true.position()).norm();
    r_sum += std::abs(std::remainder(e_est.theta - e_true.theta, 2 * M_PI));
  }
  EXPECT_NEAR(e.translation_mean_m, t_sum / 19.0, 1e-12);
  EXPECT_NEAR(e.rotation_mean_rad, r_sum / 19.0, 1e-12);
  EXPECT_GT(e.translation_mean_m, 0.2 / 19.0 - 1e-12);  // at least the jump's share
}

TEST(RelationMetric, TimesMatchOnlyWithinTheirTolerance) {
  const auto truth = loop();
  std::vector<ReferenceRelation> r = relations_of(truth, 2);
  r[0].t1 += 0.004;  // within 0.005 of scan 0
  r[1].t2 += 0.2;    // no scan there
  const auto e = relation_errors(truth, r);
  EXPECT_TRUE(e.matched_each[0]);
  EXPECT_FALSE(e.matched_each[1]);
  EXPECT_EQ(e.matched, r.size() - 1);
}

}  // namespace
}  // namespace fleetmap::localization
