#pragma once
// FastSLAM 2.0 for point landmarks (Montemerlo, Thrun, Koller & Wegbreit 2003): a particle filter
// over the robot's path in which every particle carries its own map, one small EKF (mean and 2x2
// covariance) per landmark. Unlike FastSLAM 1.0, a particle's new pose is drawn from a proposal
// that already includes the step's readings: the motion model's Gaussian, updated by an EKF step
// per reading of a landmark the particle knows (Montemerlo et al. 2003, eq. (11)-(12)); the
// particle's weight is the readings' likelihood under that Gaussian before the update
// (eq. (16)-(18): L = H_x P H_x^T + H_m Sigma H_m^T + R per reading, in sequence).
//
// Per step (predict, then update with the step's readings):
//  1. predict: each particle's pose mean moves by the motion model and its covariance grows by
//     F P F^T + Q; no sample is drawn yet (steps without readings accumulate);
//  2. update: per particle, associate the readings (the sensor's ids, or per-particle nearest
//     neighbour with a Mahalanobis gate), fold the known landmarks' readings into the pose
//     Gaussian and multiply the weight, draw the pose from the result, update the known landmarks'
//     EKFs at the drawn pose and add the new ones (g(x, z), covariance G_z R G_z^T);
//  3. resample (low variance) when the effective number of particles 1 / sum w^2 falls below
//     resample_threshold x particles (0.75, as in Bailey's FastSLAM 2.0 implementation).
// The map of the filter is either the maximum-weight particle's, or the combination of every
// particle's estimate of each landmark (the map-alignment paper, eq. (14)-(15)).
#include <Eigen/Core>

#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/random.h"
#include "core/transform2.h"
#include "localization/localizer.h"

namespace fleetmap::localization {

struct FastSlam2Options {
  int particles = 100;
  double resample_threshold = 0.75;  // resample when N_eff < this x particles
  Eigen::Matrix3d process_noise = Eigen::Matrix3d::Identity() * 1e-6;      // Q, additive on (x, y, theta)
  Eigen::Matrix2d measurement_noise = Eigen::Matrix2d::Identity() * 1e-4;  // R on (range, bearing)
  bool known_associations = true;
  double association_gate = 9.21;     // chi2(2) at 99%: a reading this close joins a landmark
  double new_landmark_gate = 27.63;   // farther than this from every landmark: a new one
};

// The map-alignment paper's two maps of a particle filter (§V.A, Table I).
enum class ParticleMap { MaxWeight, Combined };

struct FastSlam2Particle {
  core::Pose2 pose;  // the drawn pose, moved by the motion model since the last update
  // The pose's uncertainty accumulated by predictions since the pose was last drawn.
  Eigen::Matrix3d pose_covariance = Eigen::Matrix3d::Zero();
  double weight = 1.0;  // normalised over the particles
  // The weight that chose this particle: its ancestor's before the last resampling (equal weights
  // after resampling tell the particles apart no more).
  double selection_weight = 1.0;
  std::vector<Landmark> landmarks;  // the particle's map: one EKF per landmark
};

class FastSlam2 {
 public:
  // The particles start at poses drawn from N(initial_pose, initial_covariance) (all at
  // initial_pose when it is zero). Throws InputError for fewer than one particle or a threshold
  // outside (0, 1].
  FastSlam2(const core::Pose2& initial_pose, const Eigen::Matrix3d& initial_covariance, const FastSlam2Options& options,
            std::uint64_t seed);

  void predict(const Odometry& u);
  void update(const std::vector<LandmarkObservation>& observations);

  // The weighted mean pose (circular mean of the headings) and its covariance (the particles'
  // spread plus their mean accumulated covariance).
  core::Pose2 pose() const;
  Eigen::Matrix3d pose_covariance() const;
  // The pose that goes with map(which): the maximum-weight particle's, or the weighted mean.
  core::Pose2 pose(ParticleMap which) const;

  // The maximum-weight particle's landmarks, or eq. (14)-(15) of the map-alignment paper:
  // mu_i = sum_l w_l mu_i^[l], Sigma_i = sum_l w_l Sigma_i^[l] over the particles that hold landmark
  // i (weights renormalised over them). Landmarks are combined by id, so with unknown associations
  // (each particle numbers its own landmarks) the combined map is the maximum-weight particle's.
  std::vector<Landmark> map(ParticleMap which) const;

  const std::vector<FastSlam2Particle>& particles() const { return particles_; }
  double effective_particles() const;

  // Every particle's pose and landmarks re-expressed by x_new = new_from_old * x_old.
  void change_frame(const core::Transform2& new_from_old);

  long resamples() const { return resamples_; }
  long landmark_updates() const { return landmark_updates_; }
  long landmarks_added() const { return landmarks_added_; }
  long rejected_associations() const { return rejected_; }

 private:
  // Per reading of particle p: a landmark slot, kNew, or kReject.
  std::vector<int> associate(const FastSlam2Particle& p, const std::vector<LandmarkObservation>& observations);
  void update_particle(FastSlam2Particle& p, const std::vector<LandmarkObservation>& observations,
                       const std::vector<int>& target, double& log_weight);
  void resample();
  std::size_t best_particle() const;

  FastSlam2Options options_;
  core::Random random_;
  std::vector<FastSlam2Particle> particles_;
  // Known associations: every particle adds the same landmarks in the same order, so one table
  // gives the slot of an id in every particle.
  std::unordered_map<int, int> slot_of_id_;
  long resamples_ = 0;
  long landmark_updates_ = 0;
  long landmarks_added_ = 0;
  long rejected_ = 0;
};

// The filter of the registered `fastslam2` localizer, for experiments that measure both of its maps
// (the map-alignment paper, Table I). Throws Error for another localizer.
const FastSlam2& fastslam2_filter(const Localizer& localizer);

}  // namespace fleetmap::localization
