#include "merging/landmark_alignment.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "merging/rigid_fit.h"

namespace fleetmap::merging {

namespace {

double signature_distance(const MapLandmark& a, const MapLandmark& b) {
  if (a.signature.size() == 0 || b.signature.size() == 0 || a.signature.size() != b.signature.size()) return 0.0;
  return (a.signature - b.signature).norm();
}

// Supports of t: other's landmarks whose transformed position has one of self's within th_p.
std::vector<std::pair<int, int>> supports_of(const LandmarkMap& self, const LandmarkMap& other, const core::Transform2& t,
                                             double th_p) {
  std::vector<std::pair<int, int>> out;
  for (int k = 0; k < int(other.landmarks.size()); ++k) {
    const Eigen::Vector2d p = t.apply(other.landmarks[std::size_t(k)].position);
    int best = -1;
    double best_d = th_p;
    for (int i = 0; i < int(self.landmarks.size()); ++i) {
      const double d = (self.landmarks[std::size_t(i)].position - p).norm();
      if (d < best_d) best_d = d, best = i;
    }
    if (best >= 0) out.emplace_back(best, k);
  }
  return out;
}

}  // namespace

std::vector<std::pair<int, int>> candidate_matches(const LandmarkMap& self, const LandmarkMap& other,
                                                   const LandmarkAlignmentOptions& options) {
  std::vector<std::pair<int, int>> out;
  for (int k = 0; k < int(other.landmarks.size()); ++k) {
    const auto& o = other.landmarks[std::size_t(k)];
    if (o.signature.size() == 0) {
      for (int i = 0; i < int(self.landmarks.size()); ++i) out.emplace_back(i, k);
      continue;
    }
    int best = -1;
    double best_d = std::numeric_limits<double>::max();
    for (int i = 0; i < int(self.landmarks.size()); ++i) {
      const auto& s = self.landmarks[std::size_t(i)];
      if (s.signature.size() != o.signature.size()) continue;
      const double d = signature_distance(s, o);
      if (d < best_d) best_d = d, best = i;
    }
    if (best >= 0 && best_d < options.signature_threshold) out.emplace_back(best, k);
  }
  return out;
}

core::Transform2 transform_from_two_pairs(const Eigen::Vector2d& self_i, const Eigen::Vector2d& other_i,
                                          const Eigen::Vector2d& self_j, const Eigen::Vector2d& other_j) {
  const double a = other_i.x() - other_j.x(), b = other_i.y() - other_j.y();
  const double c = self_i.x() - self_j.x(), d = self_i.y() - self_j.y();
  const double theta = std::atan2(b * c - a * d, a * c + b * d);  // eq. (6)
  const double ct = std::cos(theta), st = std::sin(theta);
  const double dx = self_i.x() - other_i.x() * ct - other_i.y() * st;  // eq. (3)
  const double dy = self_i.y() - other_i.y() * ct + other_i.x() * st;  // eq. (4)
  // x = x' cos + y' sin + d_x, y = -x' sin + y' cos + d_y: a rotation by -theta.
  return {dx, dy, -theta};
}

LandmarkAlignment align_landmarks(const LandmarkMap& self, const LandmarkMap& other,
                                  const LandmarkAlignmentOptions& options, core::Random& random) {
  LandmarkAlignment out;
  const auto matches = candidate_matches(self, other, options);
  out.candidates = int(matches.size());
  const int n = int(matches.size());
  if (n < 2) return out;
  const auto try_pair = [&](int u, int v) {
    const auto [si, oi] = matches[std::size_t(u)];
    const auto [sj, oj] = matches[std::size_t(v)];
    if (si == sj || oi == oj) return;
    const Eigen::Vector2d& ps_i = self.landmarks[std::size_t(si)].position;
    const Eigen::Vector2d& ps_j = self.landmarks[std::size_t(sj)].position;
    const Eigen::Vector2d& po_i = other.landmarks[std::size_t(oi)].position;
    const Eigen::Vector2d& po_j = other.landmarks[std::size_t(oj)].position;
    // Eq. (2): a rigid motion keeps the distance between the two landmarks.
    if (std::abs((po_i - po_j).squaredNorm() - (ps_i - ps_j).squaredNorm()) >= options.geometric_threshold) return;
    const core::Transform2 t = transform_from_two_pairs(ps_i, po_i, ps_j, po_j);
    auto sup = supports_of(self, other, t, options.support_threshold);
    if (sup.size() > out.supports.size()) {
      out.supports = std::move(sup);
      out.transform = t;
    }
  };
  const long long all_pairs = (long long)n * (n - 1) / 2;
  if (all_pairs <= options.max_pair_trials) {
    for (int u = 0; u < n; ++u) for (int v = u + 1; v < n; ++v) try_pair(u, v);
  } else {
    for (int k = 0; k < options.max_pair_trials; ++k) {
      const int u = random.uniform_int(0, n - 1), v = random.uniform_int(0, n - 1);
      if (u != v) try_pair(u, v);
    }
  }
  if (int(out.supports.size()) < std::max(2, options.min_supports)) {
    out.supports.clear();
    return out;
  }
  if (options.refit_supports) {
    // Least squares on the supports, a few rounds, kept while it holds (nearly) all of them. A
    // support farther than three robust standard deviations (from the median residual) is a chance
    // neighbour within th_p and stays out of the fit.
    for (int round = 0; round < 3; ++round) {
      std::vector<double> residuals;
      for (const auto& [i, k] : out.supports) {
        residuals.push_back((out.transform.apply(other.landmarks[std::size_t(k)].position) -
                             self.landmarks[std::size_t(i)].position).norm());
      }
      std::vector<double> sorted = residuals;
      std::nth_element(sorted.begin(), sorted.begin() + long(sorted.size() / 2), sorted.end());
      const double gate = std::max(3.0 * 1.4826 * sorted[sorted.size() / 2], 1e-6);
      std::vector<PointPair> pairs;
      for (std::size_t s = 0; s < out.supports.size(); ++s) {
        if (residuals[s] > gate) continue;
        const auto [i, k] = out.supports[s];
        pairs.push_back({other.landmarks[std::size_t(k)].position, self.landmarks[std::size_t(i)].position, 1.0});
      }
      const auto t = fit_rigid(pairs);
      if (!t) break;
      auto sup = supports_of(self, other, *t, options.support_threshold);
      if (10 * sup.size() < 9 * out.supports.size()) break;
      const bool same = sup == out.supports && t->is_approx(out.transform, 1e-12);
      out.transform = *t;
      out.supports = std::move(sup);
      if (same) break;
    }
  }
  out.found = true;
  return out;
}

LandmarkMap transform_landmarks(const LandmarkMap& map, const core::Transform2& t) {
  LandmarkMap out = map;
  const Eigen::Matrix2d r = t.rotation_matrix();
  for (auto& l : out.landmarks) {
    l.position = t.apply(l.position);
    l.covariance = r * l.covariance * r.transpose();  // eq. (10)
  }
  return out;
}

MapLandmark fuse_landmarks(const MapLandmark& self, const MapLandmark& other) {
  const Eigen::Matrix2d k = self.covariance * (self.covariance + other.covariance).inverse();  // eq. (11)
  MapLandmark out = self;
  out.covariance = self.covariance - k * self.covariance;                                      // eq. (12)
  out.covariance = 0.5 * (out.covariance + out.covariance.transpose());
  out.position = self.position + k * (other.position - self.position);                         // eq. (13)
  return out;
}

LandmarkMergeResult merge_landmark_maps(const LandmarkMap& self, const LandmarkMap& other,
                                        const core::Transform2& other_to_self, const LandmarkAlignmentOptions& options) {
  const LandmarkMap moved = transform_landmarks(other, other_to_self);
  // Candidate duplicate pairs, nearest first, taken one to one.
  struct Pair { double d; int i, k; };
  std::vector<Pair> pairs;
  for (int k = 0; k < int(moved.landmarks.size()); ++k) {
    for (int i = 0; i < int(self.landmarks.size()); ++i) {
      const auto& s = self.landmarks[std::size_t(i)];
      const auto& o = moved.landmarks[std::size_t(k)];
      const double d = (s.position - o.position).norm();
      if (d <= options.duplicate_distance && signature_distance(s, o) < options.signature_threshold) pairs.push_back({d, i, k});
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& x, const Pair& y) { return x.d < y.d; });
  LandmarkMergeResult out;
  out.merged = self;
  std::vector<bool> self_used(self.landmarks.size(), false), other_used(moved.landmarks.size(), false);
  for (const auto& p : pairs) {
    if (self_used[std::size_t(p.i)] || other_used[std::size_t(p.k)]) continue;
    self_used[std::size_t(p.i)] = other_used[std::size_t(p.k)] = true;
    out.merged.landmarks[std::size_t(p.i)] = fuse_landmarks(self.landmarks[std::size_t(p.i)], moved.landmarks[std::size_t(p.k)]);
    ++out.duplicates;
  }
  for (std::size_t k = 0; k < moved.landmarks.size(); ++k) {
    if (other_used[k]) continue;
    out.merged.landmarks.push_back(moved.landmarks[k]);
    ++out.added;
  }
  return out;
}

LandmarkMethodChoice align_landmark_maps(const LandmarkMap& self, const LandmarkMap& other,
                                         const std::optional<Rendezvous>& rendezvous,
                                         const LandmarkAlignmentOptions& options, core::Random& random) {
  LandmarkMethodChoice out;
  out.overlapping_landmarks = int(candidate_matches(self, other, options).size());
  const auto use_observation = [&]() {
    if (!rendezvous) return false;
    out.method = AlignmentMethod::InterRobotObservation;
    out.transform = rendezvous_transform(rendezvous->self_pose, rendezvous->other_pose, rendezvous->observation);
    out.message = "Map alignment using inter robot observations";
    return true;
  };
  if (out.overlapping_landmarks >= options.overlap_threshold) {
    out.ransac = align_landmarks(self, other, options, random);
    if (out.ransac.found) {
      out.method = AlignmentMethod::DataAssociation;
      out.transform = out.ransac.transform;
      out.message = "Map alignment using data association";
      return out;
    }
    if (!use_observation()) out.message = "no map alignment: data association found no consistent landmarks and there is no rendezvous";
    return out;
  }
  if (!use_observation()) {
    out.message = "no map alignment: " + std::to_string(out.overlapping_landmarks) + " overlapping landmarks (< " +
                  std::to_string(options.overlap_threshold) + ") and no rendezvous";
  }
  return out;
}

const char* to_string(AlignmentMethod method) {
  switch (method) {
    case AlignmentMethod::DataAssociation: return "data_association";
    case AlignmentMethod::InterRobotObservation: return "inter_robot_observation";
    case AlignmentMethod::None: return "none";
  }
  return "none";
}

}  // namespace fleetmap::merging
