#pragma once
// Rigid transforms and poses in the plane.
#include <Eigen/Core>
#include <iosfwd>

namespace fleetmap::core {

// A rotation by `theta` followed by a translation `t`: p' = R(theta) p + t, the 3x3 homogeneous
// matrix [[cos, -sin, tx], [sin, cos, ty], [0, 0, 1]] of the papers (wave-algorithm paper, eq. (6)).
// `a * b` applies b first, then a, like the matrix product.
class Transform2 {
 public:
  Transform2() = default;
  Transform2(double tx, double ty, double theta);
  Transform2(const Eigen::Vector2d& t, double theta);

  static Transform2 identity() { return {}; }
  // Rejects matrices whose upper-left block is not a rotation (tolerance 1e-6).
  static Transform2 from_matrix(const Eigen::Matrix3d& m);

  const Eigen::Vector2d& translation() const { return t_; }
  double rotation() const { return theta_; }
  Eigen::Matrix2d rotation_matrix() const {
    Eigen::Matrix2d r;
    r << cos_, -sin_, sin_, cos_;
    return r;
  }
  Eigen::Matrix3d matrix() const;

  Transform2 inverse() const;
  // R(theta) p + t, the sums in the order of the matrix product rotation_matrix() * p + t.
  Eigen::Vector2d apply(const Eigen::Vector2d& p) const {
    return {cos_ * p.x() - sin_ * p.y() + t_.x(), sin_ * p.x() + cos_ * p.y() + t_.y()};
  }
  Eigen::Vector2d operator*(const Eigen::Vector2d& p) const { return apply(p); }
  Transform2 operator*(const Transform2& other) const;

  bool is_approx(const Transform2& other, double tol = 1e-9) const;

 private:
  Eigen::Vector2d t_ = Eigen::Vector2d::Zero();
  double theta_ = 0.0;  // in (-pi, pi]
  // cos and sin of theta_, computed once: apply() runs per cell in fusion and per point in the
  // searches, and a sine and cosine per call were a sixth of `fleetmap merge`'s time on
  // 1000 x 1000 maps.
  double cos_ = 1.0, sin_ = 0.0;
};

// Where a robot is: position (metres) and heading (radians, in (-pi, pi]) in some frame.
// A pose is also the transform from the robot's frame to that frame.
struct Pose2 {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;

  Pose2() = default;
  Pose2(double x_, double y_, double theta_);
  static Pose2 from_transform(const Transform2& t);

  Transform2 as_transform() const { return {x, y, theta}; }
  Eigen::Vector2d position() const { return {x, y}; }
  Eigen::Vector3d vector() const { return {x, y, theta}; }

  // this ⊕ other: `other` expressed in this pose's frame, brought into the parent frame.
  Pose2 compose(const Pose2& other) const;
  Pose2 inverse() const;
  // A point in this pose's frame, brought into the parent frame.
  Eigen::Vector2d transform(const Eigen::Vector2d& p) const;

  bool operator==(const Pose2&) const = default;
};

std::ostream& operator<<(std::ostream& os, const Transform2& t);
std::ostream& operator<<(std::ostream& os, const Pose2& p);

}  // namespace fleetmap::core
