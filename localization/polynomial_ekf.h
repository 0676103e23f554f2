#pragma once
// The extended Kalman filter of D'Alfonso et al.'s polynomial SLAM (§3.1): the augmented state
// X = [x, y, theta, c0_1, ..., c0_n], the pose followed by one position coefficient c_0 per
// polynomial landmark ("slots" 0, 1, ... in state order), or, with the shape in the state, a block
// [c0, a_1..a_m] per landmark (PolynomialSlam decides what the slots mean). Readings are scalar (a
// distance along a sensor axis, eq. (2)); landmarks enter by the covariance augmentation of
// eq. (4)-(5) and leave by removing their rows and columns.
// Contract: the covariance stays symmetric (Joseph-form updates, symmetrised) and the heading in (-pi, pi].
#include <Eigen/Core>

#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "core/transform2.h"
#include "localization/localizer.h"

namespace fleetmap::localization {

// A scalar reading z = h(X) + v linearised at the current state: H has a pose block and, for a
// reading of a landmark, one entry at that landmark's slot.
struct ScalarReading {
  double predicted = 0.0;                                   // h(X)
  Eigen::RowVector3d h_pose = Eigen::RowVector3d::Zero();   // dh / d(x, y, theta)
  int slot = -1;                                            // the landmark read, -1 for none
  double h_slot = 0.0;                                      // dh / d c0_slot
  std::vector<std::pair<int, double>> h_more;               // (slot, dh / d X_slot): further entries (shape)
  double noise = 0.0;                                       // Var(v)
};

// A new landmark's generation function c0_new = g(X, y) (D'Alfonso et al., eq. (5)) linearised at the
// predicted state: G_x = [I_n; g_x] with g_x's non-zero entries on the pose and on the slots of the
// landmarks it was computed from; G_y V G_y^T reduces to `noise_variance`.
struct LandmarkGeneration {
  double value = 0.0;
  Eigen::RowVector3d g_pose = Eigen::RowVector3d::Zero();
  std::vector<std::pair<int, double>> g_slots;  // (slot, d c0_new / d c0_slot)
  double noise_variance = 0.0;
};

// A block of k new entries X_new = g(X, y) (eq. (4)-(5) for a landmark with its shape in the
// state): G_x = [I_n; J] with J = [g_pose, 0, ..., g_slots columns], and G_y V G_y^T = `noise`.
struct BlockGeneration {
  Eigen::VectorXd value;                                    // k
  Eigen::MatrixXd g_pose;                                   // k x 3
  std::vector<std::pair<int, Eigen::VectorXd>> g_slots;     // (slot, d X_new / d X_slot, k)
  Eigen::MatrixXd noise;                                    // k x k
};

class PolynomialEkf {
 public:
  PolynomialEkf(const core::Pose2& initial_pose, const Eigen::Matrix3d& initial_covariance);

  // x <- f(x, u) (the exact differential-drive arc); P_rr <- F P_rr F^T + Q, P_rl <- F P_rl.
  void predict(const Odometry& u, const Eigen::Matrix3d& process_noise);
  // The same with the motion Jacobian's displacement taken as p_k+1|k - `previous_predicted`
  // (first-estimate Jacobians, Huang, Mourikis & Roumeliotis 2008: the displacement between the
  // predicted positions, not from the corrected one).
  void predict(const Odometry& u, const Eigen::Matrix3d& process_noise, const Eigen::Vector2d& previous_predicted);

  // P_ss += variance: process noise on a landmark entry.
  void add_noise(int slot, double variance) { covariance_(3 + slot, 3 + slot) += variance; }

  // S = H P H^T + R.
  double innovation_variance(const ScalarReading& r) const;
  // The EKF update with one scalar reading, Joseph form (I-KH) P (I-KH)^T + K R K^T, O(n^2).
  // Does nothing when S is not positive.
  void update(double z, const ScalarReading& r);

  // The reading model at a state: nullopt when the reading does not see its landmark there.
  using ReadingModel = std::function<std::optional<ScalarReading>(const Eigen::VectorXd& state)>;
  enum class UpdateOutcome { Updated, Gated, Lost };
  // The EKF update with a reading given as its model: linearised at the current state; nothing
  // changes when the innovation fails the chi-square `gate` (nu^2 / S > gate: Gated) or when, at
  // the updated state, the reading no longer sees its landmark (Lost: the linearisation does not
  // hold over the step, e.g. a sensor axis moved off a short polynomial's end, and the information
  // it would add is spurious).
  UpdateOutcome update(double z, const ReadingModel& model, double gate);

  // D'Alfonso et al. eq. (4): appends c0_new and P~ = G_x P G_x^T + G_y V G_y^T; returns the new slot.
  int augment(const LandmarkGeneration& g);
  // The same for a block of entries; returns the first new slot.
  int augment(const BlockGeneration& g);
  // Removes the slots' rows and columns (D'Alfonso et al., §3.1); later slots move down to fill the gaps.
  void remove(const std::vector<int>& slots);
  // Re-expresses the state in another frame, x_new = new_from_old * x_old, where each landmark's
  // new c_0 is `positions[s]` and depends on its old one as d c0_new / d c0_old = `scales[s]`:
  // X <- (pose moved, positions), P <- A P A^T with A = diag(R, 1, scales).
  void change_frame(const core::Transform2& new_from_old, const std::vector<double>& positions,
                    const std::vector<double>& scales);
  // The general form: the slots' new values and d X_new / d X_old over all slots (n_new x n_old):
  // P <- A P A^T with A = diag(R, 1, jacobian).
  void change_frame(const core::Transform2& new_from_old, const Eigen::VectorXd& values,
                    const Eigen::MatrixXd& jacobian);

  core::Pose2 pose() const { return {mean_(0), mean_(1), mean_(2)}; }
  Eigen::Matrix3d pose_covariance() const { return covariance_.topLeftCorner<3, 3>(); }
  int slots() const { return static_cast<int>(mean_.size()) - 3; }
  double position(int slot) const { return mean_(3 + slot); }
  double position_variance(int slot) const { return covariance_(3 + slot, 3 + slot); }
  double value(int slot) const { return mean_(3 + slot); }
  const Eigen::VectorXd& mean() const { return mean_; }
  const Eigen::MatrixXd& covariance() const { return covariance_; }

 private:
  Eigen::VectorXd mean_;
  Eigen::MatrixXd covariance_;
};

// D'Alfonso et al. §3.1's divergence test P_k|k-1 > K P0: true when K P0 - P is not positive
// semi-definite (P exceeds K P0 in some direction).
bool is_diverging(const Eigen::Matrix3d& predicted_covariance, double k, const Eigen::Matrix3d& initial_covariance);

}  // namespace fleetmap::localization
