#include "merging/rendezvous.h"

#include <Eigen/Dense>
#include <cmath>
#include <numbers>

#include "core/error.h"

namespace fleetmap::merging {

core::Transform2 rendezvous_transform(const core::Pose2& self_pose, const core::Pose2& other_pose,
                                      const MutualObservation& z) {
  const double rho = 0.5 * (z.range_self_to_other + z.range_other_to_self);
  const double theta = std::numbers::pi + z.bearing_self_to_other - z.bearing_other_to_self;
  const double big_theta = self_pose.theta + theta - other_pose.theta;  // eq. (9)
  const double c = std::cos(big_theta), s = std::sin(big_theta);
  const double heading = self_pose.theta + z.bearing_self_to_other;
  const double dx = self_pose.x + rho * std::cos(heading) - (other_pose.x * c - other_pose.y * s);  // eq. (7)
  const double dy = self_pose.y + rho * std::sin(heading) - (other_pose.x * s + other_pose.y * c);  // eq. (8)
  return {dx, dy, big_theta};
}

core::Transform2 rendezvous_transform_matrices(const core::Pose2& receiver_pose, const core::Pose2& sender_pose,
                                               double distance, double bearing_receiver_to_sender,
                                               double bearing_sender_to_receiver) {
  const double vartheta = std::numbers::pi + bearing_receiver_to_sender - bearing_sender_to_receiver;
  Eigen::Matrix3d t_lj = Eigen::Matrix3d::Identity();
  t_lj << std::cos(vartheta), -std::sin(vartheta), distance * std::cos(bearing_receiver_to_sender),
      std::sin(vartheta), std::cos(vartheta), distance * std::sin(bearing_receiver_to_sender), 0.0, 0.0, 1.0;
  const Eigen::Matrix3d t_jj0 = receiver_pose.as_transform().matrix();
  const Eigen::Matrix3d t_ll0 = sender_pose.as_transform().matrix();
  return core::Transform2::from_matrix(t_jj0 * t_lj * t_ll0.inverse());  // D'Alfonso et al., §3.2
}

namespace {

void check_same_resolution(const core::GridGeometry& a, const core::GridGeometry& b) {
  if (std::abs(a.resolution() - b.resolution()) > 1e-9 * std::max(a.resolution(), b.resolution())) {
    throw Error("rigid map transforms need one resolution; got " + std::to_string(a.resolution()) + " and " +
                std::to_string(b.resolution()) + " m per cell");
  }
}

}  // namespace

core::Transform2 cells_from_world(const core::GridGeometry& a, const core::GridGeometry& b,
                                  const core::Transform2& b_world_to_a_world) {
  check_same_resolution(a, b);
  // Cell p of b is at origin_b (res (p + 1/2)) in b's world; m maps b's grid metres to a's.
  const core::Transform2 m = a.origin().as_transform().inverse() * b_world_to_a_world * b.origin().as_transform();
  const double res = a.resolution();
  const Eigen::Vector2d half(0.5, 0.5);
  return {m.rotation_matrix() * half + m.translation() / res - half, m.rotation()};
}

core::Transform2 world_from_cells(const core::GridGeometry& a, const core::GridGeometry& b,
                                  const core::Transform2& cells) {
  check_same_resolution(a, b);
  const double res = a.resolution();
  const Eigen::Vector2d half(0.5, 0.5);
  // Inverse of the above: m.t = res (t + half - R half).
  const core::Transform2 m(res * (cells.translation() + half - cells.rotation_matrix() * half), cells.rotation());
  return a.origin().as_transform() * m * b.origin().as_transform().inverse();
}

core::Transform2 flip_rows(const core::Transform2& b_to_a, int height_a, int height_b) {
  // F_h(x, y) = (x, h - 1 - y) = D p + e_h with D = diag(1, -1); F_a T F_b = (R(-theta), D (R e_b + t) + e_a).
  const Eigen::Vector2d e_a(0.0, height_a - 1.0), e_b(0.0, height_b - 1.0);
  const Eigen::Vector2d v = b_to_a.rotation_matrix() * e_b + b_to_a.translation();
  return {Eigen::Vector2d(v.x(), -v.y()) + e_a, -b_to_a.rotation()};
}

}  // namespace fleetmap::merging
