#pragma once
// The models behind the EKF localizers, as plain functions of the state so that tests can check
// every Jacobian against numerical differentiation:
//  - differential-drive motion f(x, u) (integrate_motion) and F = df/dx;
//  - the range-bearing reading h(x, m) of a point m and its Jacobians;
//  - the landmark generation function g(x, y) of D'Alfonso et al. eq. (4)-(5) (a reading turned into a
//    point) and its Jacobians G_x, G_y, with the covariance augmentation of eq. (4).
// The state is x = (x, y, theta) for the pose, followed by (x, y) of each point landmark.
#include <Eigen/Core>

#include "core/transform2.h"
#include "localization/localizer.h"

namespace fleetmap::localization {

// Measurement noise below this standard deviation is raised to it, so that a perfect sensor
// (noise 0 in a scenario) still gives an invertible innovation covariance.
inline constexpr double kMinMeasurementStd = 1e-6;

// F = df/dx at (pose, u) for the exact arc of integrate_motion (the same straight-line branch
// when |omega * dt| < 1e-9).
Eigen::Matrix3d motion_jacobian(const core::Pose2& pose, const Odometry& u);

// The EKF prediction of a state [x, y, theta, landmarks...]: the pose moves by the motion model,
// the pose block becomes F P F^T + Q and the pose-landmark blocks F P_xl; landmarks stay.
void predict_augmented_state(Eigen::VectorXd& mean, Eigen::MatrixXd& covariance, const Odometry& u,
                             const Eigen::Matrix3d& q);
// The same with a given F (e.g. evaluated at first estimates instead of the current pose).
void predict_augmented_state(Eigen::VectorXd& mean, Eigen::MatrixXd& covariance, const Odometry& u,
                             const Eigen::Matrix3d& q, const Eigen::Matrix3d& f);

// Q = diag(sxy^2, sxy^2, sth^2): the process noise, additive in the world frame.
Eigen::Matrix3d process_noise(const LocalizerOptions& options);
// R = diag(range^2, bearing^2), each standard deviation at least kMinMeasurementStd.
Eigen::Matrix2d measurement_noise(const LocalizerOptions& options);
// P0 = diag(initial_xy^2, initial_xy^2, initial_theta^2).
Eigen::Matrix3d initial_covariance(const LocalizerOptions& options);
// Throws InputError naming the option for a negative noise, a non-positive gate or a new-landmark
// gate below the association gate.
void validate_options(const LocalizerOptions& options);
// The `new_landmark_gate` parameter of ekf-slam and fastslam2; throws InputError naming the
// localizer when it is below options.association_gate.
double new_landmark_gate(const LocalizerOptions& options, const core::Params& params);

// h(x, m) = (|m - p|, atan2(m - p) - theta) with the bearing wrapped to (-pi, pi].
Eigen::Vector2d range_bearing(const core::Pose2& pose, const Eigen::Vector2d& point);

// dh/dx (pose part) and dh/dm. Undefined when the point is at the robot's position: callers
// check range_bearing(...)(0) > 0 first.
struct RangeBearingJacobians {
  Eigen::Matrix<double, 2, 3> pose;
  Eigen::Matrix2d point;
};
RangeBearingJacobians range_bearing_jacobians(const core::Pose2& pose, const Eigen::Vector2d& point);

// g(x, y) = p + range * (cos(theta + bearing), sin(theta + bearing)): the landmark generation
// function, the inverse of h for one reading y = (range, bearing).
Eigen::Vector2d landmark_from_reading(const core::Pose2& pose, const Eigen::Vector2d& reading);

// The non-trivial blocks of D'Alfonso et al. eq. (5): dg/d(pose) (2x3) and dg/dy (2x2).
struct LandmarkGenerationJacobians {
  Eigen::Matrix<double, 2, 3> pose;
  Eigen::Matrix2d reading;
};
LandmarkGenerationJacobians landmark_generation_jacobians(const core::Pose2& pose, const Eigen::Vector2d& reading);

// D'Alfonso et al. eq. (4): P~ = G_x P G_x^T + G_y V G_y^T for a state whose first three entries are the
// pose, where G_x = [I_n; dg/dpose 0] and G_y = [0; dg/dy] (eq. (5)). Computed block-wise in
// O(n) new entries, which equals the product of the full matrices; returns the (n+2)x(n+2) matrix.
Eigen::MatrixXd augment_covariance(const Eigen::MatrixXd& covariance, const LandmarkGenerationJacobians& g,
                                   const Eigen::Matrix2d& reading_noise);

}  // namespace fleetmap::localization
