// `ekf`: the pose (x, y, theta) estimated by an extended Kalman filter from the differential-drive
// odometry and range-bearing readings of point landmarks at known positions (wave-algorithm paper, §V: fixed
// artificial landmarks, LocalizerContext::known_landmarks).
//
// Data association:
//  - options.known_associations: a reading belongs to the map landmark with the reading's id;
//    a reading without an id, or whose id is not in the map, is rejected.
//  - otherwise: global nearest neighbour in Mahalanobis distance over all map landmarks, at the
//    predicted pose, gated at options.association_gate (chi-square, 2 dof); a reading with no
//    landmark inside the gate is rejected.
// Rejected readings are counted in "rejected_associations".
#include <Eigen/Core>

#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "localization/ekf_core.h"
#include "localization/ekf_models.h"
#include "localization/localizer.h"
#include "localization/localizers.h"

namespace fleetmap::localization {

namespace {

class EkfLocalizer final : public Localizer {
 public:
  explicit EkfLocalizer(const LocalizerContext& c)
      : options_((validate_options(c.options), c.options)),
        q_(process_noise(c.options)),
        r_(measurement_noise(c.options)),
        filter_(c.initial_pose, initial_covariance(c.options)) {
    landmarks_.reserve(c.known_landmarks.size());
    for (const Landmark& l : c.known_landmarks) {
      if (!by_id_.emplace(l.id, landmarks_.size()).second) {
        throw InputError("localization: known landmark id " + std::to_string(l.id) + " appears twice");
      }
      landmarks_.push_back(l);
    }
  }

  std::string name() const override { return "ekf"; }

  void predict(const Odometry& u) override { filter_.predict(u, q_); }

  void update_landmarks(const std::vector<LandmarkObservation>& observations) override {
    const std::vector<int> match = associate(observations);
    for (std::size_t i = 0; i < observations.size(); ++i) {
      if (match[i] < 0) {
        ++rejected_associations_;
        continue;
      }
      const Landmark& l = landmarks_[static_cast<std::size_t>(match[i])];
      const auto reading = filter_.predict_point(l.position, l.covariance, r_);
      if (!reading) {
        ++rejected_associations_;
        continue;
      }
      filter_.update({observations[i].range, observations[i].bearing}, *reading);
      ++landmark_updates_;
    }
  }

  void update_robot(const RobotObservation& o) override { detections_.apply(filter_, o, r_, options_); }

  core::Pose2 pose() const override { return filter_.pose(); }
  Eigen::Matrix3d covariance() const override { return filter_.pose_covariance(); }
  // The known landmark map moves with the frame (the robot knows it in its own frame).
  void change_frame(const core::Transform2& t) override {
    filter_.change_frame(t);
    for (Landmark& l : landmarks_) {
      l.position = t.apply(l.position);
      l.covariance = t.rotation_matrix() * l.covariance * t.rotation_matrix().transpose();
    }
  }

  std::vector<std::pair<std::string, double>> counters() const override {
    auto out = detections_.counters();
    out.insert(out.begin(), {{"landmark_updates", static_cast<double>(landmark_updates_)},
                             {"rejected_associations", static_cast<double>(rejected_associations_)}});
    return out;
  }

 private:
  // Per observation: the index into landmarks_, or -1 when rejected.
  std::vector<int> associate(const std::vector<LandmarkObservation>& observations) const {
    std::vector<int> match(observations.size(), -1);
    if (options_.known_associations) {
      for (std::size_t i = 0; i < observations.size(); ++i) {
        const auto it = by_id_.find(observations[i].id);
        if (it != by_id_.end()) match[i] = static_cast<int>(it->second);
      }
      return match;
    }
    Eigen::MatrixXd d2(static_cast<Eigen::Index>(observations.size()), static_cast<Eigen::Index>(landmarks_.size()));
    for (std::size_t j = 0; j < landmarks_.size(); ++j) {
      const auto reading = filter_.predict_point(landmarks_[j].position, landmarks_[j].covariance, r_);
      for (std::size_t i = 0; i < observations.size(); ++i) {
        d2(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) =
            reading ? EkfCore::mahalanobis2({observations[i].range, observations[i].bearing}, *reading)
                    : std::numeric_limits<double>::infinity();
      }
    }
    return associate_nearest_neighbour(d2, options_.association_gate).match;
  }

  LocalizerOptions options_;
  Eigen::Matrix3d q_;
  Eigen::Matrix2d r_;
  EkfCore filter_;
  std::vector<Landmark> landmarks_;
  std::map<int, std::size_t> by_id_;
  long landmark_updates_ = 0;
  long rejected_associations_ = 0;
  RobotDetectionUpdates detections_;
};

}  // namespace

std::unique_ptr<Localizer> make_ekf_localizer(const LocalizerContext& c) { return std::make_unique<EkfLocalizer>(c); }

}  // namespace fleetmap::localization
