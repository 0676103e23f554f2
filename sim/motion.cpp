#include "sim/motion.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/angle.h"
#include "localization/localizer.h"

namespace fleetmap::sim {

namespace {

// Distance (m) from p to the nearest occupied cell's square of `map`, looking `horizon_m` around.
double occupied_clearance(const mapping::OccupancyGrid& map, const Eigen::Vector2d& p, double horizon_m) {
  const double res = map.resolution();
  const Eigen::Vector2d g = map.geometry().world_to_grid(p);
  const int cx = int(std::floor(g.x())), cy = int(std::floor(g.y()));
  const int r = int(std::ceil(horizon_m / res)) + 1;
  double best2 = horizon_m * horizon_m;
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      const core::Cell c{cx + dx, cy + dy};
      if (map.state(c) != mapping::CellState::Occupied) continue;
      const double ex = std::max({double(c.x) - g.x(), 0.0, g.x() - double(c.x + 1)});
      const double ey = std::max({double(c.y) - g.y(), 0.0, g.y() - double(c.y + 1)});
      best2 = std::min(best2, (ex * ex + ey * ey) * res * res);
    }
  }
  return std::sqrt(best2);
}

// The disc never comes closer to an occupied cell of `map` along the segment a-b (sampled every half
// cell) than `radius_m`, or than it already is at a when that is less.
bool segment_clear(const mapping::OccupancyGrid& map, const Eigen::Vector2d& a, const Eigen::Vector2d& b, double radius_m) {
  const double need = std::min(radius_m, occupied_clearance(map, a, radius_m) - 1e-6);
  const int samples = std::max(1, int(std::ceil((b - a).norm() / (0.5 * map.resolution()))));
  for (int k = 1; k <= samples; ++k) {
    if (occupied_clearance(map, a + (b - a) * (double(k) / samples), radius_m) < need) return false;
  }
  return true;
}

// Along the arc a robot at `from` drives with (v, omega) for `period_s`, sampled as finely as the
// simulator checks a move, the disc stays radius + a hundredth of a cell from every occupied cell of
// `map` (an arc that grazes a wall at exactly the radius is one the simulator stops), except the
// cells it already overlaps at `from`: on the robot's own map those are noise (a range reading
// that fell short marks the free cell before a wall) or what it touched; moving away must stay
// possible.
bool arc_clear(const mapping::OccupancyGrid& map, const core::Pose2& from, double v, double omega, double period_s,
               double radius_m) {
  const double res = map.resolution();
  const double need = radius_m + 0.01 * res;
  const Eigen::Vector2d start = map.geometry().world_to_grid(from.position());
  const double overlap = radius_m / res;  // in cells
  const auto overlapped = [&](const core::Cell& c) {
    const double ex = std::max({double(c.x) - start.x(), 0.0, start.x() - double(c.x + 1)});
    const double ey = std::max({double(c.y) - start.y(), 0.0, start.y() - double(c.y + 1)});
    return ex * ex + ey * ey < overlap * overlap;
  };
  const int samples = std::max(1, int(std::ceil(std::abs(v) * period_s / (0.25 * res))));
  const int r = int(std::ceil(need / res)) + 1;
  for (int k = 1; k <= samples; ++k) {
    const double f = double(k) / samples;
    const Eigen::Vector2d q = map.geometry().world_to_grid(
        localization::integrate_motion(from, {v * f, omega * f, period_s}).position());
    const int cx = int(std::floor(q.x())), cy = int(std::floor(q.y()));
    for (int dy = -r; dy <= r; ++dy) {
      for (int dx = -r; dx <= r; ++dx) {
        const core::Cell c{cx + dx, cy + dy};
        if (map.state(c) != mapping::CellState::Occupied || overlapped(c)) continue;
        const double ex = std::max({double(c.x) - q.x(), 0.0, q.x() - double(c.x + 1)});
        const double ey = std::max({double(c.y) - q.y(), 0.0, q.y() - double(c.y + 1)});
        if ((ex * ex + ey * ey) * res * res < need * need) return false;
      }
    }
  }
  return true;
}

}  // namespace

Command clear_on_map(Command c, const core::Pose2& estimate, const mapping::OccupancyGrid& own_map, const RobotOptions& robot,
                     double period_s) {
  const double v = c.v;
  c.v = 0.0;
  for (double scale : {1.0, 0.75, 0.5, 0.25, 0.1}) {
    if (v == 0.0) break;
    if (arc_clear(own_map, estimate, v * scale, c.omega, period_s, robot.radius_m)) {
      c.v = v * scale;
      break;
    }
  }
  return c;
}

Command follow_path(const core::Pose2& estimate, const std::vector<Eigen::Vector2d>& path,
                    const mapping::OccupancyGrid& own_map, const RobotOptions& robot, double period_s, double lookahead_m) {
  if (path.empty()) return {};
  const Eigen::Vector2d p = estimate.position();
  Eigen::Vector2d aim = path.front();
  for (const auto& q : path) {
    if ((q - p).norm() > lookahead_m) break;
    if (segment_clear(own_map, p, q, robot.radius_m)) aim = q;
  }
  const Eigen::Vector2d d = aim - p;
  const double dist_to_end = (path.back() - p).norm();
  if (d.norm() < 1e-9) return {};
  const double error = core::normalize_angle(std::atan2(d.y(), d.x()) - estimate.theta);
  Command c;
  c.omega = std::clamp(error / period_s, -robot.max_turn_rate_rps, robot.max_turn_rate_rps);
  if (std::abs(error) <= std::numbers::pi / 3.0) {
    c.v = std::min({robot.max_speed_mps, dist_to_end / period_s, d.norm() / period_s}) * std::cos(error);
  }
  return clear_on_map(c, estimate, own_map, robot, period_s);
}

Command escape_command(const core::Pose2& estimate, const mapping::OccupancyGrid& own_map, double period_s,
                       const std::vector<Eigen::Vector2d>& bumped, double radius_m) {
  constexpr double kStep = 0.15;
  constexpr int kDirections = 16;
  const Eigen::Vector2d p = estimate.position();
  double best = -1.0, best_angle = estimate.theta;
  for (int k = 0; k < kDirections; ++k) {
    const double a = estimate.theta + 2.0 * std::numbers::pi * k / kDirections;
    const Eigen::Vector2d q = p + kStep * Eigen::Vector2d(std::cos(a), std::sin(a));
    double c = occupied_clearance(own_map, q, 1.0);
    for (const auto& b : bumped) c = std::min(c, (q - b).norm() - 2.0 * radius_m);
    if (c > best + 1e-9) best = c, best_angle = a;
  }
  const double e = core::normalize_angle(best_angle - estimate.theta);
  Command c;
  c.v = kStep * std::cos(e) / period_s;  // negative: backwards
  return c;
}

localization::Odometry misreport_odometry(const localization::Odometry& driven, const OdometryError& e,
                                          core::Random& rng) {
  localization::Odometry r = driven;
  r.v = driven.v * (1.0 + e.scale_error) + rng.normal(0.0, e.speed_noise_mps);
  r.omega = driven.omega + e.turn_bias_rad_per_m * std::abs(driven.v) + rng.normal(0.0, e.turn_noise_rps);
  return r;
}

bool clear_of_robots(int self, const Eigen::Vector2d& p, const std::vector<core::Pose2>& truths, double radius_m) {
  for (std::size_t j = 0; j < truths.size(); ++j) {
    if (int(j) != self && (truths[j].position() - p).norm() < 2.0 * radius_m) return false;
  }
  return true;
}

MoveResult move_robot(const World& world, int self, const std::vector<core::Pose2>& truths, const RobotOptions& robot,
                      const Command& command, double period_s, const MotionNoise& noise, core::Random& rng) {
  const core::Pose2 start = truths[std::size_t(self)];
  const auto valid = [&](const Eigen::Vector2d& q) {
    return world.disc_free(q, robot.radius_m) && clear_of_robots(self, q, truths, robot.radius_m);
  };
  const double v = std::clamp(command.v, -robot.max_speed_mps, robot.max_speed_mps);
  const double w = std::clamp(command.omega, -robot.max_turn_rate_rps, robot.max_turn_rate_rps);
  const double res = world.geometry().resolution();
  // The whole arc, checked in sub-steps of a quarter cell, must stay clear.
  const auto arc_clear = [&](double speed) {
    const int substeps = std::max(1, int(std::ceil(std::abs(speed) * period_s / (0.25 * res))));
    for (int k = 1; k <= substeps; ++k) {
      const double f = double(k) / substeps;
      if (!valid(localization::integrate_motion(start, {speed * f, w * f, period_s}).position())) return false;
    }
    return true;
  };
  // A blocked move is slowed down along the same turn, down to turning in place (always possible:
  // the disc does not move), so the robot can turn away from what stopped it.
  MoveResult out;
  double speed = 0.0;
  for (double scale : {1.0, 0.75, 0.5, 0.25, 0.1}) {
    if (v == 0.0) break;
    if (arc_clear(v * scale)) {
      speed = v * scale;
      break;
    }
  }
  out.blocked = v != 0.0 && speed != v;
  if (out.blocked) {
    // The first sub-step of the full move that failed: if a wall stopped it, that is the contact.
    const int substeps = std::max(1, int(std::ceil(std::abs(v) * period_s / (0.25 * res))));
    for (int k = 1; k <= substeps; ++k) {
      const double f = double(k) / substeps;
      const Eigen::Vector2d q = localization::integrate_motion(start, {v * f, w * f, period_s}).position();
      if (valid(q)) continue;
      if (!world.disc_free(q, robot.radius_m)) {
        out.contact = world.nearest_blocked_point(q, robot.radius_m);
      } else {
        for (std::size_t j = 0; j < truths.size() && !out.robot; ++j) {
          if (int(j) != self && (truths[j].position() - q).norm() < 2.0 * robot.radius_m) out.robot = int(j);
        }
      }
      break;
    }
  }
  out.odometry = {speed, w, period_s};
  out.pose = localization::integrate_motion(start, out.odometry);
  out.distance_m = std::abs(speed) * period_s;
  // Process noise (the model's w_k), kept only where it leaves the robot clear.
  core::Pose2 noisy(rng.normal(out.pose.x, noise.position_m), rng.normal(out.pose.y, noise.position_m),
                    rng.normal(out.pose.theta, noise.heading_rad));
  if (valid(noisy.position())) out.pose = noisy;
  return out;
}

}  // namespace fleetmap::sim
