#include "localization/ekf_core.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <limits>
#include <vector>

#include "core/angle.h"
#include "localization/ekf_models.h"

namespace fleetmap::localization {
namespace {

const Eigen::Matrix2d kR = Eigen::Vector2d(0.05 * 0.05, 0.02 * 0.02).asDiagonal();

// A filter with a pose and three landmarks, correlated through their creation.
EkfCore make_filter() {
  EkfCore f({1.0, -0.5, 0.3}, Eigen::Vector3d(0.04, 0.03, 0.01).asDiagonal());
  f.add_landmark({4.0, 0.2}, kR);
  f.predict({1.0, 0.1, 1.0}, Eigen::Vector3d(0.01, 0.01, 0.001).asDiagonal());
  f.add_landmark({3.0, -0.9}, kR);
  f.predict({0.5, -0.2, 1.0}, Eigen::Vector3d(0.01, 0.01, 0.001).asDiagonal());
  f.add_landmark({6.0, 1.1}, kR);
  return f;
}

// The textbook EKF update with the full dense H.
struct Dense {
  Eigen::VectorXd x;
  Eigen::MatrixXd p;
};
Dense dense_update(const EkfCore& f, const Eigen::Vector2d& z, const PointReading& r) {
  const Eigen::Index n = f.mean().size();
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(2, n);
  h.leftCols(3) = r.h_pose;
  if (r.point_offset >= 0) h.middleCols(r.point_offset, 2) = r.h_point;
  const Eigen::MatrixXd& p = f.covariance();
  const Eigen::Matrix2d s = h * p * h.transpose() + r.noise;
  const Eigen::MatrixXd k = p * h.transpose() * s.inverse();
  const Eigen::VectorXd nu = EkfCore::innovation(z, r);
  const Eigen::MatrixXd ikh = Eigen::MatrixXd::Identity(n, n) - k * h;
  Dense d{f.mean() + k * nu, ikh * p * ikh.transpose() + k * r.noise * k.transpose()};
  d.x(2) = core::normalize_angle(d.x(2));
  EXPECT_TRUE(s.isApprox(r.innovation_covariance, 1e-12));
  return d;
}

TEST(EkfCore, UpdateWithALandmarkInTheStateEqualsTheDenseJosephUpdate) {
  EkfCore f = make_filter();
  const auto r = f.predict_slot(1, kR);
  ASSERT_TRUE(r.has_value());
  const Eigen::Vector2d z = r->predicted + Eigen::Vector2d(0.08, -0.03);
  const Dense expected = dense_update(f, z, *r);
  f.update(z, *r);
  EXPECT_LT((f.mean() - expected.x).norm(), 1e-12);
  EXPECT_LT((f.covariance() - expected.p).norm(), 1e-12);
  EXPECT_TRUE(f.covariance().isApprox(f.covariance().transpose(), 0.0));
}

TEST(EkfCore, UpdateWithAnUncertainOutsidePointAddsItsCovarianceToTheNoise) {
  EkfCore f = make_filter();
  const Eigen::Matrix2d sigma = (Eigen::Matrix2d() << 0.09, 0.02, 0.02, 0.04).finished();
  const auto r = f.predict_point({6.0, 3.0}, sigma, kR);
  ASSERT_TRUE(r.has_value());
  EXPECT_TRUE(r->noise.isApprox(kR + r->h_point * sigma * r->h_point.transpose(), 1e-12));
  const Eigen::Vector2d z = r->predicted + Eigen::Vector2d(-0.1, 0.05);
  const Dense expected = dense_update(f, z, *r);
  f.update(z, *r);
  EXPECT_LT((f.mean() - expected.x).norm(), 1e-12);
  EXPECT_LT((f.covariance() - expected.p).norm(), 1e-12);
}

TEST(EkfCore, PredictMovesThePoseBlockAndTheCrossCovariancesOnly) {
  EkfCore f = make_filter();
  const Eigen::MatrixXd p0 = f.covariance();
  const core::Pose2 pose0 = f.pose();
  const Odometry u{0.8, 0.4, 1.0};
  const Eigen::Matrix3d q = Eigen::Vector3d(0.01, 0.02, 0.003).asDiagonal();
  f.predict(u, q);
  const Eigen::Matrix3d fj = motion_jacobian(pose0, u);
  const Eigen::Index m = p0.rows() - 3;
  EXPECT_TRUE(f.pose_covariance().isApprox(fj * p0.topLeftCorner<3, 3>() * fj.transpose() + q, 1e-12));
  EXPECT_TRUE(f.covariance().topRightCorner(3, m).isApprox(fj * p0.topRightCorner(3, m), 1e-12));
  EXPECT_TRUE(f.covariance().bottomRightCorner(m, m).isApprox(p0.bottomRightCorner(m, m), 0.0));
  const core::Pose2 expected = integrate_motion(pose0, u);
  EXPECT_NEAR(f.pose().x, expected.x, 1e-12);
  EXPECT_NEAR(f.pose().y, expected.y, 1e-12);
  EXPECT_NEAR(f.pose().theta, core::normalize_angle(expected.theta), 1e-12);
}

TEST(EkfCore, RemovingALandmarkDropsItsRowsAndColumns) {
  EkfCore f = make_filter();
  const Eigen::VectorXd x0 = f.mean();
  const Eigen::MatrixXd p0 = f.covariance();
  f.remove_landmarks({1});
  ASSERT_EQ(f.landmark_count(), 2);
  const std::vector<Eigen::Index> keep = {0, 1, 2, 3, 4, 7, 8};
  EXPECT_TRUE(f.mean().isApprox(x0(keep), 0.0));
  EXPECT_TRUE(f.covariance().isApprox(p0(keep, keep), 0.0));
  f.remove_landmarks({0, 1});
  EXPECT_EQ(f.landmark_count(), 0);
  EXPECT_EQ(f.covariance().rows(), 3);
}

TEST(EkfCore, ReadingOfAPointAtTheRobotIsRefused) {
  EkfCore f = make_filter();
  EXPECT_FALSE(f.predict_point(f.pose().position(), Eigen::Matrix2d::Zero(), kR).has_value());
}

TEST(EkfCore, RobotDetectionOutsideTheGateIsRefusedAndLeavesTheStateAlone) {
  EkfCore f = make_filter();
  const Eigen::VectorXd x0 = f.mean();
  RobotObservation o;
  o.other_pose = {f.pose().x + 3.0, f.pose().y, 0.0};
  o.other_covariance = Eigen::Matrix3d::Identity() * 1e-4;
  const Eigen::Vector2d truth = range_bearing(f.pose(), o.other_pose.position());
  o.range = truth(0) + 2.0;  // two metres off: far outside chi2(2)
  o.bearing = truth(1);
  EXPECT_FALSE(update_with_robot(f, o, kR, 9.21));
  EXPECT_TRUE(f.mean().isApprox(x0, 0.0));
  o.range = truth(0) + 0.01;
  EXPECT_TRUE(update_with_robot(f, o, kR, 9.21));
  EXPECT_LT(f.pose_covariance().trace(), make_filter().pose_covariance().trace());
}

TEST(NearestNeighbour, IsGlobalAndGated) {
  const double inf = std::numeric_limits<double>::infinity();
  Eigen::MatrixXd d2(3, 3);
  // Reading 0 is closest to candidate 0, but reading 1 is closer still to it: 1 gets 0, 0 gets 1.
  d2 << 1.0, 2.0, 50.0,  //
      0.5, 8.0, 60.0,    //
      30.0, 40.0, inf;
  const auto a = associate_nearest_neighbour(d2, 9.21);
  EXPECT_EQ(a.match, (std::vector<int>{1, 0, -1}));
  EXPECT_EQ(a.smallest_d2, (std::vector<double>{1.0, 0.5, 30.0}));
  const auto none = associate_nearest_neighbour(Eigen::MatrixXd(2, 0), 9.21);
  EXPECT_EQ(none.match, (std::vector<int>{-1, -1}));
  EXPECT_EQ(none.smallest_d2[0], inf);
}

}  // namespace
}  // namespace fleetmap::localization
