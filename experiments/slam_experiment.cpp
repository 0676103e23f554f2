#include "experiments/slam_experiment.h"

#include <Eigen/Dense>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>

#include "core/format.h"
#include "core/angle.h"
#include "core/error.h"
#include "core/random.h"
#include "localization/polynomial_slam.h"
#include "merging/polynomial_exchange.h"
#include "sim/motion.h"
#include "sim/sensors.h"

namespace fleetmap::experiments {

namespace {

// Even-odd rule.
bool inside(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p) {
  bool in = false;
  for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      in = !in;
    }
  }
  return in;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::string format_point(const Eigen::Vector2d& p) {
  return core::format_point(p);
}

}  // namespace

mapping::OccupancyGrid rasterize_room(const SlamRoom& room, double margin_m) {
  Eigen::Vector2d lo = room.boundary.front(), hi = room.boundary.front();
  for (const auto& p : room.boundary) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double res = room.resolution_m;
  const int pad = 1 + int(std::ceil(std::max(0.0, margin_m) / res));
  const int w = int(std::ceil((hi.x() - lo.x()) / res)) + 2 * pad;
  const int h = int(std::ceil((hi.y() - lo.y()) / res)) + 2 * pad;
  if (double(w) * double(h) > 64e6) {
    throw InputError("room: the room at resolution " + std::to_string(res) + " m needs more than 64 M cells");
  }
  mapping::OccupancyGrid grid(core::GridGeometry(res, w, h, core::Pose2(lo.x() - pad * res, lo.y() - pad * res, 0.0)));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector2d c = grid.geometry().cell_center({x, y});
      bool free = inside(room.boundary, c);
      for (const auto& o : room.obstacles) free = free && !inside(o, c);
      grid.set_state({x, y}, free ? mapping::CellState::Free : mapping::CellState::Occupied);
    }
  }
  return grid;
}

std::vector<localization::Odometry> path_commands(const core::Pose2& start, const std::vector<Eigen::Vector2d>& path,
                                                  double speed, int steps, double period_s, double max_turn_rate) {
  std::vector<localization::Odometry> out;
  out.reserve(std::size_t(std::max(0, steps)));
  core::Pose2 pose = start;
  std::size_t next = 0;
  const double reached = std::max(0.05, 0.5 * speed * period_s);
  for (int k = 0; k < steps; ++k) {
    while (next < path.size() && (path[next] - pose.position()).norm() <= reached) ++next;
    localization::Odometry u{0.0, 0.0, period_s};
    if (next < path.size()) {
      const Eigen::Vector2d d = path[next] - pose.position();
      const double error = core::normalize_angle(std::atan2(d.y(), d.x()) - pose.theta);
      u.omega = std::clamp(error / period_s, -max_turn_rate, max_turn_rate);
      if (std::abs(error) <= std::numbers::pi / 3.0) {
        u.v = std::min(speed, d.norm() / period_s) * std::cos(error);
      }
    }
    out.push_back(u);
    pose = localization::integrate_motion(pose, u);
  }
  return out;
}

SlamSetup prepare_slam(const SlamScenario& scenario) {
  validate_slam_scenario(scenario);
  SlamSetup setup{scenario, sim::World(rasterize_room(scenario.room), {}), room_walls(scenario.room), {}, {}};
  for (std::size_t i = 0; i < scenario.robots.size(); ++i) {
    const SlamRobot& r = scenario.robots[i];
    const std::string key = "robots.team[" + std::to_string(i) + "] (" + r.name + ")";
    if (!setup.world.disc_free(r.start.position(), scenario.robot.radius_m)) {
      throw InputError(key + ": start " + format_point(r.start.position()) + " is within the robot's radius (" +
                       std::to_string(scenario.robot.radius_m) + " m) of a wall or outside the room");
    }
    auto commands = path_commands(r.start, r.path, std::min(r.speed_mps, scenario.robot.max_speed_mps), scenario.steps,
                                  scenario.period_s, scenario.robot.max_turn_rate_rps);
    std::vector<core::Pose2> planned = {r.start};
    for (std::size_t k = 0; k < commands.size(); ++k) {
      planned.push_back(localization::integrate_motion(planned.back(), commands[k]));
      if (!setup.world.disc_free(planned.back().position(), scenario.robot.radius_m)) {
        throw InputError(key + ": path: at step " + std::to_string(k + 1) + " the robot would be at " +
                         format_point(planned.back().position()) + ", within its radius of a wall");
      }
    }
    setup.commands.push_back(std::move(commands));
    setup.planned.push_back(std::move(planned));
  }
  return setup;
}

namespace {

// D'Alfonso et al.'s polynomial SLAM, one filter per robot.
SlamRunResult run_polynomial_slam(const SlamSetup& setup, int run, bool exchange, int only) {
  const SlamScenario& sc = setup.scenario;
  std::vector<int> team;  // scenario robot index of each robot in this run
  for (int i = 0; i < int(sc.robots.size()); ++i) {
    if (only < 0 || only == i) team.push_back(i);
  }
  const int n = int(team.size());
  const core::Random run_rng = core::Random(sc.seed).fork(std::uint64_t(run));
  std::vector<core::Random> motion_rng, sensor_rng, camera_rng;
  const Eigen::Matrix3d p0 =
      Eigen::Vector3d(sc.initial_sigma_xy * sc.initial_sigma_xy, sc.initial_sigma_xy * sc.initial_sigma_xy,
                      sc.initial_sigma_heading * sc.initial_sigma_heading)
          .asDiagonal();
  const Eigen::Matrix3d q = Eigen::Vector3d(sc.noise.position_m * sc.noise.position_m,
                                            sc.noise.position_m * sc.noise.position_m,
                                            sc.noise.heading_rad * sc.noise.heading_rad)
                                .asDiagonal();
  std::vector<localization::PolynomialSlam> slam;
  std::vector<core::Pose2> truths;
  std::vector<localization::LocalizationMetrics> metrics(static_cast<std::size_t>(n));
  std::vector<double> busy(std::size_t(n), 0.0);
  SlamRunResult result;
  result.run = run;
  result.exchange = exchange;
  for (int a = 0; a < n; ++a) {
    const int r = team[std::size_t(a)];
    motion_rng.push_back(run_rng.fork(100 + std::uint64_t(r)));
    sensor_rng.push_back(run_rng.fork(200 + std::uint64_t(r)));
    camera_rng.push_back(run_rng.fork(300 + std::uint64_t(r)));
    // Each robot starts from x_j,0 = [0 0 0] in its own frame R_j,0 (§3.2).
    slam.emplace_back(core::Pose2(), p0, q, sc.polynomial);
    truths.push_back(sc.robots[std::size_t(r)].start);
    SlamRobotResult rr;
    rr.name = sc.robots[std::size_t(r)].name;
    result.robots.push_back(std::move(rr));
  }
  std::vector<std::vector<char>> was_mutual(std::size_t(n), std::vector<char>(std::size_t(n), 0));
  std::vector<std::vector<long>> sent_upto(std::size_t(n), std::vector<long>(std::size_t(n), 0));

  const auto record = [&]() {
    for (int a = 0; a < n; ++a) {
      const core::Pose2& start = sc.robots[std::size_t(team[std::size_t(a)])].start;
      // mu's x~: the estimate compensated by the bias of x_j,0 = [0 0 0] (§4); P turned with it.
      const core::Pose2 estimate = start.compose(slam[std::size_t(a)].pose());
      Eigen::Matrix3d j = Eigen::Matrix3d::Identity();
      j.topLeftCorner<2, 2>() = start.as_transform().rotation_matrix();
      const Eigen::Matrix3d p = j * slam[std::size_t(a)].pose_covariance() * j.transpose();
      metrics[std::size_t(a)].add(truths[std::size_t(a)], estimate, p);
      result.robots[std::size_t(a)].truth.push_back(truths[std::size_t(a)]);
      result.robots[std::size_t(a)].estimate.push_back(estimate);
    }
  };

  const auto sense_and_update = [&]() {
    for (int a = 0; a < n; ++a) {
      const localization::RangeScan scan = sim::read_ranges(setup.world, truths[std::size_t(a)], sc.range, sensor_rng[std::size_t(a)]);
      const auto t0 = std::chrono::steady_clock::now();
      slam[std::size_t(a)].update(scan.angles, scan.ranges);
      busy[std::size_t(a)] += seconds_since(t0);
    }
  };

  const auto rendezvous = [&](int step) {
    std::vector<std::vector<sim::Detection>> seen(static_cast<std::size_t>(n));
    for (int a = 0; a < n; ++a) seen[std::size_t(a)] = sim::detect_robots(setup.world, a, truths, sc.camera, camera_rng[std::size_t(a)]);
    const auto find = [&](int a, int b) -> const sim::Detection* {
      for (const auto& d : seen[std::size_t(a)]) {
        if (d.other == b) return &d;
      }
      return nullptr;
    };
    for (int a = 0; a < n; ++a) {
      for (int b = a + 1; b < n; ++b) {
        const sim::Detection* ab = find(a, b);
        const sim::Detection* ba = find(b, a);
        const bool mutual = ab != nullptr && ba != nullptr;
        // A rendezvous is the step two robots start seeing each other (a choice: the paper does
        // not say how often robots that keep seeing each other exchange).
        const bool meets = mutual && !was_mutual[std::size_t(a)][std::size_t(b)];
        was_mutual[std::size_t(a)][std::size_t(b)] = mutual;
        if (!meets || !exchange) continue;
        // Both messages are built before either is merged, so neither echoes the other.
        struct Outgoing {
          int from, to;
          merging::PolynomialMessage message;
        };
        std::vector<Outgoing> outgoing;
        for (const auto& [l, j, seen_lj] : {std::tuple{a, b, ab}, std::tuple{b, a, ba}}) {
          const auto& sender = slam[std::size_t(l)];
          merging::PolynomialMessage m;
          m.sender_pose = sender.pose();
          m.sender_covariance = sender.pose_covariance();
          m.distance = seen_lj->range;
          m.bearing_sender_to_receiver = seen_lj->bearing;
          long upto = sent_upto[std::size_t(l)][std::size_t(j)];
          for (std::size_t i = 0; i < sender.map().landmarks.size(); ++i) {
            const auto& landmark = sender.map().landmarks[i];
            upto = std::max(upto, landmark.id + 1);
            // Remark 1: only what was extracted since the last rendezvous with this robot.
            if (landmark.id < sent_upto[std::size_t(l)][std::size_t(j)]) continue;
            if (landmark.received_from == team[std::size_t(j)]) continue;
            m.polynomials.push_back(landmark.polynomial);
            m.position_variances.push_back(sender.position_variance(int(i)));
          }
          sent_upto[std::size_t(l)][std::size_t(j)] = upto;
          outgoing.push_back({l, j, std::move(m)});
        }
        for (const auto& o : outgoing) {
          const sim::Detection* seen_jl = find(o.to, o.from);
          merging::ExchangeOptions options;
          options.segment_tolerance = sc.segment_tolerance_m;
          options.range_noise = sc.camera.range_noise_m;
          options.bearing_noise = sc.camera.bearing_noise_rad;
          auto& receiver = slam[std::size_t(o.to)];
          const auto t0 = std::chrono::steady_clock::now();
          const auto curves = merging::receive_polynomials(o.message, receiver.pose(), seen_jl->range, seen_jl->bearing,
                                                           team[std::size_t(o.from)], options);
          receiver.integrate_received(curves);
          busy[std::size_t(o.to)] += seconds_since(t0);
          result.rendezvous.push_back({step, team[std::size_t(o.from)], team[std::size_t(o.to)],
                                       int(o.message.polynomials.size()), merging::message_bytes(o.message),
                                       merging::grid_patch_bytes(o.message.polynomials, sc.grid_patch_resolution_m)});
        }
      }
    }
  };

  // Step 0: the first readings, before moving.
  sense_and_update();
  rendezvous(0);
  record();
  for (int k = 1; k <= sc.steps; ++k) {
    for (int a = 0; a < n; ++a) {
      const auto& u = setup.commands[std::size_t(team[std::size_t(a)])][std::size_t(k - 1)];
      const sim::MoveResult mv = sim::move_robot(setup.world, a, truths, sc.robot, {u.v, u.omega}, sc.period_s, sc.noise,
                                       motion_rng[std::size_t(a)]);
      truths[std::size_t(a)] = mv.pose;
      const auto t0 = std::chrono::steady_clock::now();
      slam[std::size_t(a)].predict(mv.odometry);
      busy[std::size_t(a)] += seconds_since(t0);
    }
    sense_and_update();
    rendezvous(k);
    record();
  }

  for (int a = 0; a < n; ++a) {
    SlamRobotResult& rr = result.robots[std::size_t(a)];
    const auto& s = slam[std::size_t(a)];
    const core::Transform2 frame = sc.robots[std::size_t(team[std::size_t(a)])].start.as_transform();
    const std::vector<mapping::Polynomial> polys = s.map().polynomials();
    rr.localization = metrics[std::size_t(a)].summary();
    rr.mapping = mapping::mapping_error(polys, frame, setup.walls, 0.01);
    rr.boundary_coverage = mapping::boundary_coverage(polys, frame, setup.walls, 0.1, 0.02);
    rr.tau_s = busy[std::size_t(a)] / double(sc.steps + 1);
    rr.polynomials = int(polys.size());
    for (const auto& p : polys) {
      std::vector<Eigen::Vector2d> curve;
      for (const auto& q : mapping::sample_arc_length(p, 0.02)) curve.push_back(frame * q);
      rr.map_curves.push_back(std::move(curve));
    }
    const auto& c = s.counters();
    rr.counters = {{"good_points", double(c.good_points)},
                   {"bad_points", double(c.bad_points)},
                   {"cluster_points", double(c.cluster_points)},
                   {"updates", double(c.updates)},
                   {"rejected_readings", double(c.rejected_readings)},
                   {"polynomials_created", double(c.polynomials_created)},
                   {"refits", double(c.refits)},
                   {"merges", double(c.merges)},
                   {"received", double(c.received)},
                   {"diverged_steps", double(c.diverged_steps)},
                   {"clusters", double(s.map().clusters.size())}};
  }
  return result;
}

using SlamMethod = std::function<SlamRunResult(const SlamSetup&, int, bool, int)>;

// The SLAM methods by name: one row per name of slam_method_names().
const std::vector<std::pair<std::string, SlamMethod>>& slam_methods() {
  static const std::vector<std::pair<std::string, SlamMethod>> kMethods = {
      {"polynomial", run_polynomial_slam},
  };
  return kMethods;
}

}  // namespace

SlamRunResult run_slam(const SlamSetup& setup, int run, bool exchange, int only) {
  for (const auto& [name, method] : slam_methods()) {
    if (name == setup.scenario.method) return method(setup, run, exchange, only);
  }
  throw InputError("method: no SLAM method is named '" + setup.scenario.method + "'");
}

}  // namespace fleetmap::experiments
