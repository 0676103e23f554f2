#include "merging/refine.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>

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
  double weighted_squares = 0.0;  // sum w d^2
  int count = 0;
};

// The wall points of `from` moved by t into `to`, with the distance to `to`'s walls, added to
// `sums`. `to_a` takes `to`'s frame into a's; `turn` the distance gradient into b's frame, negated
// for a's points (they move by the inverse of the update). With `normals` (one per wall point of
// `from`, line_normals), the gradient is taken along the point's normal only where it has one: a
// slanted wall's cells stand in steps, and the distance to them changes along the wall too, which
// says where the steps are, not where the wall is.
void collect(const GridLevel& from, const GridLevel& to, const core::Transform2& t, const core::Transform2& to_a,
             const Eigen::Matrix2d& turn, double cutoff, Sums& sums, int& inliers, int& outliers,
             const std::vector<Eigen::Vector2f>* normals = nullptr) {
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
    Eigen::Vector2d g(gx, gy);
    if (normals && (*normals)[i] != Eigen::Vector2f::Zero()) {
      const Eigen::Vector2d n = (r * (*normals)[i]).cast<double>();
      g = g.dot(n) * n;
    }
    g = turn * g;
    const Eigen::Vector3d j(g.x(), g.y(), position.x() * g.y() - position.y() * g.x());
    const double w = d <= 1.0f ? 1.0 : 1.0 / d;  // Huber weights
    const Eigen::Vector3d wj = w * j;
    s.h += wj * j.transpose();
    s.g += d * wj;
    s.weighted_squares += w * double(d) * double(d);
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

// Per wall point of `level`, the unit normal of the straight wall it lies on: the direction of
// least spread of the wall cells within 3 cells, when they lie along a line (spread across at most
// a tenth of the spread along: a 7-cell stretch of a one-cell-thick line of any slope is about
// 0.02); zero at corners, ends and clutter, where the distance's gradient is the wall's own.
std::vector<Eigen::Vector2f> line_normals(const GridLevel& level) {
  constexpr int kR = 3;
  constexpr double kMostSpread = 0.1;
  std::vector<Eigen::Vector2f> out;
  out.reserve(level.wall_points.size());
  for (const Eigen::Vector2f& p : level.wall_points) {
    const int cx = int(std::lround(p.x())), cy = int(std::lround(p.y()));
    Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    int n = 0;
    for (int y = std::max(0, cy - kR); y <= std::min(level.walls.rows - 1, cy + kR); ++y) {
      const auto* row = level.walls.ptr<std::uint8_t>(y);
      for (int x = std::max(0, cx - kR); x <= std::min(level.walls.cols - 1, cx + kR); ++x) {
        if (!row[x] || (x - cx) * (x - cx) + (y - cy) * (y - cy) > kR * kR) continue;
        const Eigen::Vector2d q(x - cx, y - cy);
        scatter += q * q.transpose();
        sum += q;
        ++n;
      }
    }
    if (n < 4) {
      out.emplace_back(Eigen::Vector2f::Zero());
      continue;
    }
    const Eigen::Vector2d mean = sum / double(n);
    scatter = scatter / double(n) - mean * mean.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(scatter);
    const bool line = eig.eigenvalues()(0) <= kMostSpread * eig.eigenvalues()(1);
    out.emplace_back(line ? Eigen::Vector2f(eig.eigenvectors().col(0).cast<float>()) : Eigen::Vector2f::Zero());
  }
  return out;
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

std::optional<Eigen::Matrix3d> fit_covariance(const PreparedGrid& a, const PreparedGrid& b, const core::Transform2& b_to_a,
                                              const RefineOptions& options) {
  const GridLevel& la = a.level(0);
  const GridLevel& lb = b.level(0);
  const std::vector<Eigen::Vector2f> normals_a = line_normals(la), normals_b = line_normals(lb);
  Sums sums;
  int inliers = 0, outliers = 0;
  collect(lb, la, b_to_a, core::Transform2::identity(), Eigen::Matrix2d::Identity(), options.inlier_distance, sums,
          inliers, outliers, &normals_b);
  collect(la, lb, b_to_a.inverse(), b_to_a, -b_to_a.rotation_matrix(), options.inlier_distance, sums, inliers, outliers,
          &normals_a);
  if (sums.count < 4) return std::nullopt;
  // About the residuals' mean position c (well conditioned), then to the parameters of b_to_a: the
  // update x -> R(dtheta) (x - c) + c + dt moves t by dt + dtheta perp(t - c).
  const Eigen::Vector2d c = sums.position_sum / double(sums.count);
  Eigen::Matrix3d about_c = Eigen::Matrix3d::Identity();
  about_c(2, 0) = c.y(), about_c(2, 1) = -c.x();
  const Eigen::Matrix3d h = about_c * sums.h * about_c.transpose();
  constexpr double kCellVariance = 1.0 / 12.0;
  const double noise = std::max(kCellVariance, sums.weighted_squares / double(sums.count - 3));
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(h);
  constexpr double kUnconstrained = 1e12;
  Eigen::Vector3d inverse_values;
  for (int i = 0; i < 3; ++i) {
    const double v = eig.eigenvalues()(i);
    inverse_values(i) = v > 0.0 ? std::min(kUnconstrained, 2.0 * noise / v) : kUnconstrained;
  }
  const Eigen::Matrix3d about = eig.eigenvectors() * inverse_values.asDiagonal() * eig.eigenvectors().transpose();
  const Eigen::Vector2d lever = b_to_a.translation() - c;
  Eigen::Matrix3d to_params = Eigen::Matrix3d::Identity();
  to_params(0, 2) = -lever.y(), to_params(1, 2) = lever.x();
  return to_params * about * to_params.transpose();
}

namespace {

Eigen::Vector3d params(const core::Transform2& t) { return {t.translation().x(), t.translation().y(), t.rotation()}; }

// d params(f(T)) / d params(T) at `at`, by central differences (angles wrapped).
Eigen::Matrix3d jacobian(const core::Transform2& at, const std::function<core::Transform2(const core::Transform2&)>& f) {
  Eigen::Matrix3d j;
  const Eigen::Vector3d p = params(at);
  for (int k = 0; k < 3; ++k) {
    const double step = k < 2 ? 1e-4 * std::max(1.0, std::abs(p(k))) : 1e-6;
    Eigen::Vector3d lo = p, hi = p;
    lo(k) -= step, hi(k) += step;
    const Eigen::Vector3d fl = params(f(core::Transform2(lo.x(), lo.y(), lo.z())));
    const Eigen::Vector3d fh = params(f(core::Transform2(hi.x(), hi.y(), hi.z())));
    Eigen::Vector3d d = fh - fl;
    d(2) = std::remainder(d(2), 2.0 * std::numbers::pi);
    j.col(k) = d / (2.0 * step);
  }
  return j;
}

}  // namespace

Eigen::Matrix3d propagate_covariance(const Eigen::Matrix3d& covariance, const core::Transform2& at,
                                     const std::function<core::Transform2(const core::Transform2&)>& f) {
  const Eigen::Matrix3d j = jacobian(at, f);
  return j * covariance * j.transpose();
}

Eigen::Matrix3d propagate_covariance(const Eigen::Matrix3d& covariance_t, const core::Transform2& t,
                                     const Eigen::Matrix3d& covariance_u, const core::Transform2& u,
                                     const std::function<core::Transform2(const core::Transform2&, const core::Transform2&)>& f) {
  return propagate_covariance(covariance_t, t, [&](const core::Transform2& x) { return f(x, u); }) +
         propagate_covariance(covariance_u, u, [&](const core::Transform2& y) { return f(t, y); });
}

}  // namespace fleetmap::merging
