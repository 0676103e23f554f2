// `ekf-slam`: the pose and the point landmarks seen so far, estimated together by one extended
// Kalman filter (state X = [x y theta, l1x l1y, l2x l2y, ...]). Known landmarks in the context are
// not used: every landmark is learnt from the readings.
//
// Each update_landmarks call, at the predicted state x_{k|k-1}:
//  1. associates every reading with a landmark in the state, or marks it new, or rejects it:
//     - options.known_associations: by the reading's id (an id not in the state is new; a reading
//       without an id is rejected);
//     - otherwise: global nearest neighbour in Mahalanobis distance gated at
//       options.association_gate; an unmatched reading whose smallest distance to every landmark
//       exceeds the new_landmark_gate parameter is new, any other unmatched reading is rejected;
//  2. adds each new landmark with g(x, y) and the covariance augmentation of D'Alfonso et al. eq. (4),
//     with G_x and G_y evaluated at x_{k|k-1} and y_k as eq. (5) prescribes;
//  3. updates the state with each associated reading in turn.
// The state shrinks when the forget_after_steps parameter > 0: a landmark not observed for more
// than that many predict steps is removed (its rows and columns leave the covariance) at the
// next predict. Ids: the sensor's with known associations, otherwise 0, 1, 2, ... in order of
// creation (an id is never reused).
#include <Eigen/Core>

#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "localization/ekf_core.h"
#include "localization/ekf_models.h"
#include "localization/localizer.h"
#include "localization/localizers.h"

namespace fleetmap::localization {

namespace {

class EkfSlamLocalizer final : public Localizer {
 public:
  explicit EkfSlamLocalizer(const LocalizerContext& c)
      : options_((validate_options(c.options), c.options)),
        new_landmark_gate_(new_landmark_gate(c.options, c.params)),
        forget_after_steps_(int(c.params.number("forget_after_steps"))),
        q_(process_noise(c.options)),
        r_(measurement_noise(c.options)),
        filter_(c.initial_pose, initial_covariance(c.options)) {}

  std::string name() const override { return "ekf-slam"; }

  void predict(const Odometry& u) override {
    ++step_;
    forget_unseen();
    filter_.predict(u, q_);
  }

  void update_landmarks(const std::vector<LandmarkObservation>& observations) override {
    const std::vector<int> target = options_.known_associations ? associate_by_id(observations)
                                                                : associate_nearest(observations);
    // Step 2: new landmarks, at the predicted state (D'Alfonso et al., eq. (4)-(5)).
    for (std::size_t i = 0; i < observations.size(); ++i) {
      if (target[i] != kNew) continue;
      filter_.add_landmark({observations[i].range, observations[i].bearing}, r_);
      const int id = options_.known_associations ? observations[i].id : next_id_++;
      tracked_.push_back({id, step_});
      ++landmarks_added_;
    }
    // Step 3: the readings of landmarks already in the state.
    for (std::size_t i = 0; i < observations.size(); ++i) {
      if (target[i] == kNew) continue;
      if (target[i] == kReject) {
        ++rejected_associations_;
        continue;
      }
      const auto reading = filter_.predict_slot(target[i], r_);
      if (!reading) {
        ++rejected_associations_;
        continue;
      }
      filter_.update({observations[i].range, observations[i].bearing}, *reading);
      tracked_[static_cast<std::size_t>(target[i])].last_seen = step_;
      ++landmark_updates_;
    }
  }

  void update_robot(const RobotObservation& o) override { detections_.apply(filter_, o, r_, options_); }

  core::Pose2 pose() const override { return filter_.pose(); }
  Eigen::Matrix3d covariance() const override { return filter_.pose_covariance(); }
  void change_frame(const core::Transform2& t) override { filter_.change_frame(t); }

  std::vector<std::pair<std::string, double>> counters() const override {
    auto out = detections_.counters();
    out.insert(out.begin(), {{"landmark_updates", static_cast<double>(landmark_updates_)},
                             {"rejected_associations", static_cast<double>(rejected_associations_)}});
    out.insert(out.end(), {{"landmarks_in_state", static_cast<double>(filter_.landmark_count())},
                           {"landmarks_added", static_cast<double>(landmarks_added_)},
                           {"landmarks_removed", static_cast<double>(landmarks_removed_)}});
    return out;
  }

  bool estimates_landmarks() const override { return true; }
  std::vector<Landmark> landmark_estimates() const override {
    std::vector<Landmark> out;
    out.reserve(tracked_.size());
    for (int s = 0; s < filter_.landmark_count(); ++s) {
      out.push_back({tracked_[static_cast<std::size_t>(s)].id, filter_.landmark(s), filter_.landmark_covariance(s)});
    }
    return out;
  }

 private:
  static constexpr int kNew = -1;
  static constexpr int kReject = -2;

  struct Tracked {
    int id = 0;
    long last_seen = 0;  // the step of the last reading (or of creation)
  };

  // Per reading: a slot in the state, a slot that this call creates (a repeated new id), kNew or
  // kReject.
  std::vector<int> associate_by_id(const std::vector<LandmarkObservation>& observations) const {
    std::map<int, int> slot_of;
    for (std::size_t s = 0; s < tracked_.size(); ++s) slot_of.emplace(tracked_[s].id, static_cast<int>(s));
    int next_slot = filter_.landmark_count();
    std::vector<int> target(observations.size(), kReject);
    for (std::size_t i = 0; i < observations.size(); ++i) {
      const int id = observations[i].id;
      if (id < 0) continue;
      const auto [it, inserted] = slot_of.emplace(id, next_slot);
      if (inserted) {
        target[i] = kNew;
        ++next_slot;
      } else {
        target[i] = it->second;
      }
    }
    return target;
  }

  std::vector<int> associate_nearest(const std::vector<LandmarkObservation>& observations) const {
    const int slots = filter_.landmark_count();
    Eigen::MatrixXd d2(static_cast<Eigen::Index>(observations.size()), slots);
    for (int s = 0; s < slots; ++s) {
      const auto reading = filter_.predict_slot(s, r_);
      for (std::size_t i = 0; i < observations.size(); ++i) {
        d2(static_cast<Eigen::Index>(i), s) =
            reading ? EkfCore::mahalanobis2({observations[i].range, observations[i].bearing}, *reading)
                    : std::numeric_limits<double>::infinity();
      }
    }
    const NearestNeighbourAssociation a = associate_nearest_neighbour(d2, options_.association_gate);
    std::vector<int> target(observations.size(), kReject);
    for (std::size_t i = 0; i < observations.size(); ++i) {
      if (a.match[i] >= 0) {
        target[i] = a.match[i];
      } else if (a.smallest_d2[i] > new_landmark_gate_) {
        target[i] = kNew;
      }
    }
    return target;
  }

  void forget_unseen() {
    if (forget_after_steps_ <= 0) return;
    std::vector<int> drop;
    std::vector<Tracked> kept;
    for (std::size_t s = 0; s < tracked_.size(); ++s) {
      if (step_ - tracked_[s].last_seen > forget_after_steps_) {
        drop.push_back(static_cast<int>(s));
      } else {
        kept.push_back(tracked_[s]);
      }
    }
    if (drop.empty()) return;
    filter_.remove_landmarks(drop);
    tracked_ = std::move(kept);
    landmarks_removed_ += static_cast<long>(drop.size());
  }

  LocalizerOptions options_;
  double new_landmark_gate_;
  int forget_after_steps_;
  Eigen::Matrix3d q_;
  Eigen::Matrix2d r_;
  EkfCore filter_;
  std::vector<Tracked> tracked_;  // one per slot, in state order
  long step_ = 0;
  int next_id_ = 0;
  long landmark_updates_ = 0;
  long rejected_associations_ = 0;
  RobotDetectionUpdates detections_;
  long landmarks_added_ = 0;
  long landmarks_removed_ = 0;
};

}  // namespace

std::unique_ptr<Localizer> make_ekf_slam_localizer(const LocalizerContext& c) {
  return std::make_unique<EkfSlamLocalizer>(c);
}

}  // namespace fleetmap::localization
