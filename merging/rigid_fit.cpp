#include "merging/rigid_fit.h"

#include <cmath>

namespace fleetmap::merging {

std::optional<core::Transform2> fit_rigid(const std::vector<PointPair>& pairs) {
  if (pairs.size() < 2) return std::nullopt;
  double w = 0.0;
  Eigen::Vector2d cf = Eigen::Vector2d::Zero(), ct = Eigen::Vector2d::Zero();
  for (const auto& p : pairs) {
    w += p.weight;
    cf += p.weight * p.from;
    ct += p.weight * p.to;
  }
  if (!(w > 0.0)) return std::nullopt;
  cf /= w;
  ct /= w;
  double dot = 0.0, cross = 0.0;
  for (const auto& p : pairs) {
    const Eigen::Vector2d f = p.from - cf, t = p.to - ct;
    dot += p.weight * f.dot(t);
    cross += p.weight * (f.x() * t.y() - f.y() * t.x());
  }
  if (std::abs(dot) + std::abs(cross) < 1e-12) return std::nullopt;
  const double theta = std::atan2(cross, dot);
  const core::Transform2 r(0.0, 0.0, theta);
  return core::Transform2(ct - r.apply(cf), theta);
}

std::optional<RigidRansacResult> ransac_rigid(const std::vector<PointPair>& pairs, const RigidRansacOptions& options,
                                              core::Random& random, const std::vector<bool>& skip) {
  std::vector<int> usable;
  for (int i = 0; i < int(pairs.size()); ++i) {
    if (skip.empty() || !skip[std::size_t(i)]) usable.push_back(i);
  }
  if (int(usable.size()) < std::max(2, options.min_inliers)) return std::nullopt;
  const double d2 = options.inlier_distance * options.inlier_distance;
  const auto inliers_of = [&](const core::Transform2& t) {
    std::vector<int> in;
    const Eigen::Matrix2d r = t.rotation_matrix();
    for (int i : usable) {
      const auto& p = pairs[std::size_t(i)];
      if ((r * p.from + t.translation() - p.to).squaredNorm() <= d2) in.push_back(i);
    }
    return in;
  };
  std::vector<int> best;
  core::Transform2 best_t;
  const int n = int(usable.size());
  for (int it = 0; it < options.iterations; ++it) {
    const int i = usable[std::size_t(random.uniform_int(0, n - 1))];
    const int j = usable[std::size_t(random.uniform_int(0, n - 1))];
    if (i == j) continue;
    const auto& p = pairs[std::size_t(i)];
    const auto& q = pairs[std::size_t(j)];
    const double df = (p.from - q.from).norm(), dt = (p.to - q.to).norm();
    if (std::abs(df - dt) > 2.0 * options.inlier_distance || df < options.inlier_distance) continue;
    const auto t = fit_rigid({{p.from, p.to, 1.0}, {q.from, q.to, 1.0}});
    if (!t) continue;
    auto in = inliers_of(*t);
    if (in.size() > best.size()) {
      best = std::move(in);
      best_t = *t;
    }
  }
  if (int(best.size()) < options.min_inliers) return std::nullopt;
  // Refit on the inliers until the set is stable (a few rounds at most).
  for (int round = 0; round < 3; ++round) {
    std::vector<PointPair> in;
    for (int i : best) in.push_back(pairs[std::size_t(i)]);
    const auto t = fit_rigid(in);
    if (!t) break;
    auto next = inliers_of(*t);
    if (next.size() < best.size()) break;
    const bool same = next == best;
    best = std::move(next);
    best_t = *t;
    if (same) break;
  }
  return RigidRansacResult{best_t, best};
}

}  // namespace fleetmap::merging
