#pragma once
// The extended Kalman filter shared by `ekf` and `ekf-slam`: a Gaussian over the pose
// (x, y, theta) followed by zero or more point landmarks (x, y), "slots" 0, 1, ... in state order.
// `ekf` keeps no slots (its landmarks are a known map); `ekf-slam` adds and removes them.
// Contract: the covariance stays symmetric (every update is in Joseph form and symmetrised) and
// the heading stays in (-pi, pi].
#include <Eigen/Core>

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/transform2.h"
#include "localization/localizer.h"

namespace fleetmap::localization {

// A predicted range-bearing reading of one point, linearised at the current state.
struct PointReading {
  Eigen::Vector2d predicted = Eigen::Vector2d::Zero();  // h(x, m): (range, bearing)
  Eigen::Matrix<double, 2, 3> h_pose = Eigen::Matrix<double, 2, 3>::Zero();
  Eigen::Matrix2d h_point = Eigen::Matrix2d::Zero();
  int point_offset = -1;  // state index of the point's x, or -1 for a point outside the state
  // R, plus h_point * Sigma * h_point^T for a point outside the state with covariance Sigma.
  Eigen::Matrix2d noise = Eigen::Matrix2d::Zero();
  Eigen::Matrix2d innovation_covariance = Eigen::Matrix2d::Zero();  // S = H P H^T + noise
};

class EkfCore {
 public:
  EkfCore(const core::Pose2& initial_pose, const Eigen::Matrix3d& initial_covariance);

  // x <- f(x, u); P <- F P F^T + Q on the pose block, F P on the pose-landmark blocks.
  void predict(const Odometry& u, const Eigen::Matrix3d& process_noise);

  // The reading of the landmark in `slot`; nullopt when it sits at the robot's position.
  std::optional<PointReading> predict_slot(int slot, const Eigen::Matrix2d& measurement_noise) const;
  // The reading of a point outside the state (a known landmark, another robot) whose position
  // is uncertain with covariance `point_covariance` (zero for a known landmark).
  std::optional<PointReading> predict_point(const Eigen::Vector2d& point, const Eigen::Matrix2d& point_covariance,
                                            const Eigen::Matrix2d& measurement_noise) const;

  // z - h with the bearing wrapped.
  static Eigen::Vector2d innovation(const Eigen::Vector2d& reading, const PointReading& predicted);
  // The squared Mahalanobis distance nu^T S^-1 nu of a reading.
  static double mahalanobis2(const Eigen::Vector2d& reading, const PointReading& predicted);

  // The EKF update with one reading, Joseph form (I-KH) P (I-KH)^T + K R K^T, using only H's
  // non-zero blocks: O(n^2) for a state of size n.
  void update(const Eigen::Vector2d& reading, const PointReading& predicted);

  // D'Alfonso et al. eq. (4)-(5): appends the landmark g(x, y) seen as `reading` from the current pose and
  // augments the covariance; returns its slot.
  int add_landmark(const Eigen::Vector2d& reading, const Eigen::Matrix2d& measurement_noise);
  // Removes the slots' rows and columns (D'Alfonso et al., §3.1); later slots move down to fill the gaps.
  void remove_landmarks(const std::vector<int>& slots);

  // x_new = t x_old for the pose and every landmark; P_new = J P J^T with J the block rotation.
  void change_frame(const core::Transform2& t);

  core::Pose2 pose() const { return {mean_(0), mean_(1), mean_(2)}; }
  Eigen::Matrix3d pose_covariance() const { return covariance_.topLeftCorner<3, 3>(); }
  int landmark_count() const { return static_cast<int>((mean_.size() - 3) / 2); }
  Eigen::Vector2d landmark(int slot) const { return mean_.segment<2>(offset(slot)); }
  Eigen::Matrix2d landmark_covariance(int slot) const {
    return covariance_.block<2, 2>(offset(slot), offset(slot));
  }
  const Eigen::VectorXd& mean() const { return mean_; }
  const Eigen::MatrixXd& covariance() const { return covariance_; }

 private:
  static int offset(int slot) { return 3 + 2 * slot; }
  std::optional<PointReading> finish(PointReading r, const Eigen::Vector2d& point) const;

  Eigen::VectorXd mean_;
  Eigen::MatrixXd covariance_;
};

// A robot-robot detection in EKF form (León et al.'s detection model): the other robot's estimated
// position is the point read, and its covariance joins the measurement noise. Applied only when
// the reading passes the chi-square `gate`; returns whether it was.
bool update_with_robot(EkfCore& filter, const RobotObservation& observation, const Eigen::Matrix2d& measurement_noise,
                       double gate);

// Robot-robot detections applied to an EKF localizer's filter (when the localizer's options use
// them), and counted as metrics.json's "robot_updates" and "rejected_robot_detections": `ekf` and
// `ekf-slam` share it.
class RobotDetectionUpdates {
 public:
  void apply(EkfCore& filter, const RobotObservation& observation, const Eigen::Matrix2d& measurement_noise,
             const LocalizerOptions& options);
  std::vector<std::pair<std::string, double>> counters() const;

 private:
  long updates_ = 0;
  long rejected_ = 0;
};

// Global nearest neighbour: every (reading, candidate) pair in increasing squared Mahalanobis
// distance is accepted while both are still free and the distance is within `gate`. `d2` has one
// row per reading and one column per candidate (infinity where a pair is impossible).
struct NearestNeighbourAssociation {
  std::vector<int> match;             // per reading: the candidate, or -1
  std::vector<double> smallest_d2;    // per reading: the smallest distance to any candidate
};
NearestNeighbourAssociation associate_nearest_neighbour(const Eigen::MatrixXd& d2, double gate);

}  // namespace fleetmap::localization
