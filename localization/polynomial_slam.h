#pragma once
// D'Alfonso et al.'s single-robot polynomial SLAM (§3.1, §3.3) and the merging of polynomials received
// from another robot (§3.2-3.3). Each step, at the predicted pose x_k|k-1:
//  1. the points pi_k^i of eq. (3) from the distance sensors' readings y_k;
//  2. for each point, the best approximating polynomial p* and its error eps (Fig. 2), and one of
//     three cases with thresholds rho_k, sigma_k adapted from ||P_k|k-1||:
//       eps <= rho_k: a good reading of p*;
//       rho_k < eps <= sigma_k: the point joins Q_bad(p*); past epsilon_M points p* is refitted by
//         weighted LMS on Q_bad(p*) and epsilon_M points R sampled on p*, and replaced;
//       eps > sigma_k: the point joins the cluster with most points within R of it (or a new one);
//         past epsilon_Z points the cluster becomes a new polynomial;
//     every new polynomial enters the state by eq. (4)-(5) and is merged with an overlapping one
//     when Fig. 3's test passes (gamma < gamma_M);
//  3. the EKF update with each good reading: h is the distance along the sensor's axis to p* (eq. (2)).
// The divergence test P_k|k-1 > K P0 is counted (the filter carries on, with the thresholds at
// their maxima).
#include <Eigen/Core>

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/params.h"
#include "core/transform2.h"
#include "localization/localizer.h"
#include "localization/polynomial_ekf.h"
#include "mapping/polynomial_map.h"

namespace fleetmap::localization {

struct PolynomialSlamOptions {
  // D'Alfonso et al. §4's parameters.
  int order = 3;                  // m
  double rho_min = 0.08;          // m, rho underbar
  double rho_max = 0.24;          // m, rho bar
  double sigma_min = 0.10;        // m
  double sigma_max = 0.30;        // m
  int epsilon_m = 5;              // Q_bad points that trigger a refit; points per polynomial in R and in a merge
  int epsilon_z = 10;             // cluster points that make a new polynomial
  double k = 150.0;               // K: the thresholds vary over 0 <= P_k|k-1 <= K P0
  double cluster_radius = 0.35;   // R, m
  double gamma_m = 0.35;          // m
  double range_noise = 0.02;      // m, standard deviation of a distance reading (V)
  // Choices where the paper is silent (README "Polynomial SLAM", what differs).
  double min_overlap = 0.3;       // Fig. 3(b)'s "sufficiently large" overlap, as a share of the shorter polynomial
  double merge_max_angle = 0.5235987755982988;  // rad (30 deg): tangents in the overlap may differ at most this
  // Fig. 3's "sufficiently large" overlap in absolute terms: a polynomial shorter than this (m) is not
  // merged. A few centimetres of curve (often one spot read again and again) have a shape no reading
  // supports, and a merge with them pulls the longer one. 0: any length, as the paper.
  double min_merge_length = 0.0;
  double innovation_gate = 3.84;  // chi2(1) at 95%: a reading farther from h is not used
  double min_incidence_cos = 0.2;  // an axis meeting a curve beyond ~78 deg from its normal is not used
  double domain_margin = 0.0;      // m: an axis may meet a polynomial this far beyond its ends (< 0: not near them)
  // A cluster becomes a polynomial only when the fit leaves none of its points farther than this
  // (3 standard deviations of the distance readings); otherwise its oldest point leaves it, so that
  // a cluster spanning a corner slides along the boundary until its points agree.
  double cluster_tolerance = 0.06;  // m
  // The shape (b_m..b_1) is not in the state, as in the paper; its uncertainty (the pose's along
  // the curve and in heading when the curve was made, and the fit's slope) is added to V of each
  // reading of it, so that the fixed shape does not pin the pose. False: V is the sensor's alone.
  bool shape_noise = true;
  // A new polynomial takes the lowest order (1..m) whose fit is as good as order m's within the
  // noise (its leading coefficients zero): a cubic fitted to a short, noisy piece of a straight
  // wall has a wrong slope and curvature that the filter, holding the shape fixed, cannot correct.
  // False: always order m, as the paper.
  bool lowest_order = true;
  // D'Alfonso et al. keep the shape b_m..b_1 out of the state (a "shape landmark" of the extraction
  // step only). True: each landmark's shape is in the state with its c_0, as corrections
  // a_1..a_q to the polynomial in the centred, scaled variable t = (xi - centre) / scale of its
  // domain when it was made (q its order: a line has c_0 and a_1), so that readings correct a
  // wrong shape and its error is shared by all readings of it; `shape_noise` is then not used.
  bool shape_in_state = false;
  // Process noise on each landmark's entries per step (m^2): the walls do not move, so 0; more
  // lets the filter follow a boundary an m-th order polynomial cannot follow exactly.
  double feature_noise = 0.0;
  // First-estimate Jacobians (Huang, Mourikis & Roumeliotis 2008): a reading's Jacobians are
  // evaluated at the step's predicted pose x_k|k-1 and at its landmark's entries as they were when
  // it entered the state (its first estimate), and the motion's at the predicted positions
  // (p_k+1|k - p_k|k-1), while its innovation uses the current estimate. Linearised at estimates
  // that move, the EKF gains information along the unobservable global translation and rotation
  // and becomes overconfident; with first estimates it keeps those directions unobservable.
  bool first_estimate_jacobians = false;
};

// A landmark's state block (options.shape_in_state): `size` entries, c_0 and a_1..a_{size-1} in
// t = (xi - centre) / scale; without the shape in the state, size 1 (c_0 alone).
struct ShapeBasis {
  double centre = 0.0;
  double scale = 1.0;
  int size = 1;
  // [1, t, t^2, ..., t^(size-1)] at xi: d p(xi) / d entries.
  Eigen::VectorXd at(double xi) const;
};

// The polynomial whose entries are `entries` (c_0, a_1, ...): reference's shape plus
// sum_j a_j t^j, expanded to monomials, its c_0 replaced (a uniform shift).
mapping::Polynomial polynomial_from_entries(const mapping::Polynomial& reference, const ShapeBasis& basis,
                                            const Eigen::VectorXd& entries);

// The reading model h of eq. (2) for one sensor axis (world angle `angle` from `pose`'s position)
// and one landmark held as `entries` in slots first_slot.. : the distance, dh/d pose and dh/d each
// entry (reading.slot = first_slot for c_0, h_more for the shape). nullopt when the axis misses it.
std::optional<ScalarReading> range_reading(const mapping::Polynomial& reference, const ShapeBasis& basis,
                                           const Eigen::VectorXd& entries, int first_slot, const core::Pose2& pose,
                                           double sensor_angle, double max_distance, double domain_margin,
                                           double* cos_incidence = nullptr);

// The landmark generation function's gradient (D'Alfonso et al., eq. (5)) for a weighted LMS fit:
// d (c_0, a_1..a_{size-1}) / d pi_k (size x 2, world frame) of the fit through `points`, at the
// fitted `polynomial` (Gauss-Newton: the residuals' own change is left out). With size 1 it is
// mapping::position_gradient (the shape held fixed).
std::vector<Eigen::MatrixXd> fit_gradient(const mapping::Polynomial& polynomial, const ShapeBasis& basis,
                                          const std::vector<mapping::WeightedPoint>& points);

// Throws InputError naming the option for a value the algorithm cannot use.
void validate(const PolynomialSlamOptions& options);

// The options a user sets, as declared parameters (core/params.h) of the `polynomial` localizer and
// of `fleetmap slam`'s `polynomial` method; the defaults are PolynomialSlamOptions'. The merge angle
// is given in degrees (`merge_max_angle_deg`).
std::vector<core::ParamSpec> polynomial_slam_params();
// The options those parameters give, with the distance readings' noise V from the caller (the
// sensor's). Throws InputError as validate() for values that do not fit together (rho_max < rho_min).
PolynomialSlamOptions polynomial_slam_options(const core::Params& params, double range_noise);

// The thresholds of one step (§3.1): rho_k = rho_min + (rho_max - rho_min) f,
// sigma_k = sigma_min + (sigma_max - sigma_min) f, f = (||K P0|| - ||K P0 - P||) / ||K P0||
// clamped to [0, 1], with ||.|| the spectral norm.
struct SlamThresholds {
  double rho = 0.0;
  double sigma = 0.0;
  double factor = 0.0;
  bool diverging = false;  // P_k|k-1 > K P0
};
SlamThresholds slam_thresholds(const Eigen::Matrix3d& predicted_covariance, const Eigen::Matrix3d& initial_covariance,
                               const PolynomialSlamOptions& options);

// A curve received from another robot (§3.2): a polyline already in this robot's frame R_j,0,
// and the variance of its points' common displacement (transform and sender uncertainty), m^2.
struct ReceivedCurve {
  std::vector<Eigen::Vector2d> polyline;
  double variance = 0.0;        // m^2
  double angle_variance = 0.0;  // rad^2, of its orientation
  int from_robot = -1;
};

struct PolynomialSlamCounters {
  long steps = 0;
  long good_points = 0;       // eps <= rho
  long bad_points = 0;        // rho < eps <= sigma (into Q_bad)
  long cluster_points = 0;    // eps > sigma
  long updates = 0;           // EKF updates made
  long rejected_readings = 0;  // good points whose axis misses p*, grazes it, or fails the gate
  long polynomials_created = 0;  // from clusters
  long refits = 0;
  long merges = 0;
  long received = 0;          // received curves turned into polynomials
  long diverged_steps = 0;
};

class PolynomialSlam {
 public:
  PolynomialSlam(const core::Pose2& initial_pose, const Eigen::Matrix3d& initial_covariance,
                 const Eigen::Matrix3d& process_noise, const PolynomialSlamOptions& options);

  void predict(const Odometry& u);
  // One step of extraction, association and update with the readings of the distance sensors at
  // `angles` (robot frame); a reading without a return is skipped.
  void update(const std::vector<double>& angles, const std::vector<std::optional<double>>& ranges);
  // Turns each curve into a polynomial (weighted LMS on points along it), adds it to the state
  // and merges it into the map (§3.3). Returns the number of polynomials added.
  int integrate_received(const std::vector<ReceivedCurve>& curves);
  // Re-expresses pose, map and covariance in another frame (x_new = new_from_old * x_old). A turned
  // polynomial is no polynomial (§3.2): each is refitted to points sampled on it and moved, and its
  // c_0's rows and columns of the covariance scale by d c0_new / d c0_old.
  void change_frame(const core::Transform2& new_from_old);

  core::Pose2 pose() const { return filter_.pose(); }
  Eigen::Matrix3d pose_covariance() const { return filter_.pose_covariance(); }
  // The map; each landmark's c_0 is the filter's current estimate.
  const mapping::PolynomialMap& map() const { return map_; }
  // The variance of landmark i's c_0 (i indexes map().landmarks).
  double position_variance(int landmark) const { return filter_.position_variance(first_slot(landmark)); }
  // The filter slot of landmark i's c_0 (its shape, when in the state, follows).
  int first_slot(int landmark) const;
  const ShapeBasis& basis(int landmark) const { return bases_[std::size_t(landmark)].basis; }
  const PolynomialEkf& filter() const { return filter_; }
  const SlamThresholds& thresholds() const { return thresholds_; }
  const PolynomialSlamCounters& counters() const { return counters_; }
  const PolynomialSlamOptions& options() const { return options_; }
  long step() const { return step_; }

 private:
  struct SourcePoint;
  std::optional<long> add_landmark(const std::vector<SourcePoint>& points, int received_from, double max_residual);
  void remove_landmarks(std::vector<int> indices);
  void refit(int index);
  void add_to_cluster(const mapping::MapPoint& point);
  void merge_new(long id);
  std::vector<SourcePoint> samples_of(int index, int count) const;
  mapping::Polynomial current(int index) const;
  Eigen::VectorXd entries(int index) const;
  void sync_positions();

  struct LandmarkState {
    mapping::Polynomial reference;  // the fit it was made from
    ShapeBasis basis;
    Eigen::VectorXd first;          // its entries when it entered the state (first-estimate Jacobians)
  };

  PolynomialSlamOptions options_;
  Eigen::Matrix3d initial_covariance_;
  Eigen::Matrix3d process_noise_;
  PolynomialEkf filter_;
  mapping::PolynomialMap map_;  // landmark i <-> filter slots first_slot(i) ..
  std::vector<LandmarkState> bases_;  // one per landmark
  SlamThresholds thresholds_;
  PolynomialSlamCounters counters_;
  long step_ = 0;
  long next_id_ = 0;
  Eigen::Vector2d last_predicted_;  // p_k|k-1 of the latest prediction (x_0|0 before the first)
};

}  // namespace fleetmap::localization
