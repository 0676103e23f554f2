#include "merging/rigid_fit.h"

#include <gtest/gtest.h>

#include "core/random.h"

namespace fleetmap::merging {
namespace {

TEST(FitRigid, RecoversAnExactTransform) {
  const core::Transform2 truth(4.0, -7.5, 2.2);
  std::vector<PointPair> pairs;
  core::Random random(1);
  for (int i = 0; i < 10; ++i) {
    const Eigen::Vector2d p(random.uniform(-20, 20), random.uniform(-20, 20));
    pairs.push_back({p, truth.apply(p), 1.0});
  }
  const auto t = fit_rigid(pairs);
  ASSERT_TRUE(t.has_value());
  EXPECT_TRUE(t->is_approx(truth, 1e-9)) << *t;
}

TEST(FitRigid, NeedsTwoDistinctPoints) {
  EXPECT_FALSE(fit_rigid({}).has_value());
  EXPECT_FALSE(fit_rigid({{Eigen::Vector2d(1, 1), Eigen::Vector2d(2, 2), 1.0}}).has_value());
  EXPECT_FALSE(fit_rigid({{Eigen::Vector2d(1, 1), Eigen::Vector2d(2, 2), 1.0},
                          {Eigen::Vector2d(1, 1), Eigen::Vector2d(2, 2), 1.0}})
                   .has_value());
}

TEST(RansacRigid, IgnoresOutliersAndRefusesScale) {
  const core::Transform2 truth(30.0, 12.0, -0.9);
  core::Random random(2);
  std::vector<PointPair> pairs;
  for (int i = 0; i < 60; ++i) {
    const Eigen::Vector2d p(random.uniform(0, 200), random.uniform(0, 200));
    const bool outlier = i % 2 == 0;  // half of the matches are wrong
    const Eigen::Vector2d q = outlier ? Eigen::Vector2d(random.uniform(0, 200), random.uniform(0, 200))
                                      : truth.apply(p) + Eigen::Vector2d(random.normal(0, 0.3), random.normal(0, 0.3));
    pairs.push_back({p, q, 1.0});
  }
  RigidRansacOptions o;
  const auto fit = ransac_rigid(pairs, o, random);
  ASSERT_TRUE(fit.has_value());
  EXPECT_GE(fit->inliers.size(), 28u);
  EXPECT_LT(std::abs(fit->transform.rotation() - truth.rotation()), 0.01);
  EXPECT_LT((fit->transform.translation() - truth.translation()).norm(), 1.0);

  // Points scaled by 1.5: a similarity fits them, a rigid model must not.
  std::vector<PointPair> scaled;
  for (int i = 0; i < 40; ++i) {
    const Eigen::Vector2d p(random.uniform(0, 200), random.uniform(0, 200));
    scaled.push_back({p, 1.5 * p, 1.0});
  }
  const auto none = ransac_rigid(scaled, o, random);
  EXPECT_TRUE(!none.has_value() || none->inliers.size() < 10u);
}

}  // namespace
}  // namespace fleetmap::merging
