#include "merging/landmark_alignment.h"

#include <gtest/gtest.h>

#include <numbers>

#include "core/angle.h"
#include "core/random.h"

namespace fleetmap::merging {
namespace {

// Two robots' landmark maps of one area: `common` landmarks seen by both (other's copy moved by
// the inverse of `other_to_self`, with measurement noise), plus landmarks only one of them has.
// Signatures are 3-D (width, height, colour) as in the map-alignment paper; noise on them is small.
struct LandmarkScene {
  LandmarkMap self, other;
  core::Transform2 other_to_self;
};

// With `distinct`, landmarks only one map has get signatures no landmark of the other map has
// (their colours differ), so they never match by signature.
LandmarkScene make_scene(core::Random& r, int common, int self_only, int other_only, double noise,
                         bool distinct = false) {
  LandmarkScene s;
  s.other_to_self = core::Transform2(r.uniform(-30, 30), r.uniform(-30, 30), r.uniform(-3.1, 3.1));
  const core::Transform2 to_other = s.other_to_self.inverse();
  const auto random_landmark = [&]() {
    MapLandmark l;
    l.position = Eigen::Vector2d(r.uniform(0, 60), r.uniform(0, 60));
    l.signature = Eigen::Vector3d(r.uniform(0.2, 3.0), r.uniform(0.5, 2.5), r.uniform(0.0, 10.0));
    l.covariance = Eigen::Vector2d(r.uniform(0.01, 0.05), r.uniform(0.01, 0.05)).asDiagonal();
    return l;
  };
  for (int i = 0; i < common; ++i) {
    const MapLandmark l = random_landmark();
    s.self.landmarks.push_back(l);
    MapLandmark o = l;
    o.position = to_other.apply(l.position) + Eigen::Vector2d(r.normal(0, noise), r.normal(0, noise));
    o.signature += Eigen::Vector3d(r.normal(0, 0.01), r.normal(0, 0.01), r.normal(0, 0.01));
    s.other.landmarks.push_back(o);
  }
  for (int i = 0; i < self_only; ++i) {
    MapLandmark l = random_landmark();
    if (distinct) l.signature(2) += 20.0;
    s.self.landmarks.push_back(l);
  }
  for (int i = 0; i < other_only; ++i) {
    MapLandmark o = random_landmark();
    o.position = to_other.apply(o.position);
    if (distinct) o.signature(2) += 40.0;
    s.other.landmarks.push_back(o);
  }
  return s;
}

TEST(LandmarkAlignment, TwoPairsGiveTheExactTransform) {
  // Eq. (3)-(6) on noise-free pairs.
  core::Random random(1);
  for (int i = 0; i < 50; ++i) {
    const core::Transform2 t(random.uniform(-10, 10), random.uniform(-10, 10), random.uniform(-3.1, 3.1));
    const Eigen::Vector2d oi(random.uniform(0, 20), random.uniform(0, 20)), oj(random.uniform(0, 20), random.uniform(0, 20));
    EXPECT_TRUE(transform_from_two_pairs(t.apply(oi), oi, t.apply(oj), oj).is_approx(t, 1e-9));
  }
  // By hand: other's x axis is self's y axis, other's origin at self's (1, 2).
  const core::Transform2 quarter = transform_from_two_pairs({1, 2}, {0, 0}, {1, 3}, {1, 0});
  EXPECT_TRUE(quarter.is_approx(core::Transform2(1.0, 2.0, std::numbers::pi / 2), 1e-12)) << quarter;
}

// The map-alignment paper, §III.A with 30% outliers: 30% of other's landmarks are not in self's map at all.
TEST(LandmarkAlignment, RansacRecoversAKnownTransformWith30PercentOutliers) {
  core::Random random(7);
  LandmarkAlignmentOptions o;
  for (int trial = 0; trial < 20; ++trial) {
    const LandmarkScene s = make_scene(random, 28, 10, 12, 0.05);  // other: 28 common + 12 outliers
    const LandmarkAlignment a = align_landmarks(s.self, s.other, o, random);
    ASSERT_TRUE(a.found) << "trial " << trial;
    // Position noise 0.05 m per axis over 28 landmarks spread over 60 m: at their centroid the fit
    // is off by about 0.05 sqrt(2 / 28) = 0.013 m, its rotation by about 0.05 / (17 m sqrt(28))
    // = 0.03 degrees. Bounds: four of those.
    Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
    for (int i = 0; i < 28; ++i) centroid += s.self.landmarks[std::size_t(i)].position / 28.0;
    const Eigen::Vector2d at = s.other_to_self.inverse().apply(centroid);
    EXPECT_LT((a.transform.apply(at) - centroid).norm(), 0.055) << "trial " << trial;
    EXPECT_LT(std::abs(core::rad2deg(core::normalize_angle(a.transform.rotation() - s.other_to_self.rotation()))), 0.12)
        << "trial " << trial;
    EXPECT_GE(a.supports.size(), 26u);
    EXPECT_LE(a.supports.size(), 28u + 2u);  // an outlier may land near a landmark by chance
  }
}

TEST(LandmarkAlignment, WithoutConsistentMatchesThereIsNoAlignment) {
  core::Random random(9);
  LandmarkScene s = make_scene(random, 0, 20, 20, 0.0);
  const LandmarkAlignment a = align_landmarks(s.self, s.other, {}, random);
  EXPECT_FALSE(a.found);
}

TEST(LandmarkFusion, CovarianceTransformIsRotationSandwich) {
  LandmarkMap m;
  MapLandmark l;
  l.position = {1.0, 0.0};
  l.covariance = Eigen::Vector2d(4.0, 1.0).asDiagonal();
  m.landmarks.push_back(l);
  const LandmarkMap t = transform_landmarks(m, core::Transform2(0.0, 1.0, std::numbers::pi / 2));
  // Eq. (10): turned a quarter, the long axis moves from x to y.
  EXPECT_TRUE(t.landmarks[0].position.isApprox(Eigen::Vector2d(0.0, 2.0), 1e-12));
  EXPECT_NEAR(t.landmarks[0].covariance(0, 0), 1.0, 1e-12);
  EXPECT_NEAR(t.landmarks[0].covariance(1, 1), 4.0, 1e-12);
  EXPECT_NEAR(t.landmarks[0].covariance(0, 1), 0.0, 1e-12);
}

TEST(LandmarkFusion, Equations11To13AgainstHandComputedValues) {
  MapLandmark self, other;
  self.position = {0.0, 0.0};
  self.covariance = Eigen::Vector2d(1.0, 4.0).asDiagonal();
  other.position = {2.0, 1.0};
  other.covariance = Eigen::Vector2d(1.0, 1.0).asDiagonal();
  // K = diag(1/2, 4/5); Sigma = diag(1 - 1/2, 4 - 16/5) = diag(0.5, 0.8); p = (1, 0.8).
  const MapLandmark f = fuse_landmarks(self, other);
  EXPECT_NEAR(f.position.x(), 1.0, 1e-12);
  EXPECT_NEAR(f.position.y(), 0.8, 1e-12);
  EXPECT_NEAR(f.covariance(0, 0), 0.5, 1e-12);
  EXPECT_NEAR(f.covariance(1, 1), 0.8, 1e-12);
  EXPECT_NEAR(f.covariance(0, 1), 0.0, 1e-12);

  // A full covariance: Sigma_s = [[2, 1], [1, 2]], Sigma_o = I. (Sigma_s + I)^-1 = [[3, -1], [-1, 3]] / 8,
  // K = Sigma_s (Sigma_s + I)^-1 = [[5, 1], [1, 5]] / 8, K Sigma_s = [[11, 7], [7, 11]] / 8,
  // Sigma = Sigma_s - K Sigma_s = [[5, 1], [1, 5]] / 8, p = K (4, 0) = (2.5, 0.5).
  self.covariance << 2.0, 1.0, 1.0, 2.0;
  other.covariance = Eigen::Matrix2d::Identity();
  other.position = {4.0, 0.0};
  const MapLandmark g = fuse_landmarks(self, other);
  EXPECT_NEAR(g.position.x(), 2.5, 1e-12);
  EXPECT_NEAR(g.position.y(), 0.5, 1e-12);
  EXPECT_NEAR(g.covariance(0, 0), 5.0 / 8, 1e-12);
  EXPECT_NEAR(g.covariance(0, 1), 1.0 / 8, 1e-12);
  EXPECT_NEAR(g.covariance(1, 0), 1.0 / 8, 1e-12);
  EXPECT_NEAR(g.covariance(1, 1), 5.0 / 8, 1e-12);
}

TEST(LandmarkFusion, MergeFusesDuplicatesAndAddsTheRest) {
  core::Random random(12);
  const LandmarkScene s = make_scene(random, 15, 5, 7, 0.02, true);
  const LandmarkMergeResult m = merge_landmark_maps(s.self, s.other, s.other_to_self, {});
  EXPECT_EQ(m.duplicates, 15);
  EXPECT_EQ(m.added, 7);
  EXPECT_EQ(m.merged.landmarks.size(), 20u + 7u);
  // A fused duplicate is more certain than either estimate.
  EXPECT_LT(m.merged.landmarks[0].covariance.trace(), s.self.landmarks[0].covariance.trace());
}

TEST(LandmarkMethodChoice, Figure3ChoosesByTheNumberOfOverlappingLandmarks) {
  core::Random random(21);
  LandmarkAlignmentOptions o;
  // A rendezvous that gives a slightly wrong transform, to tell the methods apart.
  Rendezvous meeting{{0, 0, 0}, {0, 0, 0}, {2.0, 0.0, 2.0, 0.0}};
  for (const int common : {9, 10}) {
    const LandmarkScene s = make_scene(random, common, 5, 5, 0.02, true);
    const LandmarkMethodChoice c = align_landmark_maps(s.self, s.other, meeting, o, random);
    EXPECT_EQ(c.overlapping_landmarks, common);
    ASSERT_TRUE(c.transform.has_value());
    if (common < o.overlap_threshold) {
      EXPECT_EQ(c.method, AlignmentMethod::InterRobotObservation);
      EXPECT_EQ(c.message, "Map alignment using inter robot observations");
      EXPECT_TRUE(c.transform->is_approx(core::Transform2(2.0, 0.0, std::numbers::pi), 1e-9));
    } else {
      EXPECT_EQ(c.method, AlignmentMethod::DataAssociation);
      EXPECT_EQ(c.message, "Map alignment using data association");
      EXPECT_TRUE(c.transform->is_approx(s.other_to_self, 0.1)) << *c.transform << " vs " << s.other_to_self;
    }
  }
  // Few overlapping landmarks and no rendezvous: no alignment, and the report says why.
  const LandmarkScene s = make_scene(random, 3, 5, 5, 0.02, true);
  const LandmarkMethodChoice none = align_landmark_maps(s.self, s.other, std::nullopt, o, random);
  EXPECT_EQ(none.method, AlignmentMethod::None);
  EXPECT_FALSE(none.transform.has_value());
  EXPECT_NE(none.message.find("3 overlapping landmarks"), std::string::npos) << none.message;
  EXPECT_STREQ(to_string(AlignmentMethod::DataAssociation), "data_association");
}

}  // namespace
}  // namespace fleetmap::merging
