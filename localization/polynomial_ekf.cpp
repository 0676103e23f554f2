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

void PolynomialEkf::predict(const Odometry& u, const Eigen::Matrix3d& q, const Eigen::Vector2d& previous_predicted) {
  const core::Pose2 after = integrate_motion(pose(), u);
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  f(0, 2) = -(after.y - previous_predicted.y());
  f(1, 2) = after.x - previous_predicted.x();
  predict_augmented_state(mean_, covariance_, u, q, f);
}

namespace {

// P H^T for H = [h_pose, 0, ..., h_slot at slot, ...].
Eigen::VectorXd covariance_times_h(const Eigen::MatrixXd& p, const ScalarReading& r) {
  Eigen::VectorXd ph = p.leftCols<3>() * r.h_pose.transpose();
  if (r.slot >= 0) ph += r.h_slot * p.col(3 + r.slot);
  for (const auto& [slot, h] : r.h_more) ph += h * p.col(3 + slot);
  return ph;
}

double h_times(const Eigen::VectorXd& v, const ScalarReading& r) {
  double s = r.h_pose.dot(v.head<3>());
  if (r.slot >= 0) s += r.h_slot * v(3 + r.slot);
  for (const auto& [slot, h] : r.h_more) s += h * v(3 + slot);
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

// Joseph form (I - KH) P (I - KH)^T + K R K^T = P - K (PH)^T - (PH) K^T + (H P H^T + R) K K^T, K = PH / s.
void apply_gain(Eigen::MatrixXd& p, const Eigen::VectorXd& ph, double s) {
  const Eigen::VectorXd k = ph / s;
  p.noalias() -= k * ph.transpose();
  p.noalias() -= ph * k.transpose();
  p.noalias() += s * (k * k.transpose());
  symmetrise(p);
}

}  // namespace

double PolynomialEkf::innovation_variance(const ScalarReading& r) const {
  return h_times(covariance_times_h(covariance_, r), r) + r.noise;
}

void PolynomialEkf::update(double z, const ScalarReading& r) {
  const Eigen::VectorXd ph = covariance_times_h(covariance_, r);
  const double s = h_times(ph, r) + r.noise;
  if (!(s > 0.0)) return;
  mean_ += ph * ((z - r.predicted) / s);
  mean_(2) = core::normalize_angle(mean_(2));
  apply_gain(covariance_, ph, s);
}

PolynomialEkf::UpdateOutcome PolynomialEkf::update(double z, const ReadingModel& model, double gate) {
  const std::optional<ScalarReading> r = model(mean_);
  if (!r) return UpdateOutcome::Lost;
  const Eigen::VectorXd ph = covariance_times_h(covariance_, *r);
  const double s = h_times(ph, *r) + r->noise;
  const double nu = z - r->predicted;
  if (!(s > 0.0) || nu * nu / s > gate) return UpdateOutcome::Gated;
  Eigen::VectorXd next = mean_ + ph * (nu / s);
  next(2) = core::normalize_angle(next(2));
  if (!model(next)) return UpdateOutcome::Lost;
  mean_ = std::move(next);
  apply_gain(covariance_, ph, s);
  return UpdateOutcome::Updated;
}

int PolynomialEkf::augment(const LandmarkGeneration& g) {
  BlockGeneration b;
  b.value = Eigen::VectorXd::Constant(1, g.value);
  b.g_pose = g.g_pose;
  for (const auto& [slot, d] : g.g_slots) b.g_slots.emplace_back(slot, Eigen::VectorXd::Constant(1, d));
  b.noise = Eigen::MatrixXd::Constant(1, 1, g.noise_variance);
  return augment(b);
}

int PolynomialEkf::augment(const BlockGeneration& g) {
  const Eigen::Index n = mean_.size();
  const Eigen::Index k = g.value.size();
  if (g.g_pose.rows() != k || g.g_pose.cols() != 3 || g.noise.rows() != k || g.noise.cols() != k) {
    throw Error("PolynomialEkf::augment: a block of k entries needs a k x 3 g_pose and a k x k noise");
  }
  // J P: the new rows of G_x P G_x^T, from the pose rows and the rows of the source slots.
  Eigen::MatrixXd jp = g.g_pose * covariance_.topRows<3>();
  for (const auto& [slot, d] : g.g_slots) {
    if (d.size() != k) throw Error("PolynomialEkf::augment: a slot's derivative needs one entry per new entry");
    jp += d * covariance_.row(3 + slot);
  }
  Eigen::MatrixXd block = jp.leftCols<3>() * g.g_pose.transpose() + g.noise;
  for (const auto& [slot, d] : g.g_slots) block += jp.col(3 + slot) * d.transpose();
  covariance_.conservativeResize(n + k, n + k);
  covariance_.block(n, 0, k, n) = jp;
  covariance_.block(0, n, n, k) = jp.transpose();
  covariance_.block(n, n, k, k) = 0.5 * (block + block.transpose());
  mean_.conservativeResize(n + k);
  mean_.tail(k) = g.value;
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
  const Eigen::Index n = mean_.size() - 3;
  if (Eigen::Index(positions.size()) != n || Eigen::Index(scales.size()) != n) {
    throw Error("PolynomialEkf::change_frame: one position and one scale per landmark expected");
  }
  // A = diag(R, 1, scales): rows and columns of the landmarks scale, the position block turns.
  change_frame(t, Eigen::Map<const Eigen::VectorXd>(positions.data(), n),
               Eigen::Map<const Eigen::VectorXd>(scales.data(), n).asDiagonal().toDenseMatrix());
}

void PolynomialEkf::change_frame(const core::Transform2& t, const Eigen::VectorXd& values,
                                 const Eigen::MatrixXd& jacobian) {
  const Eigen::Index n = mean_.size() - 3;
  const Eigen::Index m = values.size();
  if (jacobian.rows() != m || jacobian.cols() != n) {
    throw Error("PolynomialEkf::change_frame: one value per new slot and a new x old jacobian expected");
  }
  const core::Pose2 moved = core::Pose2::from_transform(t * pose().as_transform());
  Eigen::VectorXd mean(m + 3);
  mean << moved.x, moved.y, core::normalize_angle(moved.theta), values;
  mean_ = std::move(mean);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(m + 3, n + 3);
  a.topLeftCorner<2, 2>() = t.rotation_matrix();
  a(2, 2) = 1.0;
  a.bottomRightCorner(m, n) = jacobian;
  covariance_ = a * covariance_ * a.transpose();
  symmetrise(covariance_);
}

bool is_diverging(const Eigen::Matrix3d& p, double k, const Eigen::Matrix3d& p0) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(k * p0 - p);
  return eig.eigenvalues().minCoeff() < 0.0;
}

}  // namespace fleetmap::localization
