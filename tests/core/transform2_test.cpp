#include "core/transform2.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <numbers>
#include <random>

#include "core/angle.h"
#include "core/error.h"

namespace fleetmap::core {
namespace {

constexpr double kPi = std::numbers::pi;

Transform2 random_transform(std::mt19937& rng) {
  std::uniform_real_distribution<double> t(-50.0, 50.0), a(-kPi, kPi);
  return {t(rng), t(rng), a(rng)};
}

TEST(NormalizeAngle, WrapsIntoHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(normalize_angle(0.0), 0.0);
  EXPECT_DOUBLE_EQ(normalize_angle(kPi), kPi);
  EXPECT_DOUBLE_EQ(normalize_angle(-kPi), kPi);
  EXPECT_NEAR(normalize_angle(3.0 * kPi), kPi, 1e-12);
  EXPECT_NEAR(normalize_angle(-0.5 * kPi - 4.0 * kPi), -0.5 * kPi, 1e-12);
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> big(-1000.0, 1000.0);
  for (int i = 0; i < 1000; ++i) {
    const double a = big(rng), n = normalize_angle(a);
    EXPECT_GT(n, -kPi);
    EXPECT_LE(n, kPi);
    EXPECT_NEAR(std::remainder(a - n, 2.0 * kPi), 0.0, 1e-9);
  }
}

TEST(Transform2, ComposeWithInverseIsIdentity) {
  std::mt19937 rng(42);
  for (int i = 0; i < 200; ++i) {
    const Transform2 t = random_transform(rng);
    EXPECT_TRUE((t * t.inverse()).is_approx(Transform2::identity(), 1e-9)) << t;
    EXPECT_TRUE((t.inverse() * t).is_approx(Transform2::identity(), 1e-9)) << t;
  }
}

TEST(Transform2, MatrixRoundTripAndProduct) {
  std::mt19937 rng(7);
  for (int i = 0; i < 200; ++i) {
    const Transform2 a = random_transform(rng), b = random_transform(rng);
    EXPECT_TRUE(Transform2::from_matrix(a.matrix()).is_approx(a, 1e-9));
    EXPECT_TRUE((a * b).matrix().isApprox(a.matrix() * b.matrix(), 1e-9));
    EXPECT_TRUE(a.inverse().matrix().isApprox(a.matrix().inverse(), 1e-9));
    const Eigen::Vector2d p(3.0, -2.0);
    const Eigen::Vector3d h = a.matrix() * p.homogeneous();
    EXPECT_TRUE(a.apply(p).isApprox(h.head<2>(), 1e-9));
  }
}

TEST(Transform2, MatrixMatchesThePapersForm) {
  // The wave-algorithm paper, eq. (6): rotation about the origin by phi, then translation by (tx, ty).
  const Transform2 t(2.0, 3.0, kPi / 2.0);
  Eigen::Matrix3d expected;
  expected << 0, -1, 2, 1, 0, 3, 0, 0, 1;
  EXPECT_TRUE(t.matrix().isApprox(expected, 1e-12));
  EXPECT_TRUE(t.apply({1.0, 0.0}).isApprox(Eigen::Vector2d(2.0, 4.0), 1e-12));
}

TEST(Transform2, FromMatrixRejectsNonRigid) {
  Eigen::Matrix3d scaled = Transform2(1, 2, 0.3).matrix();
  scaled.topLeftCorner<2, 2>() *= 2.0;
  EXPECT_THROW(Transform2::from_matrix(scaled), Error);
  Eigen::Matrix3d reflection = Eigen::Matrix3d::Identity();
  reflection(0, 0) = -1.0;
  EXPECT_THROW(Transform2::from_matrix(reflection), Error);
}

TEST(Pose2, ComposeInverseAndTransform) {
  const Pose2 robot(1.0, 2.0, kPi / 2.0);
  // A point one metre ahead of the robot is one metre along +y in the world.
  EXPECT_TRUE(robot.transform({1.0, 0.0}).isApprox(Eigen::Vector2d(1.0, 3.0), 1e-12));
  const Pose2 moved = robot.compose(Pose2(1.0, 0.0, kPi / 2.0));
  EXPECT_NEAR(moved.x, 1.0, 1e-12);
  EXPECT_NEAR(moved.y, 3.0, 1e-12);
  EXPECT_NEAR(moved.theta, kPi, 1e-12);
  const Pose2 back = robot.compose(robot.inverse());
  EXPECT_NEAR(back.x, 0.0, 1e-12);
  EXPECT_NEAR(back.y, 0.0, 1e-12);
  EXPECT_NEAR(back.theta, 0.0, 1e-12);
}

}  // namespace
}  // namespace fleetmap::core
