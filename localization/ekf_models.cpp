#include "localization/ekf_models.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/angle.h"
#include "core/error.h"

namespace fleetmap::localization {

Eigen::Matrix3d motion_jacobian(const core::Pose2& pose, const Odometry& u) {
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  const double dtheta = u.omega * u.dt;
  if (std::abs(dtheta) < 1e-9) {
    f(0, 2) = -u.v * u.dt * std::sin(pose.theta);
    f(1, 2) = u.v * u.dt * std::cos(pose.theta);
  } else {
    const double r = u.v / u.omega;
    f(0, 2) = r * (std::cos(pose.theta + dtheta) - std::cos(pose.theta));
    f(1, 2) = r * (std::sin(pose.theta + dtheta) - std::sin(pose.theta));
  }
  return f;
}

void predict_augmented_state(Eigen::VectorXd& mean, Eigen::MatrixXd& covariance, const Odometry& u,
                             const Eigen::Matrix3d& q) {
  predict_augmented_state(mean, covariance, u, q, motion_jacobian(core::Pose2(mean(0), mean(1), mean(2)), u));
}

void predict_augmented_state(Eigen::VectorXd& mean, Eigen::MatrixXd& covariance, const Odometry& u,
                             const Eigen::Matrix3d& q, const Eigen::Matrix3d& f) {
  const core::Pose2 before(mean(0), mean(1), mean(2));
  const core::Pose2 after = integrate_motion(before, u);
  mean.head<3>() << after.x, after.y, core::normalize_angle(after.theta);
  const Eigen::Index m = covariance.rows() - 3;
  const Eigen::Matrix3d prr = covariance.topLeftCorner<3, 3>();
  covariance.topLeftCorner<3, 3>() = f * prr * f.transpose() + q;
  if (m > 0) {
    const Eigen::MatrixXd prl = f * covariance.topRightCorner(3, m);
    covariance.topRightCorner(3, m) = prl;
    covariance.bottomLeftCorner(m, 3) = prl.transpose();
  }
}

Eigen::Matrix3d process_noise(const LocalizerOptions& o) {
  return Eigen::Vector3d(o.process_noise_xy * o.process_noise_xy, o.process_noise_xy * o.process_noise_xy,
                         o.process_noise_theta * o.process_noise_theta)
      .asDiagonal();
}

Eigen::Matrix2d measurement_noise(const LocalizerOptions& o) {
  const double r = std::max(o.range_noise, kMinMeasurementStd);
  const double b = std::max(o.bearing_noise, kMinMeasurementStd);
  return Eigen::Vector2d(r * r, b * b).asDiagonal();
}

Eigen::Matrix3d initial_covariance(const LocalizerOptions& o) {
  return Eigen::Vector3d(o.initial_xy * o.initial_xy, o.initial_xy * o.initial_xy, o.initial_theta * o.initial_theta)
      .asDiagonal();
}

void validate_options(const LocalizerOptions& o) {
  const auto non_negative = [](const char* key, double value) {
    if (!(value >= 0.0) || !std::isfinite(value)) {
      throw InputError(std::string("localization option '") + key + "': expected a finite number >= 0, got " +
                       std::to_string(value));
    }
  };
  non_negative("process_noise_xy", o.process_noise_xy);
  non_negative("process_noise_theta", o.process_noise_theta);
  non_negative("turn_noise_per_rad", o.turn_noise_per_rad);
  non_negative("drive_noise_per_m", o.drive_noise_per_m);
  non_negative("range_noise", o.range_noise);
  non_negative("bearing_noise", o.bearing_noise);
  non_negative("initial_xy", o.initial_xy);
  non_negative("initial_theta", o.initial_theta);
  if (!(o.association_gate > 0.0)) {
    throw InputError("localization option 'association_gate': expected a positive chi-square value, got " +
                     std::to_string(o.association_gate));
  }
}

double new_landmark_gate(const LocalizerOptions& o, const core::Params& params) {
  const double gate = params.number("new_landmark_gate");
  if (!(gate >= o.association_gate)) {
    throw InputError(params.owner() + ": new_landmark_gate must be >= association_gate (" + std::to_string(o.association_gate) +
                     "), got " + std::to_string(gate));
  }
  return gate;
}

Eigen::Vector2d range_bearing(const core::Pose2& pose, const Eigen::Vector2d& point) {
  const Eigen::Vector2d d = point - pose.position();
  return {d.norm(), core::normalize_angle(std::atan2(d.y(), d.x()) - pose.theta)};
}

RangeBearingJacobians range_bearing_jacobians(const core::Pose2& pose, const Eigen::Vector2d& point) {
  const Eigen::Vector2d d = point - pose.position();
  const double q = d.squaredNorm();
  const double r = std::sqrt(q);
  RangeBearingJacobians j;
  j.pose << -d.x() / r, -d.y() / r, 0.0,  //
      d.y() / q, -d.x() / q, -1.0;
  j.point << d.x() / r, d.y() / r,  //
      -d.y() / q, d.x() / q;
  return j;
}

Eigen::Vector2d landmark_from_reading(const core::Pose2& pose, const Eigen::Vector2d& reading) {
  const double a = pose.theta + reading(1);
  return pose.position() + reading(0) * Eigen::Vector2d(std::cos(a), std::sin(a));
}

LandmarkGenerationJacobians landmark_generation_jacobians(const core::Pose2& pose, const Eigen::Vector2d& reading) {
  const double a = pose.theta + reading(1);
  const double c = std::cos(a), s = std::sin(a), r = reading(0);
  LandmarkGenerationJacobians g;
  g.pose << 1.0, 0.0, -r * s,  //
      0.0, 1.0, r * c;
  g.reading << c, -r * s,  //
      s, r * c;
  return g;
}

Eigen::MatrixXd augment_covariance(const Eigen::MatrixXd& p, const LandmarkGenerationJacobians& g,
                                   const Eigen::Matrix2d& v) {
  const Eigen::Index n = p.rows();
  Eigen::MatrixXd out(n + 2, n + 2);
  out.topLeftCorner(n, n) = p;
  // Rows of G_x for the new point are [dg/dpose 0 ... 0], so G_x P only needs P's pose rows.
  const Eigen::MatrixXd cross = g.pose * p.topRows(3);  // 2 x n
  out.bottomLeftCorner(2, n) = cross;
  out.topRightCorner(n, 2) = cross.transpose();
  out.bottomRightCorner<2, 2>() =
      g.pose * p.topLeftCorner<3, 3>() * g.pose.transpose() + g.reading * v * g.reading.transpose();
  return out;
}

}  // namespace fleetmap::localization
