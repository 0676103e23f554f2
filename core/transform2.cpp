#include "core/transform2.h"

#include <Eigen/Dense>
#include <cmath>
#include <ostream>

#include "core/angle.h"
#include "core/error.h"

namespace fleetmap::core {

Transform2::Transform2(double tx, double ty, double theta) : Transform2(Eigen::Vector2d(tx, ty), theta) {}

Transform2::Transform2(const Eigen::Vector2d& t, double theta)
    : t_(t), theta_(normalize_angle(theta)), cos_(std::cos(theta_)), sin_(std::sin(theta_)) {}

Transform2 Transform2::from_matrix(const Eigen::Matrix3d& m) {
  const Eigen::Matrix2d r = m.topLeftCorner<2, 2>();
  const bool rotation = (r.transpose() * r - Eigen::Matrix2d::Identity()).norm() < 1e-6 &&
                        r.determinant() > 0.0;
  const bool affine_row = std::abs(m(2, 0)) < 1e-9 && std::abs(m(2, 1)) < 1e-9 &&
                          std::abs(m(2, 2) - 1.0) < 1e-9;
  if (!rotation || !affine_row) {
    throw Error("Transform2::from_matrix: not a rigid 2D homogeneous matrix");
  }
  return {Eigen::Vector2d(m(0, 2), m(1, 2)), std::atan2(r(1, 0), r(0, 0))};
}

Eigen::Matrix3d Transform2::matrix() const {
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  m.topLeftCorner<2, 2>() = rotation_matrix();
  m.topRightCorner<2, 1>() = t_;
  return m;
}

Transform2 Transform2::inverse() const {
  const Eigen::Matrix2d rt = rotation_matrix().transpose();
  return {-(rt * t_), -theta_};
}

Transform2 Transform2::operator*(const Transform2& other) const {
  return {apply(other.t_), theta_ + other.theta_};
}

bool Transform2::is_approx(const Transform2& other, double tol) const {
  return (t_ - other.t_).norm() <= tol &&
         std::abs(normalize_angle(theta_ - other.theta_)) <= tol;
}

Pose2::Pose2(double x_, double y_, double theta_) : x(x_), y(y_), theta(normalize_angle(theta_)) {}

Pose2 Pose2::from_transform(const Transform2& t) {
  return {t.translation().x(), t.translation().y(), t.rotation()};
}

Pose2 Pose2::compose(const Pose2& other) const {
  return from_transform(as_transform() * other.as_transform());
}

Pose2 Pose2::inverse() const { return from_transform(as_transform().inverse()); }

Eigen::Vector2d Pose2::transform(const Eigen::Vector2d& p) const { return as_transform().apply(p); }

std::ostream& operator<<(std::ostream& os, const Transform2& t) {
  return os << "Transform2(tx=" << t.translation().x() << ", ty=" << t.translation().y()
            << ", theta=" << t.rotation() << ")";
}

std::ostream& operator<<(std::ostream& os, const Pose2& p) {
  return os << "Pose2(" << p.x << ", " << p.y << ", " << p.theta << ")";
}

}  // namespace fleetmap::core
