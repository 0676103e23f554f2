#include "localization/fastslam2.h"

#include <Eigen/Cholesky>
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <string>

#include "core/angle.h"
#include "core/error.h"
#include "localization/ekf_core.h"
#include "localization/ekf_models.h"
#include "localization/localizers.h"

namespace fleetmap::localization {

namespace {

constexpr int kNew = -1;
constexpr int kReject = -2;

Eigen::Vector2d innovation(const Eigen::Vector2d& z, const Eigen::Vector2d& predicted) {
  return {z(0) - predicted(0), core::normalize_angle(z(1) - predicted(1))};
}

// log N(nu; 0, S) for a 2-vector.
double log_gaussian(const Eigen::Vector2d& nu, const Eigen::Matrix2d& s) {
  return -0.5 * nu.dot(s.ldlt().solve(nu)) - 0.5 * std::log(s.determinant()) - std::log(2.0 * std::numbers::pi);
}

// A draw from N(mean, covariance) for a 3x3 covariance that may be singular.
Eigen::Vector3d draw(const Eigen::Vector3d& mean, const Eigen::Matrix3d& covariance, core::Random& random) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (covariance + covariance.transpose()));
  Eigen::Vector3d z;
  for (int k = 0; k < 3; ++k) z(k) = random.normal(0.0, std::sqrt(std::max(0.0, eig.eigenvalues()(k))));
  return mean + eig.eigenvectors() * z;
}

Eigen::Vector3d as_vector(const core::Pose2& p) { return {p.x, p.y, p.theta}; }

}  // namespace

FastSlam2::FastSlam2(const core::Pose2& initial_pose, const Eigen::Matrix3d& initial_covariance,
                     const FastSlam2Options& options, std::uint64_t seed)
    : options_(options), random_(seed) {
  if (options.particles < 1) throw InputError("fastslam2: particles must be at least 1, got " + std::to_string(options.particles));
  if (!(options.resample_threshold > 0.0 && options.resample_threshold <= 1.0)) {
    throw InputError("fastslam2: resample_threshold must be in (0, 1], got " + std::to_string(options.resample_threshold));
  }
  particles_.resize(std::size_t(options.particles));
  const double w = 1.0 / options.particles;
  for (auto& p : particles_) {
    const Eigen::Vector3d x = draw(as_vector(initial_pose), initial_covariance, random_);
    p.pose = core::Pose2(x(0), x(1), core::normalize_angle(x(2)));
    p.weight = p.selection_weight = w;
  }
}

void FastSlam2::predict(const Odometry& u) {
  for (auto& p : particles_) {
    const Eigen::Matrix3d f = motion_jacobian(p.pose, u);
    p.pose = integrate_motion(p.pose, u);
    p.pose_covariance = f * p.pose_covariance * f.transpose() + options_.process_noise;
  }
}

std::vector<int> FastSlam2::associate(const FastSlam2Particle& p, const std::vector<LandmarkObservation>& observations) {
  std::vector<int> target(observations.size(), kReject);
  if (options_.known_associations) {
    // Ids new in this step get their slots in reading order, the same in every particle; a second
    // reading of a new id in the same step is rejected.
    std::vector<int> fresh;
    for (std::size_t i = 0; i < observations.size(); ++i) {
      const int id = observations[i].id;
      if (id < 0) continue;
      if (const auto it = slot_of_id_.find(id); it != slot_of_id_.end()) {
        target[i] = it->second;
      } else if (std::find(fresh.begin(), fresh.end(), id) == fresh.end()) {
        fresh.push_back(id);
        target[i] = kNew;
      }
    }
    return target;
  }
  const int slots = int(p.landmarks.size());
  Eigen::MatrixXd d2(Eigen::Index(observations.size()), slots);
  for (int s = 0; s < slots; ++s) {
    const Landmark& l = p.landmarks[std::size_t(s)];
    const Eigen::Vector2d predicted = range_bearing(p.pose, l.position);
    if (!(predicted(0) > 0.0)) {
      d2.col(s).setConstant(std::numeric_limits<double>::infinity());
      continue;
    }
    const RangeBearingJacobians h = range_bearing_jacobians(p.pose, l.position);
    const Eigen::Matrix2d s_cov = h.pose * p.pose_covariance * h.pose.transpose() +
                                  h.point * l.covariance * h.point.transpose() + options_.measurement_noise;
    const Eigen::LDLT<Eigen::Matrix2d> ldlt(s_cov);
    for (std::size_t i = 0; i < observations.size(); ++i) {
      const Eigen::Vector2d nu = innovation({observations[i].range, observations[i].bearing}, predicted);
      d2(Eigen::Index(i), s) = nu.dot(ldlt.solve(nu));
    }
  }
  const NearestNeighbourAssociation a = associate_nearest_neighbour(d2, options_.association_gate);
  for (std::size_t i = 0; i < observations.size(); ++i) {
    if (a.match[i] >= 0) {
      target[i] = a.match[i];
    } else if (a.smallest_d2[i] > options_.new_landmark_gate) {
      target[i] = kNew;
    }
  }
  return target;
}

void FastSlam2::update_particle(FastSlam2Particle& p, const std::vector<LandmarkObservation>& observations,
                                const std::vector<int>& target, double& log_weight) {
  const Eigen::Matrix2d& r = options_.measurement_noise;
  // The proposal (Montemerlo et al. 2003, eq. (11)-(12)), in EKF form so that a zero prior
  // covariance (no motion since the last draw) is allowed: each known landmark's reading updates
  // the pose Gaussian in turn, relinearised at the updated mean. Its predictive likelihood,
  // N(nu; 0, H_x P H_x^T + H_m Sigma H_m^T + R), multiplies the weight (eq. (16)-(18)).
  Eigen::Vector3d mean = as_vector(p.pose);
  Eigen::Matrix3d cov = p.pose_covariance;
  for (std::size_t i = 0; i < observations.size(); ++i) {
    if (target[i] < 0) continue;
    const Landmark& l = p.landmarks[std::size_t(target[i])];
    const core::Pose2 at(mean(0), mean(1), mean(2));
    const Eigen::Vector2d predicted = range_bearing(at, l.position);
    if (!(predicted(0) > 0.0)) continue;
    const RangeBearingJacobians h = range_bearing_jacobians(at, l.position);
    const Eigen::Matrix2d q = h.point * l.covariance * h.point.transpose() + r;
    const Eigen::Matrix2d s = h.pose * cov * h.pose.transpose() + q;
    const Eigen::Vector2d nu = innovation({observations[i].range, observations[i].bearing}, predicted);
    log_weight += log_gaussian(nu, s);
    const Eigen::Matrix<double, 3, 2> k = cov * h.pose.transpose() * s.inverse();
    mean += k * nu;
    mean(2) = core::normalize_angle(mean(2));
    const Eigen::Matrix3d ikh = Eigen::Matrix3d::Identity() - k * h.pose;
    cov = ikh * cov * ikh.transpose() + k * q * k.transpose();
  }
  const Eigen::Vector3d x = draw(mean, cov, random_);
  p.pose = core::Pose2(x(0), x(1), core::normalize_angle(x(2)));
  p.pose_covariance.setZero();

  // The landmarks' EKFs at the drawn pose (Joseph form keeps them symmetric).
  for (std::size_t i = 0; i < observations.size(); ++i) {
    if (target[i] < 0) continue;
    Landmark& l = p.landmarks[std::size_t(target[i])];
    const Eigen::Vector2d predicted = range_bearing(p.pose, l.position);
    if (!(predicted(0) > 0.0)) continue;
    const Eigen::Matrix2d hm = range_bearing_jacobians(p.pose, l.position).point;
    const Eigen::Matrix2d s = hm * l.covariance * hm.transpose() + r;
    const Eigen::Matrix2d k = l.covariance * hm.transpose() * s.inverse();
    l.position += k * innovation({observations[i].range, observations[i].bearing}, predicted);
    const Eigen::Matrix2d ikh = Eigen::Matrix2d::Identity() - k * hm;
    l.covariance = ikh * l.covariance * ikh.transpose() + k * r * k.transpose();
    l.covariance = 0.5 * (l.covariance + l.covariance.transpose());
  }
  for (std::size_t i = 0; i < observations.size(); ++i) {
    if (target[i] != kNew) continue;
    const Eigen::Vector2d z(observations[i].range, observations[i].bearing);
    const Eigen::Matrix2d gz = landmark_generation_jacobians(p.pose, z).reading;
    const int id = options_.known_associations ? observations[i].id : int(p.landmarks.size());
    p.landmarks.push_back({id, landmark_from_reading(p.pose, z), gz * r * gz.transpose()});
  }
}

void FastSlam2::update(const std::vector<LandmarkObservation>& observations) {
  std::vector<double> log_w(particles_.size(), 0.0);
  std::vector<int> first_target;
  for (std::size_t k = 0; k < particles_.size(); ++k) {
    const std::vector<int> target = associate(particles_[k], observations);
    update_particle(particles_[k], observations, target, log_w[k]);
    if (k == 0) first_target = target;
  }
  // Counters and the id table follow the first particle (with known associations all agree).
  for (std::size_t i = 0; i < observations.size(); ++i) {
    if (first_target[i] == kNew) {
      ++landmarks_added_;
      if (options_.known_associations) slot_of_id_.emplace(observations[i].id, int(slot_of_id_.size()));
    } else if (first_target[i] == kReject) {
      ++rejected_;
    } else {
      ++landmark_updates_;
    }
  }
  const double top = *std::max_element(log_w.begin(), log_w.end());
  double total = 0.0;
  for (std::size_t k = 0; k < particles_.size(); ++k) {
    particles_[k].weight *= std::exp(log_w[k] - top);
    total += particles_[k].weight;
  }
  if (!(total > 0.0) || !std::isfinite(total)) {
    for (auto& p : particles_) p.weight = 1.0;  // every particle equally unlikely: start over evenly
    total = double(particles_.size());
  }
  for (auto& p : particles_) p.selection_weight = p.weight /= total;
  if (effective_particles() < options_.resample_threshold * double(particles_.size())) resample();
}

double FastSlam2::effective_particles() const {
  double s = 0.0;
  for (const auto& p : particles_) s += p.weight * p.weight;
  return s > 0.0 ? 1.0 / s : 0.0;
}

void FastSlam2::resample() {
  // Low-variance (systematic) resampling: one random offset, N evenly spaced pointers.
  const std::size_t n = particles_.size();
  std::vector<FastSlam2Particle> next;
  next.reserve(n);
  const double step = 1.0 / double(n);
  double pointer = random_.uniform(0.0, step);
  double cumulative = particles_[0].weight;
  std::size_t k = 0;
  for (std::size_t m = 0; m < n; ++m) {
    while (pointer > cumulative && k + 1 < n) cumulative += particles_[++k].weight;
    next.push_back(particles_[k]);
    next.back().weight = step;
    pointer += step;
  }
  particles_ = std::move(next);
  ++resamples_;
}

std::size_t FastSlam2::best_particle() const {
  std::size_t best = 0;
  for (std::size_t k = 1; k < particles_.size(); ++k) {
    if (particles_[k].selection_weight > particles_[best].selection_weight) best = k;
  }
  return best;
}

core::Pose2 FastSlam2::pose() const {
  double x = 0.0, y = 0.0, c = 0.0, s = 0.0;
  for (const auto& p : particles_) {
    x += p.weight * p.pose.x;
    y += p.weight * p.pose.y;
    c += p.weight * std::cos(p.pose.theta);
    s += p.weight * std::sin(p.pose.theta);
  }
  return {x, y, std::atan2(s, c)};
}

core::Pose2 FastSlam2::pose(ParticleMap which) const {
  return which == ParticleMap::MaxWeight ? particles_[best_particle()].pose : pose();
}

Eigen::Matrix3d FastSlam2::pose_covariance() const {
  const core::Pose2 m = pose();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : particles_) {
    const Eigen::Vector3d d(p.pose.x - m.x, p.pose.y - m.y, core::normalize_angle(p.pose.theta - m.theta));
    cov += p.weight * (d * d.transpose() + p.pose_covariance);
  }
  return 0.5 * (cov + cov.transpose());
}

std::vector<Landmark> FastSlam2::map(ParticleMap which) const {
  const auto& best = particles_[best_particle()];
  if (which == ParticleMap::MaxWeight || !options_.known_associations) return best.landmarks;
  // Eq. (14)-(15), in the order of the slots (the same in every particle).
  struct Sum {
    double w = 0.0;
    Eigen::Vector2d mu = Eigen::Vector2d::Zero();
    Eigen::Matrix2d sigma = Eigen::Matrix2d::Zero();
  };
  std::vector<Sum> sums(best.landmarks.size());
  for (const auto& p : particles_) {
    for (std::size_t s = 0; s < p.landmarks.size() && s < sums.size(); ++s) {
      sums[s].w += p.weight;
      sums[s].mu += p.weight * p.landmarks[s].position;
      sums[s].sigma += p.weight * p.landmarks[s].covariance;
    }
  }
  std::vector<Landmark> out = best.landmarks;
  for (std::size_t s = 0; s < out.size(); ++s) {
    out[s].position = sums[s].mu / sums[s].w;
    out[s].covariance = sums[s].sigma / sums[s].w;
  }
  return out;
}

void FastSlam2::change_frame(const core::Transform2& t) {
  const Eigen::Matrix2d r = t.rotation_matrix();
  for (auto& p : particles_) {
    p.pose = core::Pose2::from_transform(t * p.pose.as_transform());
    p.pose_covariance = rotate_pose_covariance(p.pose_covariance, t.rotation());
    for (auto& l : p.landmarks) {
      l.position = t.apply(l.position);
      l.covariance = r * l.covariance * r.transpose();
    }
  }
}

namespace {

// `fastslam2` in the localizer registry: the filter, with its map as the combination of the
// particles' (eq. (14)-(15) of the map-alignment paper).
class FastSlam2Localizer final : public Localizer {
 public:
  explicit FastSlam2Localizer(const LocalizerContext& c)
      : filter_(c.initial_pose, initial_covariance((validate_options(c.options), c.options)), options_from(c), c.seed) {}

  static FastSlam2Options options_from(const LocalizerContext& c) {
    const LocalizerOptions& o = c.options;
    FastSlam2Options f;
    f.particles = int(c.params.number("particles"));
    f.process_noise = process_noise(o);
    f.measurement_noise = measurement_noise(o);
    f.known_associations = o.known_associations;
    f.association_gate = o.association_gate;
    f.new_landmark_gate = new_landmark_gate(o, c.params);
    return f;
  }

  std::string name() const override { return "fastslam2"; }
  const FastSlam2& filter() const { return filter_; }
  void predict(const Odometry& u) override { filter_.predict(u); }
  void update_landmarks(const std::vector<LandmarkObservation>& observations) override { filter_.update(observations); }
  core::Pose2 pose() const override { return filter_.pose(); }
  Eigen::Matrix3d covariance() const override { return filter_.pose_covariance(); }
  void change_frame(const core::Transform2& t) override { filter_.change_frame(t); }
  std::vector<Landmark> landmark_estimates() const override { return filter_.map(ParticleMap::Combined); }
  bool estimates_landmarks() const override { return true; }
  std::vector<std::pair<std::string, double>> counters() const override {
    return {{"landmark_updates", double(filter_.landmark_updates())},
            {"rejected_associations", double(filter_.rejected_associations())},
            {"landmarks_added", double(filter_.landmarks_added())},
            {"resamples", double(filter_.resamples())},
            {"effective_particles", filter_.effective_particles()}};
  }

 private:
  FastSlam2 filter_;
};

}  // namespace

std::unique_ptr<Localizer> make_fastslam2_localizer(const LocalizerContext& context) {
  return std::make_unique<FastSlam2Localizer>(context);
}

const FastSlam2& fastslam2_filter(const Localizer& localizer) {
  const auto* own = dynamic_cast<const FastSlam2Localizer*>(&localizer);
  if (!own) throw Error("fastslam2_filter: the localizer is '" + localizer.name() + "', not fastslam2");
  return own->filter();
}

}  // namespace fleetmap::localization
