#include "localization/ekf_models.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "core/angle.h"
#include "core/error.h"
#include "core/random.h"

namespace fleetmap::localization {
namespace {

using Vec = Eigen::VectorXd;

// Central differences of f at x; entries listed in `angles` are wrapped before dividing.
Eigen::MatrixXd numerical_jacobian(const std::function<Vec(const Vec&)>& f, const Vec& x,
                                   const std::vector<int>& angle_rows = {}, double h = 1e-6) {
  const Vec f0 = f(x);
  Eigen::MatrixXd j(f0.size(), x.size());
  for (Eigen::Index c = 0; c < x.size(); ++c) {
    Vec xp = x, xm = x;
    xp(c) += h;
    xm(c) -= h;
    Vec d = f(xp) - f(xm);
    for (int r : angle_rows) d(r) = core::normalize_angle(d(r));
    j.col(c) = d / (2.0 * h);
  }
  return j;
}

core::Pose2 pose_of(const Vec& x) { return {x(0), x(1), x(2)}; }
Vec vec_of(const core::Pose2& p) { return p.vector(); }

TEST(MotionJacobian, MatchesNumericalDifferentiation) {
  const std::vector<core::Pose2> poses = {{0, 0, 0}, {1.5, -2.0, 2.8}, {-3.0, 4.0, -1.2}, {0.3, 0.1, 3.1}};
  const std::vector<Odometry> commands = {{1.0, 0.0, 1.0},    {0.5, 0.3, 1.0},  {2.0, -1.1, 0.1},
                                          {-0.7, 0.2, 0.5},   {0.0, 0.8, 1.0},  {1.0, 1e-12, 1.0}};
  for (const auto& p : poses) {
    for (const auto& u : commands) {
      const auto f = [&](const Vec& x) { return vec_of(integrate_motion(pose_of(x), u)); };
      const Eigen::MatrixXd numeric = numerical_jacobian(f, vec_of(p), {2});
      EXPECT_LT((Eigen::MatrixXd(motion_jacobian(p, u)) - numeric).norm(), 1e-6)
          << "pose " << p << " v " << u.v << " omega " << u.omega << "\n"
          << motion_jacobian(p, u) << "\nvs\n"
          << numeric;
    }
  }
}

TEST(RangeBearing, JacobiansMatchNumericalDifferentiation) {
  core::Random rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    const core::Pose2 p(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-3.1, 3.1));
    Eigen::Vector2d m(rng.uniform(-5, 5), rng.uniform(-5, 5));
    if ((m - p.position()).norm() < 0.5) continue;
    const RangeBearingJacobians j = range_bearing_jacobians(p, m);
    const auto by_pose = [&](const Vec& x) -> Vec { return range_bearing(pose_of(x), m); };
    const auto by_point = [&](const Vec& x) -> Vec { return range_bearing(p, x.head<2>()); };
    EXPECT_LT((Eigen::MatrixXd(j.pose) - numerical_jacobian(by_pose, vec_of(p), {1})).norm(), 1e-6);
    EXPECT_LT((Eigen::MatrixXd(j.point) - numerical_jacobian(by_point, Vec(m), {1})).norm(), 1e-6);
  }
}

TEST(RangeBearing, WrapsTheBearing) {
  const core::Pose2 p(0, 0, 3.0);
  const Eigen::Vector2d z = range_bearing(p, Eigen::Vector2d(1.0, -0.2));
  EXPECT_NEAR(z(0), std::hypot(1.0, 0.2), 1e-12);
  EXPECT_GT(z(1), -std::numbers::pi);
  EXPECT_LE(z(1), std::numbers::pi);
  EXPECT_NEAR(z(1), core::normalize_angle(std::atan2(-0.2, 1.0) - 3.0), 1e-12);
}

TEST(LandmarkGeneration, InvertsTheReadingAndItsJacobiansMatchNumericalDifferentiation) {
  core::Random rng(12);
  for (int trial = 0; trial < 50; ++trial) {
    const core::Pose2 p(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-3.1, 3.1));
    const Eigen::Vector2d z(rng.uniform(0.5, 8.0), rng.uniform(-3.0, 3.0));
    const Eigen::Vector2d m = landmark_from_reading(p, z);
    const Eigen::Vector2d back = range_bearing(p, m);
    EXPECT_NEAR(back(0), z(0), 1e-9);
    EXPECT_NEAR(core::normalize_angle(back(1) - z(1)), 0.0, 1e-9);

    const LandmarkGenerationJacobians g = landmark_generation_jacobians(p, z);
    const auto by_pose = [&](const Vec& x) -> Vec { return landmark_from_reading(pose_of(x), z); };
    const auto by_reading = [&](const Vec& y) -> Vec { return landmark_from_reading(p, y.head<2>()); };
    EXPECT_LT((Eigen::MatrixXd(g.pose) - numerical_jacobian(by_pose, vec_of(p))).norm(), 1e-6);
    EXPECT_LT((Eigen::MatrixXd(g.reading) - numerical_jacobian(by_reading, Vec(z))).norm(), 1e-6);
  }
}

// D'Alfonso et al. eq. (4) with the full matrices G_x = [I; dg/dpose 0] and G_y = [0; dg/dy].
TEST(AugmentCovariance, EqualsTheFullProductOfEquationFour) {
  core::Random rng(13);
  const int n = 7;  // pose + 2 landmarks
  Eigen::MatrixXd a(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) a(i, j) = rng.normal(0.0, 1.0);
  const Eigen::MatrixXd p = a * a.transpose() + 0.1 * Eigen::MatrixXd::Identity(n, n);
  const core::Pose2 pose(1.0, 2.0, 0.7);
  const Eigen::Vector2d z(3.0, -0.4);
  const Eigen::Matrix2d v = Eigen::Vector2d(0.04, 0.001).asDiagonal();
  const LandmarkGenerationJacobians g = landmark_generation_jacobians(pose, z);

  Eigen::MatrixXd gx = Eigen::MatrixXd::Zero(n + 2, n);
  gx.topRows(n).setIdentity();
  gx.block(n, 0, 2, 3) = g.pose;
  Eigen::MatrixXd gy = Eigen::MatrixXd::Zero(n + 2, 2);
  gy.bottomRows(2) = g.reading;
  const Eigen::MatrixXd expected = gx * p * gx.transpose() + gy * v * gy.transpose();

  const Eigen::MatrixXd got = augment_covariance(p, g, v);
  ASSERT_EQ(got.rows(), n + 2);
  EXPECT_LT((got - expected).norm(), 1e-12 * expected.norm());
}

TEST(ModelNoise, MatricesFollowTheOptions) {
  LocalizerOptions o;
  o.process_noise_xy = 0.1;
  o.process_noise_theta = 0.02;
  o.range_noise = 0.0;  // a perfect sensor is floored, not singular
  o.bearing_noise = 0.03;
  o.initial_xy = 0.5;
  o.initial_theta = 0.2;
  EXPECT_TRUE(process_noise(o).isApprox(Eigen::Vector3d(0.01, 0.01, 0.0004).asDiagonal().toDenseMatrix()));
  EXPECT_DOUBLE_EQ(measurement_noise(o)(0, 0), kMinMeasurementStd * kMinMeasurementStd);
  EXPECT_DOUBLE_EQ(measurement_noise(o)(1, 1), 0.03 * 0.03);
  EXPECT_TRUE(initial_covariance(o).isApprox(Eigen::Vector3d(0.25, 0.25, 0.04).asDiagonal().toDenseMatrix()));
}

TEST(ValidateOptions, RejectsBadValuesNamingTheOption) {
  EXPECT_NO_THROW(validate_options(LocalizerOptions{}));
  const auto message = [](LocalizerOptions o) -> std::string {
    try {
      validate_options(o);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  LocalizerOptions o;
  o.range_noise = -1.0;
  EXPECT_NE(message(o).find("range_noise"), std::string::npos);
  o = {};
  o.association_gate = 0.0;
  EXPECT_NE(message(o).find("association_gate"), std::string::npos);
  // The new-landmark gate of ekf-slam and fastslam2 below the association gate names the parameter.
  for (const char* name : {"ekf-slam", "fastslam2"}) {
    try {
      new_landmark_gate({}, localizer_options(name, {{"new_landmark_gate", "1"}}));
      ADD_FAILURE() << name << ": a new_landmark_gate below association_gate was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("localization '") + name + "': new_landmark_gate"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_THROW(localizer_options("ekf-slam", {{"forget_after_steps", "-3"}}), InputError);
  o = {};
  o.process_noise_theta = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(message(o).find("process_noise_theta"), std::string::npos);
}

}  // namespace
}  // namespace fleetmap::localization
