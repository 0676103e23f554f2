// `ideal` and `odometry`: the two localizers that need no filter.
#include <cmath>

#include "localization/ekf_models.h"
#include "localization/localizer.h"
#include "core/error.h"
#include "localization/localizers.h"

namespace fleetmap::localization {

void Localizer::change_frame(const core::Transform2&) {
  throw Error("localization '" + name() + "' cannot move its estimate into another map frame");
}

Eigen::Matrix3d rotate_pose_covariance(const Eigen::Matrix3d& covariance, double angle) {
  Eigen::Matrix3d j = Eigen::Matrix3d::Identity();
  j.topLeftCorner<2, 2>() = core::Transform2(0.0, 0.0, angle).rotation_matrix();
  return j * covariance * j.transpose();
}

core::Pose2 integrate_motion(const core::Pose2& p, const Odometry& u) {
  const double dtheta = u.omega * u.dt;
  if (std::abs(dtheta) < 1e-9) {
    return {p.x + u.v * u.dt * std::cos(p.theta), p.y + u.v * u.dt * std::sin(p.theta), p.theta};
  }
  const double r = u.v / u.omega;
  return {p.x + r * (std::sin(p.theta + dtheta) - std::sin(p.theta)),
          p.y - r * (std::cos(p.theta + dtheta) - std::cos(p.theta)), p.theta + dtheta};
}

namespace {

// The simulator's true pose: the upper bound every other localizer is compared with.
class IdealLocalizer final : public Localizer {
 public:
  explicit IdealLocalizer(const LocalizerContext& c) : pose_(c.initial_pose) {}
  std::string name() const override { return "ideal"; }
  void predict(const Odometry& u) override { pose_ = integrate_motion(pose_, u); }
  void observe_truth(const core::Pose2& truth) override { pose_ = truth; }
  core::Pose2 pose() const override { return pose_; }
  Eigen::Matrix3d covariance() const override { return Eigen::Matrix3d::Zero(); }
  void change_frame(const core::Transform2& t) override { pose_ = core::Pose2::from_transform(t * pose_.as_transform()); }

 private:
  core::Pose2 pose_;
};

// Dead reckoning: integrates odometry; the covariance grows with the process noise.
class OdometryLocalizer final : public Localizer {
 public:
  explicit OdometryLocalizer(const LocalizerContext& c)
      : pose_(c.initial_pose), options_(c.options), covariance_(initial_covariance(c.options)) {}
  std::string name() const override { return "odometry"; }
  void predict(const Odometry& u) override {
    // Linearised propagation of the pose covariance through the motion model.
    const Eigen::Matrix3d f = motion_jacobian(pose_, u);
    covariance_ = f * covariance_ * f.transpose() + process_noise(options_);
    pose_ = integrate_motion(pose_, u);
  }
  core::Pose2 pose() const override { return pose_; }
  Eigen::Matrix3d covariance() const override { return covariance_; }
  void change_frame(const core::Transform2& t) override {
    pose_ = core::Pose2::from_transform(t * pose_.as_transform());
    covariance_ = rotate_pose_covariance(covariance_, t.rotation());
  }

 private:
  core::Pose2 pose_;
  LocalizerOptions options_;
  Eigen::Matrix3d covariance_;
};

}  // namespace

std::unique_ptr<Localizer> make_ideal_localizer(const LocalizerContext& c) { return std::make_unique<IdealLocalizer>(c); }
std::unique_ptr<Localizer> make_odometry_localizer(const LocalizerContext& c) {
  return std::make_unique<OdometryLocalizer>(c);
}

}  // namespace fleetmap::localization
