#include "localization/polynomial_ekf.h"

#include <Eigen/Dense>

#include <algorithm>

#include "core/angle.h"
#include "core/error.h"
#include "localization/ekf_models.h"

namespace fleetmap::localization {

PolynomialEkf::PolynomialEkf(const core::Pose2& initial_pose, const Eigen::Matrix3d& initial_covariance)
    : mean_(Eigen::Vector3d(initial_pose.x, initial_pose.y, core::normalize_angle(initial_pose.theta))),
      covariance_(initial_covariance) {}

void PolynomialEkf::predict(const Odometry& u, const Eigen::Matrix3d& q) {
  predict_augmented_state(mean_, covariance_, u, q);
}

namespace {

// P H^T for H = [h_pose, 0, ..., h_slot at slot, ...].
Eigen::VectorXd covariance_times_h(const Eigen::MatrixXd& p, const ScalarReading& r) {
  Eigen::VectorXd ph = p.leftCols<3>() * r.h_pose.transpose();
  if (r.slot >= 0) ph += r.h_slot * p.col(3 + r.slot);
  return ph;
}

double h_times(const Eigen::VectorXd& v, const ScalarReading& r) {
  double s = r.h_pose.dot(v.head<3>());
  if (r.slot >= 0) s += r.h_slot * v(3 + r.slot);
  return s;
}

void symmetrise(Eigen::MatrixXd& p) {
  const Eigen::Index n = p.rows();
  for (Eigen::Index j = 1; j < n; ++j) {
    for (Eigen::Index i = 0; i < j; ++i) {
      const double v = 0.5 * (p(i, j) + p(j, i));
      p(i, j) = p(j, i) = v;
    }
  }
}

}  // namespace

double PolynomialEkf::innovation_variance(const ScalarReading& r) const {
  return h_times(covariance_times_h(covariance_, r), r) + r.noise;
}

void PolynomialEkf::update(double z, const ScalarReading& r) {
  const Eigen::VectorXd ph = covariance_times_h(covariance_, r);
  const double s = h_times(ph, r) + r.noise;
  if (!(s > 0.0)) return;
  const Eigen::VectorXd k = ph / s;
  mean_ += k * (z - r.predicted);
  mean_(2) = core::normalize_angle(mean_(2));
  // Joseph form (I - KH) P (I - KH)^T + K R K^T = P - K (PH)^T - (PH) K^T + (H P H^T + R) K K^T.
  covariance_.noalias() -= k * ph.transpose();
  covariance_.noalias() -= ph * k.transpose();
  covariance_.noalias() += s * (k * k.transpose());
  symmetrise(covariance_);
}

int PolynomialEkf::augment(const LandmarkGeneration& g) {
  const Eigen::Index n = mean_.size();
  // g_x P: the new row of G_x P G_x^T, from the pose rows and the rows of the source slots.
  Eigen::RowVectorXd gp = g.g_pose * covariance_.topRows<3>();
  for (const auto& [slot, d] : g.g_slots) gp += d * covariance_.row(3 + slot);
  double diag = gp.head<3>().dot(g.g_pose);
  for (const auto& [slot, d] : g.g_slots) diag += d * gp(3 + slot);
  diag += g.noise_variance;
  covariance_.conservativeResize(n + 1, n + 1);
  covariance_.block(n, 0, 1, n) = gp;
  covariance_.block(0, n, n, 1) = gp.transpose();
  covariance_(n, n) = diag;
  mean_.conservativeResize(n + 1);
  mean_(n) = g.value;
  return int(n) - 3;
}

void PolynomialEkf::remove(const std::vector<int>& slots) {
  if (slots.empty()) return;
  std::vector<char> drop(std::size_t(this->slots()), 0);
  for (int s : slots) drop.at(std::size_t(s)) = 1;
  std::vector<Eigen::Index> keep = {0, 1, 2};
  for (int s = 0; s < this->slots(); ++s) {
    if (!drop[std::size_t(s)]) keep.push_back(3 + s);
  }
  mean_ = Eigen::VectorXd(mean_(keep));
  covariance_ = Eigen::MatrixXd(covariance_(keep, keep));
}

void PolynomialEkf::change_frame(const core::Transform2& t, const std::vector<double>& positions,
                                 const std::vector<double>& scales) {
  const Eigen::Index n = mean_.size();
  if (Eigen::Index(positions.size()) != n - 3 || Eigen::Index(scales.size()) != n - 3) {
    throw Error("PolynomialEkf::change_frame: one position and one scale per landmark expected");
  }
  const core::Pose2 moved = core::Pose2::from_transform(t * pose().as_transform());
  mean_.head<3>() << moved.x, moved.y, core::normalize_angle(moved.theta);
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(n);
  for (Eigen::Index s = 0; s < n - 3; ++s) {
    mean_(3 + s) = positions[std::size_t(s)];
    scale(3 + s) = scales[std::size_t(s)];
  }
  // A = diag(R, 1, scales): rows and columns of the landmarks scale, the position block turns.
  covariance_ = scale.asDiagonal() * covariance_ * scale.asDiagonal();
  const Eigen::Matrix2d r = t.rotation_matrix();
  covariance_.topRows<2>() = r * covariance_.topRows<2>();
  covariance_.leftCols<2>() = covariance_.leftCols<2>() * r.transpose();
  symmetrise(covariance_);
}

bool is_diverging(const Eigen::Matrix3d& p, double k, const Eigen::Matrix3d& p0) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(k * p0 - p);
  return eig.eigenvalues().minCoeff() < 0.0;
}

}  // namespace fleetmap::localization
