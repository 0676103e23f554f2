#include "localization/scan_matcher.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/angle.h"

namespace fleetmap::localization {

std::vector<Eigen::Vector2d> scan_end_points(const RangeScan& scan, int stride) {
  std::vector<Eigen::Vector2d> out;
  int k = 0;
  for (std::size_t b = 0; b < scan.angles.size(); ++b) {
    if (!scan.ranges[b]) continue;
    if (k++ % std::max(stride, 1) != 0) continue;
    const double r = *scan.ranges[b];
    out.emplace_back(r * std::cos(scan.angles[b]), r * std::sin(scan.angles[b]));
  }
  return out;
}

std::vector<Eigen::Vector2d> transform_points(const core::Pose2& pose, const std::vector<Eigen::Vector2d>& points) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(points.size());
  for (const auto& p : points) out.push_back(pose.transform(p));
  return out;
}

ScanMatcherOptions scan_matcher_options(const LocalizerOptions& o, double max_range_m, double resolution_m,
                                        double turn_rad) {
  ScanMatcherOptions m;
  m.field.max_range_m = max_range_m;
  // The field's spread covers the range noise and a cell of discretisation.
  m.field.sigma_m = std::max(resolution_m, 2.0 * o.range_noise);
  // The motion model is the prior (Olson 2009): three standard deviations of a step's odometry
  // noise. Where the scan says nothing (along a featureless corridor) the odometry stays.
  m.prior_xy_m = std::max(1e-3, 3.0 * o.process_noise_xy);
  const double turn_sigma = o.turn_noise_per_rad * std::abs(turn_rad);
  m.prior_theta_rad = std::max(1e-4, 3.0 * (o.process_noise_theta + turn_sigma));
  m.search_theta_rad += 3.0 * turn_sigma;
  return m;
}

namespace {

// log of the Gaussian prior around the guess (up to a constant); 0 when disabled.
double log_prior(const core::Pose2& pose, const core::Pose2& guess, const ScanMatcherOptions& o) {
  double s = 0.0;
  if (o.prior_xy_m > 0) {
    const double d2 = (pose.position() - guess.position()).squaredNorm();
    s -= 0.5 * d2 / (o.prior_xy_m * o.prior_xy_m);
  }
  if (o.prior_theta_rad > 0) {
    const double a = core::normalize_angle(pose.theta - guess.theta);
    s -= 0.5 * a * a / (o.prior_theta_rad * o.prior_theta_rad);
  }
  return s;
}

template <typename Objective>
std::pair<core::Pose2, double> climb(const Objective& objective, const core::Pose2& start, double xy_step,
                                     double theta_step, int iterations) {
  core::Pose2 best = start;
  double best_score = objective(best);
  const double min_xy = xy_step / 16.0;
  for (int it = 0; it < iterations && xy_step >= min_xy; ++it) {
    bool improved = false;
    const core::Pose2 moves[6] = {{best.x + xy_step, best.y, best.theta}, {best.x - xy_step, best.y, best.theta},
                                  {best.x, best.y + xy_step, best.theta}, {best.x, best.y - xy_step, best.theta},
                                  {best.x, best.y, best.theta + theta_step}, {best.x, best.y, best.theta - theta_step}};
    core::Pose2 candidate = best;
    double candidate_score = best_score;
    for (const auto& m : moves) {
      const double s = objective(m);
      if (s > candidate_score) {
        candidate_score = s;
        candidate = m;
      }
    }
    if (candidate_score > best_score) {
      best = candidate;
      best_score = candidate_score;
      improved = true;
    }
    if (!improved) {
      xy_step *= 0.5;
      theta_step *= 0.5;
    }
  }
  best.theta = core::normalize_angle(best.theta);
  return {best, best_score};
}

}  // namespace

std::pair<core::Pose2, double> refine_pose(const LikelihoodField& field, const std::vector<Eigen::Vector2d>& points,
                                           const core::Pose2& start, double xy_step_m, double theta_step_rad,
                                           int iterations) {
  return climb([&](const core::Pose2& p) { return field.score(transform_points(p, points)); }, start, xy_step_m,
               theta_step_rad, iterations);
}

ScanMatch match_scan(const LikelihoodField& field, const std::vector<Eigen::Vector2d>& points, const core::Pose2& guess,
                     const ScanMatcherOptions& o, const std::optional<core::Pose2>& prior_mean) {
  const core::Pose2 centre = prior_mean.value_or(guess);
  ScanMatch result;
  result.pose = guess;
  result.points = int(points.size());
  if (int(points.size()) < o.min_points || field.occupied_cells() < o.min_map_cells) return result;

  const auto& g = field.geometry();
  const double res = g.resolution();
  double max_r = 0.0;
  for (const auto& p : points) max_r = std::max(max_r, p.norm());
  const double dtheta = o.angular_step_rad > 0 ? o.angular_step_rad : std::clamp(res / std::max(max_r, res), 0.002, 0.05);
  const int nt = int(std::ceil(o.search_theta_rad / dtheta));
  const int nxy = int(std::ceil(o.search_xy_m / res));
  const int side = 2 * nxy + 1;
  // One cell offset along the grid axes, in world metres (the grid may be turned).
  const Eigen::Vector2d ex = g.grid_to_world({1.0, 0.0}) - g.grid_to_world({0.0, 0.0});
  const Eigen::Vector2d ey = g.grid_to_world({0.0, 1.0}) - g.grid_to_world({0.0, 0.0});

  struct Candidate {
    double score;
    double dx, dy, dt;  // world metres, radians
  };
  const double gain = o.independent_beams > 0 ? std::min(1.0, o.independent_beams / double(points.size())) : 1.0;
  std::vector<Candidate> all;
  all.reserve(std::size_t(2 * nt + 1) * std::size_t(side * side));
  std::vector<Eigen::Vector2d> grid_points(points.size());
  std::vector<double> sums(std::size_t(side * side));
  for (int it = -nt; it <= nt; ++it) {
    const double dt = it * dtheta;
    const core::Pose2 turned(guess.x, guess.y, guess.theta + dt);
    for (std::size_t k = 0; k < points.size(); ++k) grid_points[k] = g.world_to_grid(turned.transform(points[k]));
    std::fill(sums.begin(), sums.end(), 0.0);
    for (const auto& gp : grid_points) {
      // The offsets are whole cells: the cell of gp + (ix, iy) is gp's cell + (ix, iy).
      const int cx = int(std::floor(gp.x())), cy = int(std::floor(gp.y()));
      for (int iy = -nxy; iy <= nxy; ++iy) field.add_nearest_row(cx - nxy, cy + iy, side, &sums[std::size_t((iy + nxy) * side)]);
    }
    for (int iy = -nxy; iy <= nxy; ++iy) {
      for (int ix = -nxy; ix <= nxy; ++ix) {
        const Eigen::Vector2d d = ix * ex + iy * ey;
        const core::Pose2 p(guess.x + d.x(), guess.y + d.y(), guess.theta + dt);
        all.push_back({gain * sums[std::size_t((iy + nxy) * side + ix + nxy)] + log_prior(p, centre, o), d.x(), d.y(), dt});
      }
    }
  }
  const auto best = std::max_element(all.begin(), all.end(), [](const Candidate& a, const Candidate& b) {
    return a.score < b.score;
  });

  // Covariance of the candidates weighted by their likelihood (Olson 2009, §IV-B), floored by the
  // search resolution.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  double total = 0.0;
  for (const auto& c : all) {
    const double w = std::exp(c.score - best->score);
    if (w < 1e-12) continue;
    const Eigen::Vector3d v(c.dx, c.dy, c.dt);
    mean += w * v;
    second += w * v * v.transpose();
    total += w;
  }
  result.log_normalizer = best->score + std::log(total);
  mean /= total;
  Eigen::Matrix3d cov = second / total - mean * mean.transpose();
  cov += Eigen::Vector3d(res * res / 12.0, res * res / 12.0, dtheta * dtheta / 12.0).asDiagonal().toDenseMatrix();

  const core::Pose2 start(guess.x + best->dx, guess.y + best->dy, guess.theta + best->dt);
  const auto objective = [&](const core::Pose2& p) {
    return gain * field.score(transform_points(p, points)) + log_prior(p, centre, o);
  };
  const auto [pose, score] = climb(objective, start, 0.5 * res, 0.5 * dtheta, o.refine_iterations);
  result.matched = true;
  result.pose = pose;
  result.log_likelihood = field.score(transform_points(pose, points));
  result.covariance = cov;
  return result;
}

ScanMatch match_scan_to_grid(const CowGrid& map, const RangeScan& scan, const core::Pose2& guess,
                             const ScanMatcherOptions& o, const std::optional<core::Pose2>& prior_mean) {
  const auto points = scan_end_points(scan, o.beam_stride);
  // The field is needed only where an end point can land during the search: around the end points
  // at the guess, by how far the search's turn and shift move the farthest one, and the field's
  // reach beyond (nearer walls than max_distance_m are all inside). Smaller than the scan's range
  // all round, which a room or a corridor seldom fills.
  const auto& g = map.geometry();
  double max_r = 0.0;
  Eigen::Vector2d lo = g.world_to_grid(guess.position()), hi = lo;  // grid coordinates (cells)
  for (const auto& p : points) {
    max_r = std::max(max_r, p.norm());
    const Eigen::Vector2d c = g.world_to_grid(guess.transform(p));
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  const double turn = std::min(o.search_theta_rad, M_PI);
  const double margin = (max_r * 2.0 * std::sin(0.5 * turn) + o.search_xy_m + o.field.max_distance_m) / g.resolution() + 2.0;
  const CellWindow reach = window_around(g, guess.position(), scan.max_range + o.search_xy_m + o.field.max_distance_m);
  CellWindow window;
  window.x0 = std::clamp(int(std::floor(lo.x() - margin)), reach.x0, reach.x1);
  window.y0 = std::clamp(int(std::floor(lo.y() - margin)), reach.y0, reach.y1);
  window.x1 = std::clamp(int(std::ceil(hi.x() + margin)) + 1, window.x0, reach.x1);
  window.y1 = std::clamp(int(std::ceil(hi.y() + margin)) + 1, window.y0, reach.y1);
  const LikelihoodField field(
      map.geometry(), window, [&](int x, int y) { return map.occupied(x, y); }, o.field,
      [&](int x, int y) { return map.hit_mean(x, y); });
  return match_scan(field, points, guess, o, prior_mean);
}

}  // namespace fleetmap::localization
