// Over 500 lines on purpose: D'Alfonso et al.'s §3.1 (extraction, the three association cases,
// Q_bad refits, clusters) and §3.3 (merging) act on one filter state and its landmark bookkeeping;
// split across files, each part would need the others' private helpers. The reading model and the
// fit's Jacobians (eq. (2), (5)) are free functions at the top and tested on their own.
#include "localization/polynomial_slam.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/angle.h"
#include "core/error.h"
#include "localization/metrics.h"

namespace fleetmap::localization {

// A point a new polynomial is fitted to, with what its position depends on (for G_x, G_y).
struct PolynomialSlam::SourcePoint {
  enum class Kind {
    Measured,    // pi of eq. (3): moves with the pose (lever arm from `observer`) and its reading (`beam`)
    OnLandmark,  // sampled on landmark `slot`: moves with that landmark's c_0 along `shift`
    Received,    // on a received curve: moves with the pose (the rendezvous transform uses it, §3.2)
                 // and by a displacement common to its `group`, of variance `variance`
  };
  Kind kind = Kind::Measured;
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double weight = 1.0;
  Eigen::Vector2d observer = Eigen::Vector2d::Zero();
  Eigen::Vector2d beam = Eigen::Vector2d::UnitX();
  long step = 0;                      // Measured: the step it was read at
  int slot = -1;                      // OnLandmark: the landmark's index
  Eigen::Vector2d shift = Eigen::Vector2d::Zero();
  Eigen::VectorXd basis;              // OnLandmark: d position / d the landmark's entries, along `shift`
  int group = -1;
  double variance = 0.0;
  double angle_variance = 0.0;

  // A point measured by the laser (eq. (3)), as the map keeps it.
  static SourcePoint measured(const mapping::MapPoint& q) {
    SourcePoint s;
    s.position = q.position;
    s.weight = q.weight;
    s.observer = q.observer;
    s.beam = q.beam;
    s.step = q.step;
    return s;
  }
};

void validate(const PolynomialSlamOptions& o) {
  const auto fail = [](const std::string& key, const std::string& expected, double value) {
    throw InputError("polynomial SLAM option '" + key + "': expected " + expected + ", got " + std::to_string(value));
  };
  if (o.order < 1 || o.order > 9) fail("order", "an integer in [1, 9]", o.order);
  if (!(o.rho_min > 0.0)) fail("rho_min", "a positive number", o.rho_min);
  if (!(o.rho_max >= o.rho_min)) fail("rho_max", "a number >= rho_min", o.rho_max);
  if (!(o.sigma_min >= o.rho_min)) fail("sigma_min", "a number >= rho_min", o.sigma_min);
  if (!(o.sigma_max >= o.sigma_min) || !(o.sigma_max >= o.rho_max)) fail("sigma_max", "a number >= sigma_min and >= rho_max", o.sigma_max);
  if (o.epsilon_m < 1) fail("epsilon_m", "an integer >= 1", o.epsilon_m);
  if (o.epsilon_z < o.order) fail("epsilon_z", "an integer >= the order", o.epsilon_z);
  if (!(o.k > 0.0)) fail("k", "a positive number", o.k);
  if (!(o.cluster_radius > 0.0)) fail("cluster_radius", "a positive number", o.cluster_radius);
  if (!(o.gamma_m > 0.0)) fail("gamma_m", "a positive number", o.gamma_m);
  if (!(o.range_noise >= 0.0)) fail("range_noise", "a number >= 0", o.range_noise);
  if (!(o.min_overlap > 0.0 && o.min_overlap <= 1.0)) fail("min_overlap", "a number in (0, 1]", o.min_overlap);
  if (!(o.merge_max_angle > 0.0)) fail("merge_max_angle", "a positive angle", o.merge_max_angle);
  if (!(o.min_merge_length >= 0.0) || !std::isfinite(o.min_merge_length)) fail("min_merge_length", "a finite number >= 0", o.min_merge_length);
  if (!(o.innovation_gate > 0.0)) fail("innovation_gate", "a positive number", o.innovation_gate);
  if (!(o.min_incidence_cos >= 0.0 && o.min_incidence_cos < 1.0)) fail("min_incidence_cos", "a number in [0, 1)", o.min_incidence_cos);
  if (!std::isfinite(o.domain_margin)) fail("domain_margin", "a finite number", o.domain_margin);
  if (!(o.cluster_tolerance > 0.0)) fail("cluster_tolerance", "a positive number", o.cluster_tolerance);
  if (!(o.feature_noise >= 0.0) || !std::isfinite(o.feature_noise)) fail("feature_noise", "a finite number >= 0", o.feature_noise);
}

std::vector<core::ParamSpec> polynomial_slam_params() {
  using core::ParamSpec;
  const PolynomialSlamOptions d;
  const core::Range metres{1e-6, 100.0};
  const core::Range count{1, 100000, true};
  return {
      ParamSpec::number("order", d.order, {1, 9, true}, "", "m, the polynomials' highest order (§4)"),
      ParamSpec::number("rho_min", d.rho_min, metres, "m", "rho underbar: a reading this close to a polynomial is good (Q_good) when P is small (§3.1)"),
      ParamSpec::number("rho_max", d.rho_max, metres, "m", "rho bar: the same threshold when P has grown to K P0"),
      ParamSpec::number("sigma_min", d.sigma_min, metres, "m", "beyond rho and within this a reading is bad (Q_bad); farther, a new cluster point"),
      ParamSpec::number("sigma_max", d.sigma_max, metres, "m", "the same threshold when P has grown to K P0"),
      ParamSpec::number("epsilon_m", d.epsilon_m, count, "points", "bad points that trigger a refit; points per polynomial kept for refits and merges"),
      ParamSpec::number("epsilon_z", d.epsilon_z, count, "points", "cluster points that make a new polynomial (at least the order)"),
      ParamSpec::number("k", d.k, {1e-9, 1e12}, "", "K: the thresholds grow from their minimum to their maximum as P goes from 0 to K P0"),
      ParamSpec::number("cluster_radius", d.cluster_radius, metres, "m", "R: a point this close to a cluster joins it"),
      ParamSpec::number("gamma_m", d.gamma_m, {1e-9, 100.0}, "m", "gamma_m: two polynomials' curves this close are one wall, merged"),
      ParamSpec::number("min_overlap", d.min_overlap, {1e-6, 1.0}, "", "share of the shorter polynomial two must overlap to merge (Fig. 3(b))"),
      ParamSpec::number("merge_max_angle_deg", core::rad2deg(d.merge_max_angle), {1e-6, 90.0}, "deg", "tangents in the overlap may differ at most this for a merge"),
      ParamSpec::number("min_merge_length", d.min_merge_length, {0.0, 100.0}, "m", "a polynomial shorter than this is not merged (0: any length, as the paper)"),
      ParamSpec::number("innovation_gate", d.innovation_gate, {1e-9, 1e12}, "", "a reading farther than this (squared Mahalanobis) from its prediction is not used"),
      ParamSpec::number("min_incidence_cos", d.min_incidence_cos, {0.0, 0.999}, "", "an axis meeting a curve at a cosine below this to its normal is not used"),
      ParamSpec::number("domain_margin", d.domain_margin, {-10.0, 10.0}, "m", "an axis may meet a polynomial this far beyond its ends (< 0: not near them)"),
      ParamSpec::number("cluster_tolerance", d.cluster_tolerance, {1e-6, 10.0}, "m", "a cluster becomes a polynomial only when the fit leaves no point farther than this"),
      ParamSpec::flag("shape_noise", d.shape_noise, "the fixed shape's uncertainty is added to each reading's noise (false: the sensor's alone)"),
      ParamSpec::flag("lowest_order", d.lowest_order, "a new polynomial takes the lowest order that fits as well as order m (false: always m, as the paper)"),
      ParamSpec::flag("shape_in_state", d.shape_in_state, "each polynomial's shape is in the state with its c_0, so that readings correct it (false: c_0 only, as the paper)"),
      ParamSpec::flag("first_estimate_jacobians", d.first_estimate_jacobians, "Jacobians at first estimates (Huang et al. 2008), so that the filter does not become overconfident"),
      ParamSpec::number("feature_noise", d.feature_noise, {0.0, 1.0}, "m^2", "process noise on each landmark's entries per step (0: walls do not move)"),
  };
}

PolynomialSlamOptions polynomial_slam_options(const core::Params& p, double range_noise) {
  PolynomialSlamOptions o;
  o.order = int(p.number("order"));
  o.rho_min = p.number("rho_min");
  o.rho_max = p.number("rho_max");
  o.sigma_min = p.number("sigma_min");
  o.sigma_max = p.number("sigma_max");
  o.epsilon_m = int(p.number("epsilon_m"));
  o.epsilon_z = int(p.number("epsilon_z"));
  o.k = p.number("k");
  o.cluster_radius = p.number("cluster_radius");
  o.gamma_m = p.number("gamma_m");
  o.min_overlap = p.number("min_overlap");
  o.merge_max_angle = core::deg2rad(p.number("merge_max_angle_deg"));
  o.min_merge_length = p.number("min_merge_length");
  o.innovation_gate = p.number("innovation_gate");
  o.min_incidence_cos = p.number("min_incidence_cos");
  o.domain_margin = p.number("domain_margin");
  o.cluster_tolerance = p.number("cluster_tolerance");
  o.shape_noise = p.flag("shape_noise");
  o.lowest_order = p.flag("lowest_order");
  o.shape_in_state = p.flag("shape_in_state");
  o.first_estimate_jacobians = p.flag("first_estimate_jacobians");
  o.feature_noise = p.number("feature_noise");
  o.range_noise = range_noise;
  try {
    validate(o);
  } catch (const InputError& e) {
    throw InputError(p.owner() + ": " + e.what());
  }
  return o;
}

Eigen::VectorXd ShapeBasis::at(double xi) const {
  Eigen::VectorXd b(size);
  const double t = (xi - centre) / scale;
  double power = 1.0;
  for (int j = 0; j < size; ++j, power *= t) b(j) = power;
  return b;
}

mapping::Polynomial polynomial_from_entries(const mapping::Polynomial& reference, const ShapeBasis& basis,
                                            const Eigen::VectorXd& entries) {
  mapping::Polynomial p = reference;
  p.position = entries(0);
  const int m = p.order();
  // sum_j a_j ((xi - c) / s)^j = sum_l xi^l sum_{j >= l} a_j C(j, l) (-c)^(j - l) / s^j.
  for (int j = 1; j < basis.size && j < entries.size(); ++j) {
    const double aj = entries(j) / std::pow(basis.scale, j);
    double binom = 1.0;  // C(j, l) for l = j, j - 1, ...
    double shift = 1.0;  // (-c)^(j - l)
    for (int l = j; l >= 0; --l) {
      const double d = aj * binom * shift;
      if (l == 0) {
        p.position += d;
      } else if (l <= m) {
        p.shape[std::size_t(m - l)] += d;
      }
      binom = binom * double(l) / double(j - l + 1);
      shift *= -basis.centre;
    }
  }
  return p;
}

std::optional<ScalarReading> range_reading(const mapping::Polynomial& reference, const ShapeBasis& basis,
                                           const Eigen::VectorXd& entries, int first_slot, const core::Pose2& pose,
                                           double sensor_angle, double max_distance, double domain_margin,
                                           double* cos_incidence) {
  const mapping::Polynomial p = polynomial_from_entries(reference, basis, entries);
  const auto hit = mapping::intersect_ray(p, pose.position(), pose.theta + sensor_angle, max_distance, domain_margin);
  if (!hit) return std::nullopt;
  ScalarReading r;
  r.predicted = hit->distance;
  r.h_pose << hit->d_origin.x(), hit->d_origin.y(), hit->d_angle;
  r.slot = first_slot;
  r.h_slot = hit->d_position;
  // dF / d a_j = t^j where F = p(xi) - eta: dh / d a_j = t^j dh / d c_0.
  const Eigen::VectorXd b = basis.at(hit->xi);
  for (int j = 1; j < basis.size; ++j) r.h_more.emplace_back(first_slot + j, hit->d_position * b(j));
  if (cos_incidence) *cos_incidence = hit->cos_incidence;
  return r;
}

std::vector<Eigen::MatrixXd> fit_gradient(const mapping::Polynomial& polynomial, const ShapeBasis& basis,
                                          const std::vector<mapping::WeightedPoint>& points) {
  // beta = (A^T W A)^-1 A^T W eta with A_k = basis.at(xi_k)^T: d beta / d eta_k = N^-1 A_k^T w_k,
  // and a shift d xi_k moves the residual eta_k - p(xi_k) as an eta shift of -p'(xi_k) d xi_k.
  Eigen::MatrixXd n = Eigen::MatrixXd::Zero(basis.size, basis.size);
  std::vector<Eigen::VectorXd> rows;
  rows.reserve(points.size());
  for (const auto& q : points) {
    rows.push_back(basis.at(polynomial.local(q.position).x()));
    n += q.weight * rows.back() * rows.back().transpose();
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(n);
  std::vector<Eigen::MatrixXd> out;
  out.reserve(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) {
    const double xi = polynomial.local(points[k].position).x();
    const Eigen::VectorXd m = ldlt.solve(points[k].weight * rows[k]);
    const Eigen::Vector2d direction = polynomial.world(Eigen::Vector2d(-polynomial.slope(xi), 1.0));
    out.push_back(m * direction.transpose());
  }
  return out;
}

namespace {

double spectral_norm(const Eigen::Matrix3d& m) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (m + m.transpose()), Eigen::EigenvaluesOnly);
  return eig.eigenvalues().cwiseAbs().maxCoeff();
}

Eigen::Vector2d perp(const Eigen::Vector2d& v) { return {-v.y(), v.x()}; }

// Readings below this standard deviation are treated as this, so that a noise-free sensor still
// gives a positive innovation variance.
constexpr double kMinRangeStd = 1e-6;

}  // namespace

SlamThresholds slam_thresholds(const Eigen::Matrix3d& p, const Eigen::Matrix3d& p0, const PolynomialSlamOptions& o) {
  const Eigen::Matrix3d kp0 = o.k * p0;
  const double n = spectral_norm(kp0);
  SlamThresholds t;
  t.factor = n > 0.0 ? std::clamp((n - spectral_norm(kp0 - p)) / n, 0.0, 1.0) : 1.0;
  t.diverging = is_diverging(p, o.k, p0);
  if (t.diverging) t.factor = 1.0;
  t.rho = o.rho_min + (o.rho_max - o.rho_min) * t.factor;
  t.sigma = o.sigma_min + (o.sigma_max - o.sigma_min) * t.factor;
  return t;
}

PolynomialSlam::PolynomialSlam(const core::Pose2& initial_pose, const Eigen::Matrix3d& initial_covariance,
                               const Eigen::Matrix3d& process_noise, const PolynomialSlamOptions& options)
    : options_((validate(options), options)),
      initial_covariance_(initial_covariance),
      process_noise_(process_noise),
      filter_(initial_pose, initial_covariance),
      last_predicted_(initial_pose.position()) {
  thresholds_ = slam_thresholds(initial_covariance, initial_covariance, options_);
}

void PolynomialSlam::predict(const Odometry& u) {
  ++step_;
  if (options_.first_estimate_jacobians) {
    filter_.predict(u, process_noise_, last_predicted_);
  } else {
    filter_.predict(u, process_noise_);
  }
  last_predicted_ = filter_.pose().position();
  if (options_.feature_noise > 0.0) {
    for (int s = 0; s < filter_.slots(); ++s) filter_.add_noise(s, options_.feature_noise);
  }
}

int PolynomialSlam::first_slot(int landmark) const {
  int slot = 0;
  for (int i = 0; i < landmark; ++i) slot += bases_[std::size_t(i)].basis.size;
  return slot;
}

Eigen::VectorXd PolynomialSlam::entries(int index) const {
  const int first = first_slot(index);
  return filter_.mean().segment(3 + first, bases_[std::size_t(index)].basis.size);
}

mapping::Polynomial PolynomialSlam::current(int index) const {
  const LandmarkState& l = bases_[std::size_t(index)];
  return polynomial_from_entries(l.reference, l.basis, entries(index));
}

void PolynomialSlam::sync_positions() {
  for (std::size_t i = 0; i < map_.landmarks.size(); ++i) map_.landmarks[i].polynomial = current(int(i));
}

void PolynomialSlam::update(const std::vector<double>& angles, const std::vector<std::optional<double>>& ranges) {
  if (angles.size() != ranges.size()) throw Error("PolynomialSlam::update: one range per angle expected");
  ++counters_.steps;
  const Eigen::Matrix3d p_pred = filter_.pose_covariance();
  thresholds_ = slam_thresholds(p_pred, initial_covariance_, options_);
  if (thresholds_.diverging) ++counters_.diverged_steps;
  const double weight = 1.0 / std::max(spectral_norm(p_pred), 1e-12);  // D'Alfonso et al. §3.3: 1 / ||P_k|k-1||
  const core::Pose2 x = filter_.pose();

  // Association (§3.1), every reading at the predicted pose.
  std::vector<std::pair<std::size_t, long>> good;  // (reading, landmark id)
  for (std::size_t i = 0; i < angles.size(); ++i) {
    if (!ranges[i]) continue;
    const double a = x.theta + angles[i];
    mapping::MapPoint point;
    point.beam = Eigen::Vector2d(std::cos(a), std::sin(a));
    point.position = x.position() + *ranges[i] * point.beam;  // eq. (3)
    point.weight = weight;
    point.observer = x.position();
    point.step = step_;
    const auto best = map_.best_approximation(point.position);
    if (best.index >= 0 && best.error <= thresholds_.rho) {
      ++counters_.good_points;
      good.emplace_back(i, map_.landmarks[std::size_t(best.index)].id);
    } else if (best.index >= 0 && best.error <= thresholds_.sigma) {
      ++counters_.bad_points;
      auto& bad = map_.landmarks[std::size_t(best.index)].bad_points;
      bad.push_back(point);
      if (int(bad.size()) > options_.epsilon_m) refit(best.index);
    } else {
      ++counters_.cluster_points;
      add_to_cluster(point);
    }
  }

  // The update (eq. (2)), one scalar reading at a time, each linearised at the latest estimate.
  const double r = std::pow(std::max(options_.range_noise, kMinRangeStd), 2);
  for (const auto& [i, id] : good) {
    const int index = map_.index_of(id);
    if (index < 0) continue;  // replaced by a refit or a merge in this step
    const core::Pose2 now = filter_.pose();
    const double y = *ranges[i];
    const LandmarkState& state = bases_[std::size_t(index)];
    double cos_incidence = 0.0;
    auto model = range_reading(state.reference, state.basis, entries(index), first_slot(index), now, angles[i],
                               y + options_.sigma_max + 1.0, options_.domain_margin, &cos_incidence);
    if (!model || cos_incidence < options_.min_incidence_cos) {
      ++counters_.rejected_readings;
      continue;
    }
    ScalarReading& reading = *model;
    reading.noise = r;
    if (options_.shape_noise && !options_.shape_in_state) {
      // The shape's own uncertainty at the point read: a shift along the independent axis moves
      // the curve by -p' delta, a turn phi about the domain's middle by ((xi - xc) + p' (p - p_c)) phi.
      const mapping::Polynomial p = current(index);
      const auto& landmark = map_.landmarks[std::size_t(index)];
      const Eigen::Vector2d at = p.local(now.position() + reading.predicted * Eigen::Vector2d(std::cos(now.theta + angles[i]), std::sin(now.theta + angles[i])));
      const double d = p.slope(at.x()), xc = 0.5 * (p.lo + p.hi);
      const double lever = (at.x() - xc) + d * (p.value(at.x()) - p.value(xc));
      reading.noise += reading.h_slot * reading.h_slot *
                       (d * d * landmark.along_variance + lever * lever * landmark.angle_variance);
    }
    // The reading at any state: the same landmark and axis, with this reading's noise.
    const double noise = reading.noise;
    const int first = first_slot(index), size = state.basis.size;
    const double bearing = angles[i];  // a structured binding cannot be captured (clang 14)
    // First-estimate Jacobians: at the predicted pose and the landmark's entries when it was made
    // (the reading's value, and whether the axis meets the curve, stay the current estimate's).
    // When the axis from the predicted pose misses the first estimate there is no such Jacobian;
    // the current estimate's would bring the spurious information back, so the reading is not used.
    std::optional<ScalarReading> first_estimate;
    if (options_.first_estimate_jacobians) {
      first_estimate = range_reading(state.reference, state.basis, state.first, first, x, bearing,
                                     y + options_.sigma_max + 1.0, options_.domain_margin);
      if (!first_estimate) {
        ++counters_.rejected_readings;
        continue;
      }
    }
    const auto at = [&, first, size, noise, bearing](const Eigen::VectorXd& x) -> std::optional<ScalarReading> {
      auto m = range_reading(state.reference, state.basis, x.segment(3 + first, size), first,
                             core::Pose2(x(0), x(1), x(2)), bearing, y + options_.sigma_max + 1.0,
                             options_.domain_margin);
      if (!m) return m;
      m->noise = noise;
      if (first_estimate) {
        m->h_pose = first_estimate->h_pose;
        m->h_slot = first_estimate->h_slot;
        m->h_more = first_estimate->h_more;
      }
      return m;
    };
    const auto outcome = filter_.update(y, at, options_.innovation_gate);
    if (outcome != PolynomialEkf::UpdateOutcome::Updated) {
      ++counters_.rejected_readings;
      continue;
    }
    ++counters_.updates;
  }
  sync_positions();
}

std::optional<long> PolynomialSlam::add_landmark(const std::vector<SourcePoint>& points, int received_from,
                                                 double max_residual) {
  std::vector<mapping::WeightedPoint> weighted;
  weighted.reserve(points.size());
  for (const auto& p : points) weighted.push_back({p.position, p.weight});
  const mapping::PolynomialAxis axis = mapping::principal_axis(weighted);
  auto fit = mapping::fit_polynomial(weighted, options_.order, axis);
  if (!fit || !(fit->max_residual <= max_residual)) return std::nullopt;
  int fit_order = options_.order;
  if (options_.lowest_order) {
    // The lowest order whose residuals the readings' noise explains (chi-square test at 95%, V the
    // sensor's variance), or whose fit explains the points as well as order m does (weighted RMS
    // residual at most order m's plus half a reading's standard deviation). A higher order than
    // the noise needs only fits the noise: points that do not spread along the boundary (one spot
    // read again and again while the robot drives along the beam, range noise spreading them
    // along it) give a curve bent along the beam, with a shape no later reading supports and a
    // covariance (linearised at that shape) far too small.
    const double enough = fit->rms_residual + 0.5 * options_.range_noise;
    const double v = std::pow(std::max(options_.range_noise, kMinRangeStd), 2);
    const auto noise_explains = [&](const mapping::PolynomialFit& f, int order) {
      const int dof = int(weighted.size()) - order - 1;
      if (dof < 1) return false;
      double sum = 0.0;
      for (const auto& q : weighted) {
        const Eigen::Vector2d l = f.polynomial.local(q.position);
        sum += std::pow(l.y() - f.polynomial.value(l.x()), 2);
      }
      return sum / v <= chi_square_quantile(dof, 0.95);
    };
    for (int order = 1; order < options_.order; ++order) {
      auto lower = mapping::fit_polynomial(weighted, order, axis);
      if (lower && (lower->rms_residual <= enough || noise_explains(*lower, order)) &&
          lower->max_residual <= max_residual) {
        // Kept as an order-m polynomial whose leading coefficients are zero.
        lower->polynomial.shape.insert(lower->polynomial.shape.begin(), std::size_t(options_.order - order), 0.0);
        fit = std::move(lower);
        fit_order = order;
        break;
      }
    }
  }
  // A least-squares cubic through points bunched at two places can swing far between them (a
  // refit of Q_bad points beyond p's end with R on p, say); such a polynomial maps nothing seen.
  if (mapping::stray_between_points(fit->polynomial, weighted) > options_.sigma_max) return std::nullopt;

  // D'Alfonso et al. eq. (5): the gradient of the new entries g(X, y) (c0, and the shape when it is in
  // the state) with respect to the pose, the source landmarks' entries and the readings, at x_k|k-1
  // and y_k. Every point is a function of the current pose: one read k steps ago moved with the
  // pose since (lever arm from the current position), plus the process noise of those k steps.
  const mapping::Polynomial& shape = fit->polynomial;
  ShapeBasis basis;
  basis.centre = 0.5 * (shape.lo + shape.hi);
  basis.scale = std::max(0.5 * (shape.hi - shape.lo), 1e-3);
  basis.size = options_.shape_in_state ? fit_order + 1 : 1;
  const int k = basis.size;
  const std::vector<Eigen::MatrixXd> grad = fit_gradient(shape, basis, weighted);
  const core::Pose2 x_now = filter_.pose();
  const Eigen::Vector2d dependent = shape.dependent_direction();
  BlockGeneration g;
  g.value = Eigen::VectorXd::Zero(k);
  g.value(0) = shape.position;
  g.g_pose = Eigen::MatrixXd::Zero(k, 3);
  g.noise = Eigen::MatrixXd::Zero(k, k);
  const double r = std::pow(std::max(options_.range_noise, kMinRangeStd), 2);
  std::vector<std::pair<int, Eigen::MatrixXd>> by_age;     // (steps since read, sum of d g / d pose of those points)
  std::vector<std::pair<int, Eigen::VectorXd>> slot_grad;  // (slot, d g / d X_slot)
  struct Group {
    int id;
    Eigen::VectorXd shift, turn;
    Eigen::Vector2d centroid;
    int count;
    double variance, angle_variance;
  };
  std::vector<Group> groups;
  for (const auto& p : points) {
    if (p.kind != SourcePoint::Kind::Received) continue;
    auto it = std::find_if(groups.begin(), groups.end(), [&](const Group& gr) { return gr.id == p.group; });
    if (it == groups.end()) {
      groups.push_back({p.group, Eigen::VectorXd::Zero(k), Eigen::VectorXd::Zero(k), Eigen::Vector2d::Zero(), 0,
                        p.variance, p.angle_variance});
      it = groups.end() - 1;
    }
    it->centroid += p.position;
    ++it->count;
  }
  for (auto& gr : groups) gr.centroid /= double(gr.count);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const SourcePoint& p = points[i];
    const Eigen::MatrixXd& gk = grad[i];  // k x 2
    switch (p.kind) {
      case SourcePoint::Kind::Measured: {
        // pi = observer + y u, moved with the pose: d pi / d(x, y, theta) = [I | perp(pi - x_now)], d pi / d y = u.
        Eigen::MatrixXd dp(k, 3);
        dp << gk, gk * perp(p.position - x_now.position());
        g.g_pose += dp;
        const Eigen::VectorXd gu = gk * p.beam;
        g.noise += r * gu * gu.transpose();
        const int age = int(std::max(0L, step_ - p.step));
        if (age > 0) {
          auto it = std::find_if(by_age.begin(), by_age.end(), [&](const auto& a) { return a.first == age; });
          if (it == by_age.end()) {
            by_age.emplace_back(age, dp);
          } else {
            it->second += dp;
          }
        }
        break;
      }
      case SourcePoint::Kind::OnLandmark: {
        const int first = first_slot(p.slot);
        const Eigen::VectorXd along = gk * p.shift;
        for (int j = 0; j < int(p.basis.size()); ++j) {
          const int slot = first + j;
          auto it = std::find_if(slot_grad.begin(), slot_grad.end(), [&](const auto& s) { return s.first == slot; });
          if (it == slot_grad.end()) {
            slot_grad.emplace_back(slot, along * p.basis(j));
          } else {
            it->second += along * p.basis(j);
          }
        }
        break;
      }
      case SourcePoint::Kind::Received: {
        Eigen::MatrixXd dp(k, 3);
        dp << gk, gk * perp(p.position - x_now.position());
        g.g_pose += dp;
        auto it = std::find_if(groups.begin(), groups.end(), [&](const Group& gr) { return gr.id == p.group; });
        it->shift += gk * dependent;
        it->turn += gk * perp(p.position - it->centroid);
        break;
      }
    }
  }
  // The process noise of the steps between a point's reading and now: the noise of step now - j
  // moves every point read j or more steps ago (each step's noise independent).
  std::sort(by_age.begin(), by_age.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  Eigen::MatrixXd older = Eigen::MatrixXd::Zero(k, 3);
  for (std::size_t i = 0; i < by_age.size(); ++i) {
    older += by_age[i].second;
    const int steps = by_age[i].first - (i + 1 < by_age.size() ? by_age[i + 1].first : 0);
    g.noise += double(steps) * older * process_noise_ * older.transpose();
  }
  for (const auto& gr : groups) {
    g.noise += gr.variance * gr.shift * gr.shift.transpose() + gr.angle_variance * gr.turn * gr.turn.transpose();
  }
  g.g_slots = std::move(slot_grad);
  filter_.augment(g);
  mapping::PolynomialLandmark landmark;
  landmark.id = next_id_++;
  landmark.polynomial = fit->polynomial;
  landmark.received_from = received_from;
  bases_.push_back({fit->polynomial, basis, g.value});
  // The shape's uncertainty (options.shape_noise): the least of its sources'. Points computed from
  // the pose carry the pose's variance along the curve and in heading, plus the fit's slope variance.
  {
    const Eigen::Vector2d along = shape.world(Eigen::Vector2d(1.0, 0.0));
    const Eigen::Matrix3d pose = filter_.pose_covariance();
    const double pose_along = along.dot(pose.topLeftCorner<2, 2>() * along);
    double mean = 0.0, spread = 0.0;
    for (const auto& p : points) mean += shape.local(p.position).x();
    mean /= double(points.size());
    for (const auto& p : points) spread += std::pow(shape.local(p.position).x() - mean, 2);
    const double slope_variance = spread > 0.0 ? r / spread : 0.0;
    landmark.along_variance = landmark.angle_variance = std::numeric_limits<double>::infinity();
    const auto take = [&](double a, double b) {
      landmark.along_variance = std::min(landmark.along_variance, a);
      landmark.angle_variance = std::min(landmark.angle_variance, b);
    };
    for (const auto& p : points) {
      switch (p.kind) {
        case SourcePoint::Kind::Measured: take(pose_along, pose(2, 2) + slope_variance); break;
        case SourcePoint::Kind::OnLandmark: {
          const auto& source = map_.landmarks[std::size_t(p.slot)];
          take(source.along_variance, source.angle_variance);
          break;
        }
        case SourcePoint::Kind::Received: take(p.variance + pose_along, p.angle_variance + pose(2, 2)); break;
      }
    }
  }
  map_.landmarks.push_back(std::move(landmark));
  return map_.landmarks.back().id;
}

void PolynomialSlam::remove_landmarks(std::vector<int> indices) {
  std::sort(indices.begin(), indices.end());
  indices.erase(std::unique(indices.begin(), indices.end()), indices.end());
  std::vector<int> slots;
  for (int i : indices) {
    const int first = first_slot(i);
    for (int j = 0; j < bases_[std::size_t(i)].basis.size; ++j) slots.push_back(first + j);
  }
  filter_.remove(slots);
  for (auto it = indices.rbegin(); it != indices.rend(); ++it) {
    map_.landmarks.erase(map_.landmarks.begin() + *it);
    bases_.erase(bases_.begin() + *it);
  }
}

std::vector<PolynomialSlam::SourcePoint> PolynomialSlam::samples_of(int index, int count) const {
  const mapping::Polynomial p = current(index);
  const double weight = 1.0 / std::max(position_variance(index), 1e-12);  // §3.3
  const ShapeBasis& basis = bases_[std::size_t(index)].basis;
  std::vector<SourcePoint> out;
  for (const auto& q : mapping::sample_equally(p, count)) {
    SourcePoint s;
    s.kind = SourcePoint::Kind::OnLandmark;
    s.position = q;
    s.weight = weight;
    s.slot = index;
    s.shift = p.dependent_direction();
    s.basis = basis.at(p.local(q).x());
    out.push_back(s);
  }
  return out;
}

void PolynomialSlam::refit(int index) {
  // §3.1: R = epsilon_M equally spaced points on p*, fitted with Q_bad(p*); the new polynomial
  // replaces p*. The refit is always accepted, as the paper has it.
  std::vector<SourcePoint> points = samples_of(index, options_.epsilon_m);
  for (const auto& b : map_.landmarks[std::size_t(index)].bad_points) points.push_back(SourcePoint::measured(b));
  const auto id = add_landmark(points, -1, std::numeric_limits<double>::infinity());
  if (!id) {
    map_.landmarks[std::size_t(index)].bad_points.clear();
    return;
  }
  ++counters_.refits;
  remove_landmarks({index});
  merge_new(*id);
}

void PolynomialSlam::add_to_cluster(const mapping::MapPoint& point) {
  const int c = map_.densest_cluster(point.position, options_.cluster_radius);
  if (c < 0) {
    map_.clusters.push_back({{point}});
    return;
  }
  auto& cluster = map_.clusters[std::size_t(c)].points;
  cluster.push_back(point);
  if (int(cluster.size()) <= options_.epsilon_z) return;
  std::vector<SourcePoint> points;
  for (const auto& q : cluster) points.push_back(SourcePoint::measured(q));
  // A cluster whose points no polynomial approximates within sigma_k (e.g. one bent round a
  // corner) is not turned into one; its oldest point leaves it, so it slides along the boundary
  // until its points agree (a choice: the paper does not say).
  const auto id = add_landmark(points, -1, options_.cluster_tolerance);
  if (!id) {
    cluster.erase(cluster.begin());
    return;
  }
  ++counters_.polynomials_created;
  map_.clusters.erase(map_.clusters.begin() + c);
  merge_new(*id);
}

void PolynomialSlam::merge_new(long id) {
  // §3.3, Fig. 3: a new landmark p is merged with a landmark p2 when they overlap enough (p inside
  // p2, p2 inside p, or a sufficiently large common region) and the m + 1 points Q_0..Q_m equally
  // spaced on p in the overlap are approximated by p2 with gamma < gamma_M. The merged polynomial
  // is the weighted LMS fit of epsilon_M points on each; it is merged again, until no merge applies.
  for (;;) {
    const int i = map_.index_of(id);
    if (i < 0) return;
    const mapping::Polynomial p = current(i);
    const double p_len = p.length();
    int best = -1;
    double best_gamma = std::numeric_limits<double>::infinity();
    for (int j = 0; j < int(map_.landmarks.size()); ++j) {
      if (j == i) continue;
      const mapping::Polynomial p2 = current(j);
      const auto ov = mapping::overlap(p, p2);
      if (!ov) continue;
      const double shorter = std::min(p_len, p2.length());
      if (!(ov->length >= options_.min_overlap * shorter)) continue;
      if (mapping::tangent_angle(p, 0.5 * (ov->lo + ov->hi), p2) > options_.merge_max_angle) continue;
      if (shorter < options_.min_merge_length) continue;
      const double gamma = mapping::rms_residual(p2, mapping::sample_equally(p, ov->lo, ov->hi, options_.order + 1));
      if (gamma < options_.gamma_m && gamma < best_gamma) best = j, best_gamma = gamma;
    }
    if (best < 0) return;
    std::vector<SourcePoint> points = samples_of(i, options_.epsilon_m);
    const std::vector<SourcePoint> more = samples_of(best, options_.epsilon_m);
    points.insert(points.end(), more.begin(), more.end());
    const int from = map_.landmarks[std::size_t(i)].received_from;
    const int from_other = map_.landmarks[std::size_t(best)].received_from;
    // The merged polynomial must still approximate both within sigma_k (a choice: two pieces that
    // one m-th order polynomial cannot follow stay apart).
    const auto merged = add_landmark(points, from == from_other ? from : -1, thresholds_.sigma);
    if (!merged) return;
    ++counters_.merges;
    remove_landmarks({i, best});
    id = *merged;
  }
}

int PolynomialSlam::integrate_received(const std::vector<ReceivedCurve>& curves) {
  const core::Pose2 x = filter_.pose();
  int added = 0;
  int group = 0;
  for (const auto& curve : curves) {
    if (curve.polyline.size() < 2) continue;
    // Points every 2 cm along the polyline, at least 2 (m + 1).
    double length = 0.0;
    for (std::size_t k = 1; k < curve.polyline.size(); ++k) length += (curve.polyline[k] - curve.polyline[k - 1]).norm();
    const int n = std::max(2 * (options_.order + 1), int(std::ceil(length / 0.02)) + 1);
    std::vector<SourcePoint> points;
    const double variance = std::max(curve.variance, 1e-12);
    std::size_t seg = 1;
    double seg_start = 0.0;
    for (int k = 0; k < n; ++k) {
      const double s = length * double(k) / double(n - 1);
      while (seg + 1 < curve.polyline.size() &&
             seg_start + (curve.polyline[seg] - curve.polyline[seg - 1]).norm() < s) {
        seg_start += (curve.polyline[seg] - curve.polyline[seg - 1]).norm();
        ++seg;
      }
      const Eigen::Vector2d a = curve.polyline[seg - 1], b = curve.polyline[seg];
      const double len = (b - a).norm();
      const double f = len > 0.0 ? std::clamp((s - seg_start) / len, 0.0, 1.0) : 0.0;
      SourcePoint p;
      p.kind = SourcePoint::Kind::Received;
      p.position = a + f * (b - a);
      p.weight = 1.0 / variance;
      p.observer = x.position();
      p.group = group;
      p.variance = variance;
      p.angle_variance = curve.angle_variance;
      points.push_back(p);
    }
    ++group;
    const auto id = add_landmark(points, curve.from_robot, std::numeric_limits<double>::infinity());
    if (!id) continue;
    ++added;
    ++counters_.received;
    merge_new(*id);
  }
  sync_positions();
  return added;
}

void PolynomialSlam::change_frame(const core::Transform2& t) {
  const Eigen::Matrix2d rot = t.rotation_matrix();
  const int old_slots = filter_.slots();
  std::vector<Eigen::VectorXd> values;
  std::vector<Eigen::MatrixXd> blocks;  // d new entries / d old entries, per landmark
  for (int i = 0; i < int(map_.landmarks.size()); ++i) {
    const mapping::Polynomial old = current(i);
    const ShapeBasis& old_basis = bases_[std::size_t(i)].basis;
    // Points every 2 cm (at least 4 (m + 1)) on the old curve, moved; the refit follows them to
    // far below the sensor noise for the smooth, short curves a map holds. With the shape in the
    // state the refit keeps the landmark's order (a turned line is a line).
    const int count = std::max(4 * (options_.order + 1), int(std::ceil(old.length() / 0.02)) + 1);
    std::vector<mapping::WeightedPoint> moved;
    std::vector<double> old_xi;
    for (const auto& q : mapping::sample_equally(old, count)) {
      moved.push_back({t * q, 1.0});
      old_xi.push_back(old.local(q).x());
    }
    std::optional<mapping::PolynomialFit> fit;
    int order = options_.shape_in_state && old_basis.size > 1 ? old_basis.size - 1 : options_.order;
    for (; order >= 1 && !fit; --order) fit = mapping::fit_polynomial(moved, order, mapping::principal_axis(moved));
    if (!fit) throw Error("PolynomialSlam::change_frame: a polynomial could not be refitted in the new frame");
    ++order;
    fit->polynomial.shape.insert(fit->polynomial.shape.begin(), std::size_t(options_.order - order), 0.0);
    ShapeBasis basis;
    basis.centre = 0.5 * (fit->polynomial.lo + fit->polynomial.hi);
    basis.scale = std::max(0.5 * (fit->polynomial.hi - fit->polynomial.lo), 1e-3);
    basis.size = options_.shape_in_state && old_basis.size > 1 ? order + 1 : 1;
    // An old entry e_j moves the old curve by basis_j(xi) along its dependent axis, each moved
    // point by basis_j(xi_k) R e_old, and the refit's entries by sum_k G_k R e_old basis_j(xi_k).
    const Eigen::Vector2d shift = rot * old.dependent_direction();
    const std::vector<Eigen::MatrixXd> grad = fit_gradient(fit->polynomial, basis, moved);
    Eigen::MatrixXd block = Eigen::MatrixXd::Zero(basis.size, old_basis.size);
    for (std::size_t k = 0; k < moved.size(); ++k) block += (grad[k] * shift) * old_basis.at(old_xi[k]).transpose();
    Eigen::VectorXd value = Eigen::VectorXd::Zero(basis.size);
    value(0) = fit->polynomial.position;
    auto& landmark = map_.landmarks[std::size_t(i)];
    landmark.polynomial = fit->polynomial;
    bases_[std::size_t(i)] = {fit->polynomial, basis, value};
    for (auto& b : landmark.bad_points) {
      b.position = t * b.position;
      b.observer = t * b.observer;
      b.beam = rot * b.beam;
    }
    values.push_back(std::move(value));
    blocks.push_back(std::move(block));
  }
  for (auto& cluster : map_.clusters) {
    for (auto& q : cluster.points) {
      q.position = t * q.position;
      q.observer = t * q.observer;
      q.beam = rot * q.beam;
    }
  }
  int new_slots = 0;
  for (const auto& v : values) new_slots += int(v.size());
  Eigen::VectorXd all_values(new_slots);
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(new_slots, old_slots);
  for (std::size_t i = 0, row = 0, col = 0; i < values.size(); ++i) {
    all_values.segment(Eigen::Index(row), values[i].size()) = values[i];
    jacobian.block(Eigen::Index(row), Eigen::Index(col), blocks[i].rows(), blocks[i].cols()) = blocks[i];
    row += std::size_t(blocks[i].rows());
    col += std::size_t(blocks[i].cols());
  }
  filter_.change_frame(t, all_values, jacobian);
  last_predicted_ = t * last_predicted_;
  sync_positions();
}

}  // namespace fleetmap::localization
