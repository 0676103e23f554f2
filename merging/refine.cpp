#include "merging/refine.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "merging/grid_level.h"

namespace fleetmap::merging {

namespace {

// The Gauss-Newton sums of one pass, about the origin of a's (level) frame. A residual r at a's
// position p, whose distance gradient g' is seen from b's frame, has the Jacobian
// j0 = [g'x, g'y, p.x g'y - p.y g'x] for an update turning about the origin; turning about c
// instead, j = A j0 with A = [1 0 0; 0 1 0; c.y -c.x 1], so the sums about c (the residuals'
// mean position, known only at the end of the pass) are A H0 A^T and A g0.
struct Sums {
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  Eigen::Vector2d position_sum = Eigen::Vector2d::Zero();
  int count = 0;
};

// The wall points of `from` moved by t into `to`, with the distance to `to`'s walls, added to
// `sums`. `to_a` takes `to`'s frame into a's; `turn` the distance gradient into b's frame, negated
// for a's points (they move by the inverse of the update).
void collect(const GridLevel& from, const GridLevel& to, const core::Transform2& t, const core::Transform2& to_a,
             const Eigen::Matrix2d& turn, double cutoff, Sums& sums, int& inliers, int& outliers) {
  const Eigen::Matrix2f r = t.rotation_matrix().cast<float>();
  const Eigen::Vector2f tr = t.translation().cast<float>();
  // to_a.apply, with its rotation computed once (not once per point).
  const Eigen::Matrix2d ra = to_a.rotation_matrix();
  const Eigen::Vector2d ta = to_a.translation();
  constexpr float kFar = 1e4f;
  // Locals, not the references: the compiler keeps them in registers (the same additions in the
  // same order).
  Sums s = sums;
  int in = 0, out = 0;
  const int width = to.width(), height = to.height();
  for (std::size_t i = 0; i < from.wall_points.size(); ++i) {
    const Eigen::Vector2f p = r * from.wall_points[i] + tr;
    const int x = nearest_cell(p.x()), y = nearest_cell(p.y());
    if (x < 0 || y < 0 || x >= width || y >= height || !to.known(x, y)) continue;
    float gx = 0.0f, gy = 0.0f;
    const float d = to.distance_gradient_at(p.x(), p.y(), kFar, gx, gy);
    if (d >= 2.5f && !from.wall_clutter[i] && to.is_free(x, y)) ++out;
    // A wall of the other map seen from the other side attracts nothing.
    if (d > cutoff || !seen_from_same_side(to, p, r * from.wall_normals[i])) continue;
    if (d <= 1.0f) ++in;
    const Eigen::Vector2d position = ra * p.cast<double>() + ta;
    const Eigen::Vector2d g = turn * Eigen::Vector2d(gx, gy);
    const Eigen::Vector3d j(g.x(), g.y(), position.x() * g.y() - position.y() * g.x());
    const double w = d <= 1.0f ? 1.0 : 1.0 / d;  // Huber weights
    const Eigen::Vector3d wj = w * j;
    s.h += wj * j.transpose();
    s.g += d * wj;
    s.position_sum += position;
    ++s.count;
  }
  sums = s;
  inliers += in;
  outliers += out;
}

// Interior points of `from` (inside filled obstacles) moved by t onto `to`'s clear free space.
// They count against the fit only, so only at the final transform.
int interior_outliers(const GridLevel& from, const GridLevel& to, const core::Transform2& t) {
  const Eigen::Matrix2f r = t.rotation_matrix().cast<float>();
  const Eigen::Vector2f tr = t.translation().cast<float>();
  constexpr float kFar = 1e4f;
  int outliers = 0;
  for (const auto& w : from.interior_points) {
    const Eigen::Vector2f p = r * w + tr;
    const int x = nearest_cell(p.x()), y = nearest_cell(p.y());
    if (x < 0 || y < 0 || x >= to.width() || y >= to.height() || !to.is_free(x, y)) continue;
    if (to.distance_at(p.x(), p.y(), kFar) >= 2.5f) ++outliers;
  }
  return outliers;
}

}  // namespace

LevelFit refine_at_level(const PreparedGrid& a, const PreparedGrid& b, const core::Transform2& b_to_a, int level,
                         const RefineOptions& options) {
  const GridLevel& la = a.level(level);
  const GridLevel& lb = b.level(level);
  core::Transform2 t = to_level(b_to_a, la.factor);
  LevelFit fit;
  for (int it = 0; it <= options.iterations; ++it) {
    fit.inliers = fit.outliers = 0;
    const core::Transform2 inv = t.inverse();
    Sums sums;
    // b's points move with the update; a's by its inverse, their gradients turned into b's frame.
    collect(lb, la, t, core::Transform2::identity(), Eigen::Matrix2d::Identity(), options.inlier_distance, sums,
            fit.inliers, fit.outliers);
    collect(la, lb, inv, t, -t.rotation_matrix(), options.inlier_distance, sums, fit.inliers, fit.outliers);
    if (it == options.iterations || sums.count < 3) break;
    const Eigen::Vector2d c = sums.position_sum / double(sums.count);
    // Update T <- L(delta) T, L(delta)(x) = R(dtheta) (x - c) + c + dt, linearised around 0.
    Eigen::Matrix3d a = Eigen::Matrix3d::Identity();
    a(2, 0) = c.y(), a(2, 1) = -c.x();
    Eigen::Matrix3d h = a * sums.h * a.transpose();
    const Eigen::Vector3d g = a * sums.g;
    // Marquardt damping, relative to each diagonal entry: the rotation entry grows with the
    // square of the map size, so a damping shared by all entries would stall the translation.
    h.diagonal() = h.diagonal() * (1.0 + 1e-3) + Eigen::Vector3d::Constant(1e-9);
    const Eigen::Vector3d delta = -h.ldlt().solve(g);
    if (!delta.allFinite()) break;
    const double dth = std::clamp(delta(2), -0.05, 0.05);
    Eigen::Vector2d dt = delta.head<2>();
    if (dt.norm() > 2.0) dt *= 2.0 / dt.norm();
    // Converged: a step this small changes nothing that counts, and the counts are at t (taking
    // the step would cost one more pass to count again).
    const double converged = level > 0 ? options.coarse_converged_cells : options.converged_cells;
    if (dt.norm() < converged && std::abs(dth) * options.converged_radius < converged) break;
    const core::Transform2 rot(0.0, 0.0, dth);
    const core::Transform2 step(c + dt - rot.apply(c), dth);
    t = step * t;
  }
  // The last pass above was at the final t.
  fit.outliers += interior_outliers(lb, la, t) + interior_outliers(la, lb, t.inverse());
  fit.b_to_a = from_level(t, la.factor);
  fit.score = fit.inliers - options.contradiction_weight * fit.outliers;
  return fit;
}

LevelFit refine_alignment(const PreparedGrid& a, const PreparedGrid& b, const core::Transform2& b_to_a, int from_level,
                          const RefineOptions& options) {
  LevelFit fit;
  fit.b_to_a = b_to_a;
  const int top = std::min({from_level, a.level_count() - 1, b.level_count() - 1});
  for (int k = top; k >= 0; --k) fit = refine_at_level(a, b, fit.b_to_a, k, options);
  return fit;
}

}  // namespace fleetmap::merging
