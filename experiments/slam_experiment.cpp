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
#include "localization/polynomial_localizer.h"
#include "merging/polynomial_exchange.h"
#include "sim/simulation.h"

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
  SlamSetup setup{scenario, make_slam_method(scenario.method, scenario.method_settings),
                  sim::World(rasterize_room(scenario.room), {}), room_walls(scenario.room), {}, {}};
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

// Each robot's localizer is the `polynomial` one, built with the scenario's options (below).
const localization::PolynomialSlam& filter_of(const sim::Simulation& s, int robot) {
  return dynamic_cast<const localization::PolynomialLocalizer&>(s.localizer(robot)).slam();
}

localization::PolynomialSlam& filter_of(sim::Simulation& s, int robot) {
  return dynamic_cast<localization::PolynomialLocalizer&>(s.localizer(robot)).slam();
}

// The smallest grid at the room's resolution that holds the whole room in the frame of a robot
// starting at `start` (its own map is not this experiment's output; the polynomials are).
core::GridGeometry room_in_frame(const core::GridGeometry& room, const core::Pose2& start) {
  const core::Transform2 to_frame = start.as_transform().inverse();
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& corner : {Eigen::Vector2d(0, 0), Eigen::Vector2d(room.width(), 0), Eigen::Vector2d(0, room.height()),
                             Eigen::Vector2d(room.width(), room.height())}) {
    const Eigen::Vector2d p = to_frame.apply(room.grid_to_world(corner));
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double res = room.resolution();
  return core::GridGeometry(res, int(std::ceil((hi.x() - lo.x()) / res)), int(std::ceil((hi.y() - lo.y()) / res)),
                            core::Pose2(lo.x(), lo.y(), 0.0));
}

// The rendezvous of D'Alfonso et al. §3.2 between robots a and b of the simulation: each sends the
// other the polynomials extracted since their last rendezvous, with its pose and the camera's
// reading of the other; both messages are built before either is merged, so neither echoes the other.
class PolynomialExchange {
 public:
  PolynomialExchange(const SlamScenario& scenario, const std::vector<int>& team, bool enabled, SlamRunResult& result)
      : sc_(scenario), team_(team), enabled_(enabled), result_(result),
        sent_upto_(team.size(), std::vector<long>(team.size(), 0)), seconds_(team.size(), 0.0) {}

  // A rendezvous is the step two robots start seeing each other (a choice: the paper does not say
  // how often robots that keep seeing each other exchange).
  void operator()(sim::Simulation& s, int a, int b) {
    const sim::Detection* ab = s.detection(a, b);
    const sim::Detection* ba = s.detection(b, a);
    if (!enabled_ || ab == nullptr || ba == nullptr) return;
    struct Outgoing {
      int from, to;
      merging::PolynomialMessage message;
    };
    std::vector<Outgoing> outgoing;
    for (const auto& [l, j, seen_lj] : {std::tuple{a, b, ab}, std::tuple{b, a, ba}}) {
      const auto& sender = filter_of(s, l);
      merging::PolynomialMessage m;
      m.sender_pose = sender.pose();
      m.sender_covariance = sender.pose_covariance();
      m.distance = seen_lj->range;
      m.bearing_sender_to_receiver = seen_lj->bearing;
      long& sent = sent_upto_[std::size_t(l)][std::size_t(j)];
      long upto = sent;
      for (std::size_t i = 0; i < sender.map().landmarks.size(); ++i) {
        const auto& landmark = sender.map().landmarks[i];
        upto = std::max(upto, landmark.id + 1);
        // Remark 1: only what was extracted since the last rendezvous with this robot.
        if (landmark.id < sent) continue;
        if (landmark.received_from == team_[std::size_t(j)]) continue;
        m.polynomials.push_back(landmark.polynomial);
        m.position_variances.push_back(sender.position_variance(int(i)));
      }
      sent = upto;
      outgoing.push_back({l, j, std::move(m)});
    }
    for (const auto& o : outgoing) {
      const sim::Detection* seen_jl = s.detection(o.to, o.from);
      merging::ExchangeOptions options;
      options.segment_tolerance = sc_.segment_tolerance_m;
      options.range_noise = sc_.camera.range_noise_m;
      options.bearing_noise = sc_.camera.bearing_noise_rad;
      auto& receiver = filter_of(s, o.to);
      const auto t0 = std::chrono::steady_clock::now();
      const auto curves = merging::receive_polynomials(o.message, receiver.pose(), seen_jl->range, seen_jl->bearing,
                                                       team_[std::size_t(o.from)], options);
      receiver.integrate_received(curves);
      seconds_[std::size_t(o.to)] += seconds_since(t0);
      result_.rendezvous.push_back({s.step_count(), team_[std::size_t(o.from)], team_[std::size_t(o.to)],
                                    int(o.message.polynomials.size()), merging::message_bytes(o.message),
                                    merging::grid_patch_bytes(o.message.polynomials, sc_.grid_patch_resolution_m)});
    }
  }

  // Time robot a spent merging what it received.
  double seconds(int a) const { return seconds_[std::size_t(a)]; }

 private:
  const SlamScenario& sc_;
  const std::vector<int>& team_;
  bool enabled_;
  SlamRunResult& result_;
  std::vector<std::vector<long>> sent_upto_;
  std::vector<double> seconds_;
};

// D'Alfonso et al.'s polynomial SLAM, one filter per robot, on the simulator: each robot in its own
// frame R_j,0, driven by its precomputed commands, its camera on a stream of its own.
SlamRunResult run_polynomial_slam(const SlamSetup& setup, const localization::PolynomialSlamOptions& options, int run,
                                  bool exchange, int only) {
  const SlamScenario& sc = setup.scenario;
  std::vector<int> team;  // scenario robot index of each robot in this run
  for (int i = 0; i < int(sc.robots.size()); ++i) {
    if (only < 0 || only == i) team.push_back(i);
  }
  const int n = int(team.size());
  const core::Random run_rng = core::Random(sc.seed).fork(std::uint64_t(run));
  const Eigen::Matrix3d p0 =
      Eigen::Vector3d(sc.initial_sigma_xy * sc.initial_sigma_xy, sc.initial_sigma_xy * sc.initial_sigma_xy,
                      sc.initial_sigma_heading * sc.initial_sigma_heading)
          .asDiagonal();
  const Eigen::Matrix3d q = Eigen::Vector3d(sc.noise.position_m * sc.noise.position_m,
                                            sc.noise.position_m * sc.noise.position_m,
                                            sc.noise.heading_rad * sc.noise.heading_rad)
                                .asDiagonal();
  std::vector<core::Pose2> start_estimates;  // per robot, in its own frame
  SlamRunResult result;
  result.run = run;
  result.exchange = exchange;

  sim::Scenario scenario;
  scenario.seed = run_rng.seed();
  scenario.steps = sc.steps;
  scenario.period_s = sc.period_s;
  scenario.placement = sim::Placement::List;
  scenario.robot = sc.robot;
  scenario.noise = sc.noise;
  scenario.range = sc.range;
  scenario.detector = sc.camera;
  scenario.localization = "polynomial";
  scenario.merging = "rendezvous";       // each robot maps in its own frame R_j,0 (§3.2)
  scenario.communication.range_m = 0.0;  // robots talk when they see each other
  sim::SimulationSetup how;
  how.measure_coverage = false;
  for (int a = 0; a < n; ++a) {
    const int r = team[std::size_t(a)];
    const SlamRobot& robot = sc.robots[std::size_t(r)];
    scenario.starts.push_back(robot.start);
    // Each robot starts from x_j,0 = [0 0 0] in its own frame R_j,0 (§3.2), or from a draw of P0
    // around it (sampled_start: then the truth is off the estimate as P0 says).
    core::Pose2 start_estimate;
    if (sc.sampled_start) {
      core::Random start_rng = run_rng.fork(400 + std::uint64_t(r));
      start_estimate = core::Pose2(start_rng.normal(0.0, sc.initial_sigma_xy), start_rng.normal(0.0, sc.initial_sigma_xy),
                                   start_rng.normal(0.0, sc.initial_sigma_heading));
    }
    start_estimates.push_back(start_estimate);
    sim::RobotSetup rs;
    std::vector<sim::Command> commands;
    for (const auto& u : setup.commands[std::size_t(r)]) commands.push_back({u.v, u.omega});
    rs.driver = std::make_shared<sim::CommandScript>(std::move(commands));
    // The simulator's initial pose is x_j,0 in the robot's own frame; the filter starts there or at
    // the draw, with the method's options, P0 and Q, reading every distance sensor.
    rs.localizer = [&, start_estimate](const localization::LocalizerContext& c) {
      return std::make_unique<localization::PolynomialLocalizer>(c.initial_pose.compose(start_estimate), p0, q,
                                                                 options);
    };
    // Streams by the robot's index in the scenario, so that a robot alone has its noise in the team.
    rs.motion_rng = std::make_shared<core::Random>(run_rng.fork(100 + std::uint64_t(r)));
    rs.sensor_rng = std::make_shared<core::Random>(run_rng.fork(200 + std::uint64_t(r)));
    rs.detector_rng = std::make_shared<core::Random>(run_rng.fork(300 + std::uint64_t(r)));
    rs.map_geometry = room_in_frame(setup.world.geometry(), robot.start);
    how.robots.push_back(std::move(rs));
    SlamRobotResult rr;
    rr.name = robot.name;
    result.robots.push_back(std::move(rr));
  }
  scenario.robot_count = n;
  auto exchanges = std::make_shared<PolynomialExchange>(sc, team, exchange, result);
  how.on_meeting = [exchanges](sim::Simulation& s, int a, int b) { (*exchanges)(s, a, b); };

  std::vector<localization::LocalizationMetrics> metrics(static_cast<std::size_t>(n));
  const auto record = [&](const sim::Simulation& s) {
    const std::vector<core::Pose2> truths = s.true_poses();
    for (int a = 0; a < n; ++a) {
      const core::Pose2& start = sc.robots[std::size_t(team[std::size_t(a)])].start;
      const auto& filter = filter_of(s, a);
      // mu's x~: the estimate compensated by the bias of x_j,0 = [0 0 0] (§4); P turned with it.
      const core::Pose2 estimate = start.compose(filter.pose());
      Eigen::Matrix3d j = Eigen::Matrix3d::Identity();
      j.topLeftCorner<2, 2>() = start.as_transform().rotation_matrix();
      const Eigen::Matrix3d p = j * filter.pose_covariance() * j.transpose();
      metrics[std::size_t(a)].add(truths[std::size_t(a)], estimate, p);
      result.robots[std::size_t(a)].truth.push_back(truths[std::size_t(a)]);
      result.robots[std::size_t(a)].estimate.push_back(estimate);
    }
  };
  sim::Simulation simulation(scenario, setup.world.truth(), std::move(how));
  simulation.run_to_end({}, record);

  for (int a = 0; a < n; ++a) {
    SlamRobotResult& rr = result.robots[std::size_t(a)];
    const auto& s = filter_of(simulation, a);
    const core::Transform2 frame = sc.robots[std::size_t(team[std::size_t(a)])].start.as_transform();
    const std::vector<mapping::Polynomial> polys = s.map().polynomials();
    rr.localization = metrics[std::size_t(a)].summary();
    double dr_sq = 0.0;
    const auto& planned = setup.planned[std::size_t(team[std::size_t(a)])];
    const core::Pose2& start = sc.robots[std::size_t(team[std::size_t(a)])].start;
    // From the same start estimate as the filter's: start * x_0 * start^-1 * planned_k.
    const core::Pose2 from = start.compose(start_estimates[std::size_t(a)]).compose(start.inverse());
    for (std::size_t k = 0; k < rr.truth.size(); ++k) {
      dr_sq += (rr.truth[k].position() - from.compose(planned[k]).position()).squaredNorm();
    }
    rr.dead_reckoning_rmse = std::sqrt(dr_sq / double(rr.truth.size()));
    rr.mapping = mapping::mapping_error(polys, frame, setup.walls, 0.01);
    rr.boundary_coverage = mapping::boundary_coverage(polys, frame, setup.walls, 0.1, 0.02);
    rr.tau_s = (simulation.track(a).localization_s + exchanges->seconds(a)) / double(sc.steps + 1);
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

}  // namespace

core::Registry<SlamMethod>& slam_method_registry() {
  static core::Registry<SlamMethod> registry("SLAM method");
  static const bool built_in = [] {
    registry.add("polynomial",
                 "D'Alfonso et al.'s polynomial EKF-SLAM, one filter per robot, polynomials exchanged at a rendezvous "
                 "(§3.2)",
                 [](const core::Params& params) -> SlamRun {
                   localization::polynomial_slam_options(params, 0.0);  // values that do not fit together
                   return [params](const SlamSetup& setup, int run, bool exchange, int only) {
                     const auto& sc = setup.scenario;
                     const auto options =
                         localization::polynomial_slam_options(params, sc.filter_range_noise_m.value_or(sc.range.noise_m));
                     return run_polynomial_slam(setup, options, run, exchange, only);
                   };
                 },
                 localization::polynomial_slam_params());
    return true;
  }();
  (void)built_in;
  return registry;
}

void register_slam_method(std::string name, std::string help, SlamMethod method, std::vector<core::ParamSpec> params) {
  slam_method_registry().add(std::move(name), std::move(help), std::move(method), std::move(params));
}

std::vector<std::string> slam_method_names() { return slam_method_registry().names(); }

core::Params slam_method_options(const std::string& name, const core::Settings& settings) {
  return slam_method_registry().configure(name, settings);
}

SlamRun make_slam_method(const std::string& name, const core::Settings& settings) {
  return slam_method_registry().get(name).make(slam_method_options(name, settings));
}

SlamRunResult run_slam(const SlamSetup& setup, int run, bool exchange, int only) {
  return setup.method(setup, run, exchange, only);
}

}  // namespace fleetmap::experiments
