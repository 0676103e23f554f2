#include "localization/polynomial_slam.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"

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
  int slot = -1;
  Eigen::Vector2d shift = Eigen::Vector2d::Zero();
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
  if (!(o.innovation_gate > 0.0)) fail("innovation_gate", "a positive number", o.innovation_gate);
  if (!(o.min_incidence_cos >= 0.0 && o.min_incidence_cos < 1.0)) fail("min_incidence_cos", "a number in [0, 1)", o.min_incidence_cos);
  if (!std::isfinite(o.domain_margin)) fail("domain_margin", "a finite number", o.domain_margin);
  if (!(o.cluster_tolerance > 0.0)) fail("cluster_tolerance", "a positive number", o.cluster_tolerance);
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
      filter_(initial_pose, initial_covariance) {
  thresholds_ = slam_thresholds(initial_covariance, initial_covariance, options_);
}

void PolynomialSlam::predict(const Odometry& u) {
  ++step_;
  filter_.predict(u, process_noise_);
}

mapping::Polynomial PolynomialSlam::current(int index) const {
  mapping::Polynomial p = map_.landmarks[std::size_t(index)].polynomial;
  p.position = filter_.position(index);
  return p;
}

void PolynomialSlam::sync_positions() {
  for (std::size_t i = 0; i < map_.landmarks.size(); ++i) map_.landmarks[i].polynomial.position = filter_.position(int(i));
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
    const auto hit = mapping::intersect_ray(current(index), now.position(), now.theta + angles[i],
                                            y + options_.sigma_max + 1.0, options_.domain_margin);
    if (!hit || hit->cos_incidence < options_.min_incidence_cos) {
      ++counters_.rejected_readings;
      continue;
    }
    ScalarReading reading;
    reading.predicted = hit->distance;
    reading.h_pose << hit->d_origin.x(), hit->d_origin.y(), hit->d_angle;
    reading.slot = index;
    reading.h_slot = hit->d_position;
    reading.noise = r;
    if (options_.shape_noise) {
      // The shape's own uncertainty at the point read: a shift along the independent axis moves
      // the curve by -p' delta, a turn phi about the domain's middle by ((xi - xc) + p' (p - p_c)) phi.
      const mapping::Polynomial p = current(index);
      const auto& landmark = map_.landmarks[std::size_t(index)];
      const double d = p.slope(hit->xi), xc = 0.5 * (p.lo + p.hi);
      const double lever = (hit->xi - xc) + d * (p.value(hit->xi) - p.value(xc));
      reading.noise += hit->d_position * hit->d_position *
                       (d * d * landmark.along_variance + lever * lever * landmark.angle_variance);
    }
    const double s = filter_.innovation_variance(reading);
    const double nu = y - hit->distance;
    if (!(s > 0.0) || nu * nu / s > options_.innovation_gate) {
      ++counters_.rejected_readings;
      continue;
    }
    filter_.update(y, reading);
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
  if (options_.lowest_order) {
    // The lowest order whose fit explains the points as well as order m does, within the noise:
    // its weighted RMS residual at most that of order m plus half a reading's standard deviation.
    const double enough = fit->rms_residual + 0.5 * options_.range_noise;
    for (int order = 1; order < options_.order; ++order) {
      auto lower = mapping::fit_polynomial(weighted, order, axis);
      if (lower && lower->rms_residual <= enough && lower->max_residual <= max_residual) {
        // Kept as an order-m polynomial whose leading coefficients are zero.
        lower->polynomial.shape.insert(lower->polynomial.shape.begin(), std::size_t(options_.order - order), 0.0);
        fit = std::move(lower);
        break;
      }
    }
  }
  // A least-squares cubic through points bunched at two places can swing far between them (a
  // refit of Q_bad points beyond p's end with R on p, say); such a polynomial maps nothing seen.
  if (mapping::stray_between_points(fit->polynomial, weighted) > options_.sigma_max) return std::nullopt;

  // D'Alfonso et al. eq. (5): the gradient of c0_new = g(X, y) with respect to the pose, the source
  // landmarks' c0 and the readings, at x_k|k-1 and y_k.
  const std::vector<Eigen::Vector2d> grad = mapping::position_gradient(fit->polynomial, weighted);
  const Eigen::Vector2d dependent = fit->polynomial.dependent_direction();
  LandmarkGeneration g;
  g.value = fit->polynomial.position;
  const double r = std::pow(std::max(options_.range_noise, kMinRangeStd), 2);
  std::vector<std::pair<int, double>> group_shift;  // per received group: sum of g . dependent
  for (std::size_t k = 0; k < points.size(); ++k) {
    const SourcePoint& p = points[k];
    const Eigen::Vector2d& gk = grad[k];
    switch (p.kind) {
      case SourcePoint::Kind::Measured:
        // pi = observer + y u: d pi / d(x, y, theta) = [I | perp(pi - observer)], d pi / d y = u.
        g.g_pose += Eigen::RowVector3d(gk.x(), gk.y(), gk.dot(perp(p.position - p.observer)));
        g.noise_variance += std::pow(gk.dot(p.beam), 2) * r;
        break;
      case SourcePoint::Kind::OnLandmark: {
        const double d = gk.dot(p.shift);
        auto it = std::find_if(g.g_slots.begin(), g.g_slots.end(), [&](const auto& s) { return s.first == p.slot; });
        if (it == g.g_slots.end()) {
          g.g_slots.emplace_back(p.slot, d);
        } else {
          it->second += d;
        }
        break;
      }
      case SourcePoint::Kind::Received: {
        g.g_pose += Eigen::RowVector3d(gk.x(), gk.y(), gk.dot(perp(p.position - p.observer)));
        auto it = std::find_if(group_shift.begin(), group_shift.end(), [&](const auto& s) { return s.first == p.group; });
        if (it == group_shift.end()) {
          group_shift.emplace_back(p.group, gk.dot(dependent));
        } else {
          it->second += gk.dot(dependent);
        }
        break;
      }
    }
  }
  for (const auto& [group, shift] : group_shift) {
    for (const auto& p : points) {
      if (p.kind == SourcePoint::Kind::Received && p.group == group) {
        g.noise_variance += shift * shift * p.variance;
        break;
      }
    }
  }
  filter_.augment(g);
  mapping::PolynomialLandmark landmark;
  landmark.id = next_id_++;
  landmark.polynomial = fit->polynomial;
  landmark.received_from = received_from;
  // The shape's uncertainty (options.shape_noise): the least of its sources'. Points computed from
  // the pose carry the pose's variance along the curve and in heading, plus the fit's slope variance.
  {
    const mapping::Polynomial& shape = fit->polynomial;
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
  filter_.remove(indices);
  for (auto it = indices.rbegin(); it != indices.rend(); ++it) map_.landmarks.erase(map_.landmarks.begin() + *it);
}

std::vector<PolynomialSlam::SourcePoint> PolynomialSlam::samples_of(int index, int count) const {
  const mapping::Polynomial p = current(index);
  const double weight = 1.0 / std::max(filter_.position_variance(index), 1e-12);  // §3.3
  std::vector<SourcePoint> out;
  for (const auto& q : mapping::sample_equally(p, count)) {
    SourcePoint s;
    s.kind = SourcePoint::Kind::OnLandmark;
    s.position = q;
    s.weight = weight;
    s.slot = index;
    s.shift = p.dependent_direction();
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
  std::vector<double> positions, scales;
  for (int i = 0; i < int(map_.landmarks.size()); ++i) {
    const mapping::Polynomial old = current(i);
    // Points every 2 cm (at least 4 (m + 1)) on the old curve, moved; the refit follows them to
    // far below the sensor noise for the smooth, short curves a map holds.
    const int count = std::max(4 * (options_.order + 1), int(std::ceil(old.length() / 0.02)) + 1);
    std::vector<mapping::WeightedPoint> moved;
    for (const auto& q : mapping::sample_equally(old, count)) moved.push_back({t * q, 1.0});
    std::optional<mapping::PolynomialFit> fit;
    for (int order = options_.order; order >= 1 && !fit; --order) {
      fit = mapping::fit_polynomial(moved, order, mapping::principal_axis(moved));
    }
    if (!fit) throw Error("PolynomialSlam::change_frame: a polynomial could not be refitted in the new frame");
    // Shifting the old curve by delta along its dependent axis shifts the moved points by
    // delta R e_old, and the refit's c_0 by delta sum_k g_k . R e_old.
    const Eigen::Vector2d shift = rot * old.dependent_direction();
    double scale = 0.0;
    for (const auto& g : mapping::position_gradient(fit->polynomial, moved)) scale += g.dot(shift);
    auto& landmark = map_.landmarks[std::size_t(i)];
    landmark.polynomial = fit->polynomial;
    for (auto& b : landmark.bad_points) {
      b.position = t * b.position;
      b.observer = t * b.observer;
      b.beam = rot * b.beam;
    }
    positions.push_back(fit->polynomial.position);
    scales.push_back(scale);
  }
  for (auto& cluster : map_.clusters) {
    for (auto& q : cluster.points) {
      q.position = t * q.position;
      q.observer = t * q.observer;
      q.beam = rot * q.beam;
    }
  }
  filter_.change_frame(t, positions, scales);
  sync_positions();
}

}  // namespace fleetmap::localization
