// The map aligners by name: the built-in four, an unknown name refused naming them, the rendezvous
// transform from a mutual detection, and the landmark aligner recovering a known transform between
// two noisy landmark maps, refusing maps too small or unrelated.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/angle.h"
#include "core/random.h"
#include "merging/map_aligner.h"
#include "tests/test_support.h"

namespace fleetmap::merging {
namespace {

TEST(MapAligners, TheBuiltInOnesAreRegisteredAndAnUnknownNameIsRefused) {
  const auto names = map_aligner_registry().names();
  for (const char* name : {"known", "rendezvous", "overlap", "landmarks"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  }
  EXPECT_TRUE(make_map_aligner("known")->shared_frame());
  EXPECT_FALSE(make_map_aligner("overlap")->shared_frame());
  fleetmap::testing::expect_input_error([] { make_map_aligner("telepathy"); },
                                        {"unknown merging 'telepathy'", "known", "rendezvous", "overlap", "landmarks"});
}

// Two robots 2 m apart facing each other, their frames turned by 30 degrees: the rendezvous aligner
// gives the sender's frame in the receiver's; without a detection it does not try.
TEST(MapAligners, RendezvousNeedsAMutualDetection) {
  const auto aligner = make_map_aligner("rendezvous");
  const core::Transform2 truth(Eigen::Vector2d(1.0, -0.5), core::deg2rad(30.0));  // sender frame -> receiver frame
  AlignmentRequest q;
  q.receiver_pose = core::Pose2(0.0, 0.0, 0.0);
  const core::Pose2 sender_in_receiver(2.0, 0.0, M_PI);
  q.sender_pose = core::Pose2::from_transform(truth.inverse() * sender_in_receiver.as_transform());
  EXPECT_FALSE(aligner->align(q).attempted);
  q.detection = MutualObservation{2.0, 0.0, 2.0, 0.0};
  const FrameAlignment a = aligner->align(q);
  ASSERT_TRUE(a.merged);
  EXPECT_NEAR(core::normalize_angle(a.sender_to_receiver.rotation() - truth.rotation()), 0.0, 1e-9);
  EXPECT_LT((a.sender_to_receiver.translation() - truth.translation()).norm(), 1e-9);
  EXPECT_GT(a.bytes_sent, 0);
}

std::vector<localization::Landmark> scattered(int n, core::Random& rng) {
  std::vector<localization::Landmark> out;
  for (int i = 0; i < n; ++i) {
    out.push_back({i, Eigen::Vector2d(rng.uniform(0.0, 20.0), rng.uniform(0.0, 15.0)), Eigen::Matrix2d::Identity() * 0.01});
  }
  return out;
}

// The sender saw 12 of the receiver's 20 landmarks (0.05 m noise) in a frame turned by 70 degrees.
TEST(MapAligners, LandmarksRecoverTheTransformBetweenTwoLandmarkMaps) {
  core::Random rng(7);
  const auto receiver = scattered(20, rng);
  const core::Transform2 truth(Eigen::Vector2d(-3.0, 4.0), core::deg2rad(70.0));  // sender frame -> receiver frame
  std::vector<localization::Landmark> sender;
  for (int i = 5; i < 17; ++i) {
    auto l = receiver[std::size_t(i)];
    l.position = truth.inverse().apply(l.position) + Eigen::Vector2d(rng.normal(0.0, 0.05), rng.normal(0.0, 0.05));
    sender.push_back(l);
  }
  AlignmentRequest q;
  q.receiver_landmarks = receiver;
  q.sender_landmarks = sender;
  const FrameAlignment a = make_map_aligner("landmarks")->align(q);
  ASSERT_TRUE(a.merged) << a.reason;
  EXPECT_GE(a.confidence, 0.9);
  // Noise of 0.05 m over landmarks metres apart: well under a degree and 0.1 m.
  EXPECT_LT(std::abs(core::rad2deg(core::normalize_angle(a.sender_to_receiver.rotation() - truth.rotation()))), 1.0);
  EXPECT_LT((a.sender_to_receiver.translation() - truth.translation()).norm(), 0.1);
  // Its declared support distance reaches it: a landmark 0.05 m off supports nothing within 1 mm.
  EXPECT_FALSE(make_map_aligner("landmarks", {{"support_distance", "0.001"}})->align(q).merged);
}

TEST(MapAligners, LandmarksRefuseTooFewOrUnrelatedLandmarks) {
  core::Random rng(11);
  const auto aligner = make_map_aligner("landmarks");
  AlignmentRequest q;
  q.receiver_landmarks = scattered(20, rng);
  q.sender_landmarks = scattered(2, rng);
  EXPECT_FALSE(aligner->align(q).attempted);  // nothing to associate yet
  q.sender_landmarks = scattered(15, rng);    // another place altogether
  const FrameAlignment a = aligner->align(q);
  EXPECT_TRUE(a.attempted);
  EXPECT_FALSE(a.merged);
  EXPECT_FALSE(a.reason.empty());
}

}  // namespace
}  // namespace fleetmap::merging
