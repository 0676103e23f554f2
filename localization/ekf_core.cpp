#include "localization/ekf_core.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "core/angle.h"
#include "localization/ekf_models.h"

namespace fleetmap::localization {

EkfCore::EkfCore(const core::Pose2& initial_pose, const Eigen::Matrix3d& initial_covariance)
    : mean_(Eigen::Vector3d(initial_pose.x, initial_pose.y, core::normalize_angle(initial_pose.theta))),
      covariance_(initial_covariance) {}

void EkfCore::predict(const Odometry& u, const Eigen::Matrix3d& q) {
  predict_augmented_state(mean_, covariance_, u, q);
}

std::optional<PointReading> EkfCore::finish(PointReading r, const Eigen::Vector2d& point) const {
  const core::Pose2 p = pose();
  r.predicted = range_bearing(p, point);
  if (!(r.predicted(0) > 1e-9)) return std::nullopt;
  const RangeBearingJacobians j = range_bearing_jacobians(p, point);
  r.h_pose = j.pose;
  r.h_point = j.point;
  Eigen::Matrix2d s = r.h_pose * covariance_.topLeftCorner<3, 3>() * r.h_pose.transpose() + r.noise;
  if (r.point_offset >= 0) {
    const Eigen::Matrix<double, 3, 2> prl = covariance_.block<3, 2>(0, r.point_offset);
    const Eigen::Matrix2d pll = covariance_.block<2, 2>(r.point_offset, r.point_offset);
    const Eigen::Matrix2d cross = r.h_pose * prl * r.h_point.transpose();
    s += cross + cross.transpose() + r.h_point * pll * r.h_point.transpose();
  }
  r.innovation_covariance = 0.5 * (s + s.transpose());
  return r;
}

std::optional<PointReading> EkfCore::predict_slot(int slot, const Eigen::Matrix2d& measurement_noise) const {
  PointReading r;
  r.point_offset = offset(slot);
  r.noise = measurement_noise;
  return finish(r, landmark(slot));
}

std::optional<PointReading> EkfCore::predict_point(const Eigen::Vector2d& point,
                                                   const Eigen::Matrix2d& point_covariance,
                                                   const Eigen::Matrix2d& measurement_noise) const {
  PointReading r;
  r.noise = measurement_noise;
  auto out = finish(r, point);
  if (!out) return out;
  // The point's own uncertainty enters as measurement noise: the other robot's estimate is not
  // in this state, so its correlation with this pose is unknown and taken as zero.
  out->noise += out->h_point * point_covariance * out->h_point.transpose();
  out->innovation_covariance += out->h_point * point_covariance * out->h_point.transpose();
  return out;
}

Eigen::Vector2d EkfCore::innovation(const Eigen::Vector2d& reading, const PointReading& p) {
  return {reading(0) - p.predicted(0), core::normalize_angle(reading(1) - p.predicted(1))};
}

double EkfCore::mahalanobis2(const Eigen::Vector2d& reading, const PointReading& p) {
  const Eigen::Vector2d nu = innovation(reading, p);
  const Eigen::LDLT<Eigen::Matrix2d> ldlt(p.innovation_covariance);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) {
    return std::numeric_limits<double>::infinity();
  }
  return nu.dot(ldlt.solve(nu));
}

void EkfCore::update(const Eigen::Vector2d& reading, const PointReading& r) {
  const Eigen::Index n = mean_.size();
  const bool in_state = r.point_offset >= 0;
  // HP = H P (2 x n) from H's pose block and, for a landmark in the state, its point block.
  Eigen::Matrix<double, 2, Eigen::Dynamic> hp = r.h_pose * covariance_.topRows<3>();
  if (in_state) hp.noalias() += r.h_point * covariance_.middleRows<2>(r.point_offset);
  // K = P H^T S^-1 = (S^-1 H P)^T, as P and S are symmetric.
  const Eigen::LDLT<Eigen::Matrix2d> ldlt(r.innovation_covariance);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return;
  const Eigen::Matrix<double, Eigen::Dynamic, 2> k = ldlt.solve(hp).transpose();

  mean_.noalias() += k * innovation(reading, r);
  mean_(2) = core::normalize_angle(mean_(2));

  // Joseph form P' = (I - KH) P (I - KH)^T + K R K^T, expanded without assuming K optimal:
  //   P' = P - K (HP) - (A H^T) K^T + K R K^T,  A H^T = (HP)^T - K (H P H^T) = (HP)^T - K (S - R),
  // as one rank-6 product computed on the lower triangle only and mirrored, so P' is exactly
  // symmetric and each update is one O(n^2) pass.
  const Eigen::Matrix<double, Eigen::Dynamic, 2> aht = hp.transpose() - k * (r.innovation_covariance - r.noise);
  Eigen::Matrix<double, Eigen::Dynamic, 6> u(n, 6);
  u << -k, -aht, k * r.noise;
  Eigen::Matrix<double, 6, Eigen::Dynamic> vt(6, n);
  vt << hp, k.transpose(), k.transpose();
  covariance_.triangularView<Eigen::Lower>() += u * vt;
  for (Eigen::Index j = 1; j < n; ++j) {
    for (Eigen::Index i = 0; i < j; ++i) covariance_(i, j) = covariance_(j, i);
  }
}

int EkfCore::add_landmark(const Eigen::Vector2d& reading, const Eigen::Matrix2d& measurement_noise) {
  const core::Pose2 p = pose();
  const Eigen::Vector2d point = landmark_from_reading(p, reading);
  covariance_ = augment_covariance(covariance_, landmark_generation_jacobians(p, reading), measurement_noise);
  const Eigen::Index n = mean_.size();
  mean_.conservativeResize(n + 2);
  mean_.tail<2>() = point;
  return landmark_count() - 1;
}

void EkfCore::remove_landmarks(const std::vector<int>& slots) {
  if (slots.empty()) return;
  std::vector<bool> drop(static_cast<std::size_t>(landmark_count()), false);
  for (int s : slots) drop.at(static_cast<std::size_t>(s)) = true;
  std::vector<Eigen::Index> keep = {0, 1, 2};
  for (int s = 0; s < landmark_count(); ++s) {
    if (!drop[static_cast<std::size_t>(s)]) {
      keep.push_back(offset(s));
      keep.push_back(offset(s) + 1);
    }
  }
  mean_ = Eigen::VectorXd(mean_(keep));
  covariance_ = Eigen::MatrixXd(covariance_(keep, keep));
}

bool update_with_robot(EkfCore& filter, const RobotObservation& o, const Eigen::Matrix2d& measurement_noise,
                       double gate) {
  const Eigen::Vector2d z(o.range, o.bearing);
  const auto reading =
      filter.predict_point(o.other_pose.position(), o.other_covariance.topLeftCorner<2, 2>(), measurement_noise);
  if (!reading || !(EkfCore::mahalanobis2(z, *reading) <= gate)) return false;
  filter.update(z, *reading);
  return true;
}

void RobotDetectionUpdates::apply(EkfCore& filter, const RobotObservation& o, const Eigen::Matrix2d& measurement_noise,
                                  const LocalizerOptions& options) {
  if (!options.use_robot_detections) return;
  ++(update_with_robot(filter, o, measurement_noise, options.association_gate) ? updates_ : rejected_);
}

std::vector<std::pair<std::string, double>> RobotDetectionUpdates::counters() const {
  return {{"robot_updates", static_cast<double>(updates_)}, {"rejected_robot_detections", static_cast<double>(rejected_)}};
}

NearestNeighbourAssociation associate_nearest_neighbour(const Eigen::MatrixXd& d2, double gate) {
  const Eigen::Index readings = d2.rows(), candidates = d2.cols();
  NearestNeighbourAssociation out;
  out.match.assign(static_cast<std::size_t>(readings), -1);
  out.smallest_d2.assign(static_cast<std::size_t>(readings), std::numeric_limits<double>::infinity());
  std::vector<std::tuple<double, Eigen::Index, Eigen::Index>> pairs;
  for (Eigen::Index i = 0; i < readings; ++i) {
    for (Eigen::Index j = 0; j < candidates; ++j) {
      const double v = d2(i, j);
      auto& smallest = out.smallest_d2[static_cast<std::size_t>(i)];
      smallest = std::min(smallest, v);
      if (v <= gate) pairs.emplace_back(v, i, j);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<bool> taken(static_cast<std::size_t>(candidates), false);
  for (const auto& [v, i, j] : pairs) {
    auto& m = out.match[static_cast<std::size_t>(i)];
    if (m >= 0 || taken[static_cast<std::size_t>(j)]) continue;
    m = static_cast<int>(j);
    taken[static_cast<std::size_t>(j)] = true;
  }
  return out;
}

void EkfCore::change_frame(const core::Transform2& t) {
  const core::Pose2 p = core::Pose2::from_transform(t * pose().as_transform());
  mean_(0) = p.x;
  mean_(1) = p.y;
  mean_(2) = p.theta;
  const Eigen::Matrix2d r = t.rotation_matrix();
  for (int slot = 0; slot < landmark_count(); ++slot) mean_.segment<2>(offset(slot)) = t.apply(landmark(slot));
  // J: R on every (x, y) pair, 1 on the heading.
  const Eigen::Index n = mean_.size();
  Eigen::MatrixXd j = Eigen::MatrixXd::Identity(n, n);
  j.block<2, 2>(0, 0) = r;
  for (int slot = 0; slot < landmark_count(); ++slot) j.block<2, 2>(offset(slot), offset(slot)) = r;
  covariance_ = j * covariance_ * j.transpose();
  covariance_ = 0.5 * (covariance_ + covariance_.transpose());
}

}  // namespace fleetmap::localization
