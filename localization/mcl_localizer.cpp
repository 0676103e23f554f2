// `mcl`: Monte Carlo localization on a known map (León et al., §IV, eq. (12)-(17); Thrun, Burgard &
// Fox, Probabilistic Robotics §8.3), and its collaborative form (eq. (15)).
//  - belief: particles (pose, weight); a Gaussian around the start (tracking) or uniform over the
//    known map's free cells (global localization, LocalizerContext::global_localization);
//  - motion model (eq. (14)): each particle moves by the odometry plus noise that grows with the
//    motion, at least the process noise;
//  - perceptual model (eq. (13), (17)): the likelihood field of the known map, over a subset of the
//    beams, its spread annealed from 0.5 m to the sensor's as the belief converges, tempered to kIndependentBeams effectively independent beams; particles in cells the map
//    does not know as free are nearly ruled out;
//  - detection model (eq. (15)): when robot m detects this robot n with range r and bearing b, the
//    integral of p(x_n | x_m, r) Bel_m(x_m) is approximated by a Gaussian: the position
//    x_m + r (cos, sin)(theta_m + b) with the detector's covariance propagated through it, plus
//    the detection noise; every particle's weight is multiplied by it. A detection says nothing
//    of this robot's heading, and a finite particle set may hold no particle near the detected
//    position: when the detection is much sharper than the belief, half of the particles are
//    drawn anew from it with uniform headings (sensor resetting, Lenser & Veloso 2000);
//  - selective resampling (low variance) when N_eff < N / 2.
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/angle.h"
#include "core/error.h"
#include "core/random.h"
#include "localization/likelihood_field.h"
#include "localization/localizer.h"
#include "localization/localizers.h"
#include "localization/scan_matcher.h"

namespace fleetmap::localization {

namespace {

constexpr double kIndependentBeams = 10.0;
constexpr int kMaxBeams = 36;
constexpr double kMinDetectionSigma = 0.1;  // m: detections are no sharper than this

class MclLocalizer final : public Localizer {
 public:
  explicit MclLocalizer(const LocalizerContext& c) : options_(c.options), rng_(c.seed), map_(c.known_map) {
    if (!map_) throw InputError("localization 'mcl' needs the known map (merging: known)");
    const std::size_t n = std::size_t(c.params.number("particles"));  // declared >= 1
    const auto& g = map_->geometry();
    for (int i = 0; i < g.width() * g.height(); ++i) {
      if (map_->state_at(i) == mapping::CellState::Free) free_cells_.push_back(i);
    }
    if (free_cells_.empty()) throw InputError("localization 'mcl': the known map has no free cell");
    poses_.resize(n);
    log_w_.assign(n, -std::log(double(n)));
    if (c.global_localization) {
      for (auto& p : poses_) p = uniform_pose();
    } else {
      const double sxy = std::max(c.options.initial_xy, 0.01), sth = std::max(c.options.initial_theta, 0.005);
      for (auto& p : poses_) {
        p = {c.initial_pose.x + rng_.normal(0.0, sxy), c.initial_pose.y + rng_.normal(0.0, sxy),
             core::normalize_angle(c.initial_pose.theta + rng_.normal(0.0, sth))};
      }
    }
  }

  std::string name() const override { return "mcl"; }
  bool uses_scans() const override { return true; }

  void predict(const Odometry& u) override {
    const double dist = std::abs(u.v * u.dt), turn = std::abs(u.omega * u.dt);
    const double sxy = std::max(options_.process_noise_xy, 0.01 + 0.05 * dist);
    const double sth = std::max(options_.process_noise_theta, 0.005 + 0.05 * turn + 0.01 * dist);
    for (auto& p : poses_) {
      const core::Pose2 next = integrate_motion(p, u);
      p = {next.x + rng_.normal(0.0, sxy), next.y + rng_.normal(0.0, sxy),
           core::normalize_angle(next.theta + rng_.normal(0.0, sth))};
    }
  }

  void update_scan(const RangeScan& scan, const mapping::OccupancyGrid& /*own_map: MCL uses the known map*/) override {
    if (fields_.empty()) {
      // Coarse to fine: a broad field while the belief is spread (so that particles far from the
      // truth still see a gradient), the sensor's own spread once it has converged (annealing).
      for (double sigma : {0.5, 0.25, std::max(0.1, 2.0 * options_.range_noise)}) {
        LikelihoodFieldOptions f;
        f.sigma_m = sigma;
        f.max_distance_m = std::max(1.0, 3.0 * sigma);
        f.max_range_m = scan.max_range;
        fields_.push_back({sigma, LikelihoodField::of_grid(*map_, {0, 0, map_->width(), map_->height()}, f)});
      }
    }
    const Eigen::Matrix3d spread = covariance();
    const double belief_sigma = std::sqrt(std::max(spread(0, 0), spread(1, 1)));
    const LikelihoodField* field = &fields_.front().second;
    for (const auto& [sigma, f] : fields_) {
      if (sigma >= 0.5 * belief_sigma) field = &f;
    }
    int returns = 0;
    for (const auto& r : scan.ranges) returns += r.has_value();
    const auto points = scan_end_points(scan, std::max(1, (returns + kMaxBeams - 1) / kMaxBeams));
    if (points.empty()) return;
    const double gain = std::min(1.0, kIndependentBeams / double(points.size()));
    const auto& g = map_->geometry();
    for (std::size_t k = 0; k < poses_.size(); ++k) {
      const core::Pose2& p = poses_[k];
      const auto cell = g.world_to_cell(p.position());
      if (!cell || map_->state(*cell) != mapping::CellState::Free) {
        log_w_[k] += std::log(1e-6);
        continue;
      }
      double s = 0.0;
      for (const auto& q : points) s += field->log_likelihood_nearest(g.world_to_grid(p.transform(q)));
      log_w_[k] += gain * s;
    }
    normalize_and_resample();
  }

  void update_detected_by(const DetectedBy& d) override {
    // The detected position and its covariance (first-order propagation of the detector's belief).
    const double a = d.detector_pose.theta + d.bearing;
    const Eigen::Vector2d dir(std::cos(a), std::sin(a)), normal(-std::sin(a), std::cos(a));
    const Eigen::Vector2d mu = d.detector_pose.position() + d.range * dir;
    Eigen::Matrix<double, 2, 3> j;
    j << 1, 0, -d.range * std::sin(a), 0, 1, d.range * std::cos(a);
    Eigen::Matrix2d cov = j * d.detector_covariance * j.transpose();
    cov += d.range_noise * d.range_noise * dir * dir.transpose() +
           (d.range * d.bearing_noise) * (d.range * d.bearing_noise) * normal * normal.transpose();
    cov += kMinDetectionSigma * kMinDetectionSigma * Eigen::Matrix2d::Identity();
    const Eigen::Matrix2d info = cov.inverse();
    for (std::size_t k = 0; k < poses_.size(); ++k) {
      const Eigen::Vector2d e = poses_[k].position() - mu;
      log_w_[k] += -0.5 * e.dot(info * e);
    }
    ++detections_used_;
    // Sensor resetting when the detection is much sharper than this robot's own belief.
    const Eigen::Matrix3d belief = covariance();
    if (cov.trace() < 0.25 * belief.topLeftCorner<2, 2>().trace()) {
      const Eigen::Matrix2d l = cov.llt().matrixL();
      // The new particles weigh as much as an old one at the same place would.
      const double base = -std::log(double(poses_.size()));
      for (std::size_t k = 0; k < poses_.size(); k += 2) {
        const Eigen::Vector2d z(rng_.normal(0.0, 1.0), rng_.normal(0.0, 1.0));
        const Eigen::Vector2d p = mu + l * z;
        poses_[k] = {p.x(), p.y(), rng_.uniform(-std::numbers::pi, std::numbers::pi)};
        log_w_[k] = base - 0.5 * z.squaredNorm();
      }
      ++resets_;
    }
    normalize_and_resample();
  }

  core::Pose2 pose() const override {
    double x = 0, y = 0, c = 0, s = 0;
    for (std::size_t k = 0; k < poses_.size(); ++k) {
      const double w = std::exp(log_w_[k]);
      x += w * poses_[k].x;
      y += w * poses_[k].y;
      c += w * std::cos(poses_[k].theta);
      s += w * std::sin(poses_[k].theta);
    }
    return {x, y, std::atan2(s, c)};
  }

  Eigen::Matrix3d covariance() const override {
    const core::Pose2 m = pose();
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (std::size_t k = 0; k < poses_.size(); ++k) {
      const Eigen::Vector3d d(poses_[k].x - m.x, poses_[k].y - m.y, core::normalize_angle(poses_[k].theta - m.theta));
      cov += std::exp(log_w_[k]) * d * d.transpose();
    }
    return cov;
  }

  std::vector<std::pair<std::string, double>> counters() const override {
    return {{"particles", double(poses_.size())},
            {"resamplings", double(resamplings_)},
            {"robot_detections_used", double(detections_used_)},
            {"detection_resets", double(resets_)}};
  }

 private:
  core::Pose2 uniform_pose() {
    const auto& g = map_->geometry();
    const Cell c = g.cell_of_index(free_cells_[std::size_t(rng_.uniform_int(0, int(free_cells_.size()) - 1))]);
    const Eigen::Vector2d p = g.grid_to_world({c.x + rng_.uniform(), c.y + rng_.uniform()});
    return {p.x(), p.y(), rng_.uniform(-std::numbers::pi, std::numbers::pi)};
  }

  void normalize_and_resample() {
    const double top = *std::max_element(log_w_.begin(), log_w_.end());
    double sum = 0.0;
    for (double& l : log_w_) sum += std::exp(l -= top);
    double sum2 = 0.0;
    for (double& l : log_w_) sum2 += std::exp(2.0 * (l -= std::log(sum)));
    if (1.0 / sum2 >= 0.5 * double(poses_.size())) return;
    const std::size_t n = poses_.size();
    std::vector<core::Pose2> next;
    next.reserve(n);
    const double step = 1.0 / double(n);
    double u = rng_.uniform(0.0, step), c = std::exp(log_w_[0]);
    std::size_t i = 0;
    for (std::size_t k = 0; k < n; ++k, u += step) {
      while (u > c && i + 1 < n) c += std::exp(log_w_[++i]);
      next.push_back(poses_[i]);
    }
    poses_ = std::move(next);
    log_w_.assign(n, -std::log(double(n)));
    ++resamplings_;
  }

  using Cell = core::Cell;
  LocalizerOptions options_;
  core::Random rng_;
  std::shared_ptr<const mapping::OccupancyGrid> map_;
  std::vector<int> free_cells_;
  std::vector<core::Pose2> poses_;
  std::vector<double> log_w_;
  std::vector<std::pair<double, LikelihoodField>> fields_;  // (sigma, field), broad first
  int resamplings_ = 0, detections_used_ = 0, resets_ = 0;
};

}  // namespace

std::unique_ptr<Localizer> make_mcl_localizer(const LocalizerContext& c) { return std::make_unique<MclLocalizer>(c); }

}  // namespace fleetmap::localization
