#include "sim/simulation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include <fmt/format.h>

#include "core/angle.h"
#include "core/error.h"
#include "core/format.h"
#include "localization/localizers.h"
#include "mapping/range_scan.h"
#include "planning/planner.h"
#include "sim/motion.h"
#include "sim/sensors.h"

namespace fleetmap::sim {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string point_text(const Eigen::Vector2d& p) { return core::format_point(p); }

std::string extent_text(const core::GridGeometry& g) { return core::format_extent(g); }

World make_world(const Scenario& s, mapping::OccupancyGrid truth) {
  core::Random rng = core::Random(s.seed).fork(2);
  std::vector<Eigen::Vector2d> landmarks;
  for (std::size_t i = 0; i < s.landmarks.size(); ++i) {
    const auto cell = truth.geometry().world_to_cell(s.landmarks[i]);
    const std::string who = "landmarks.points[" + std::to_string(i) + "] " + point_text(s.landmarks[i]);
    if (!cell) throw InputError(who + " is outside the map (" + extent_text(truth.geometry()) + ")");
    if (truth.state(*cell) != mapping::CellState::Free) throw InputError(who + " is inside a wall, where no sensor could see it");
    landmarks.push_back(s.landmarks[i]);
  }
  for (const auto& p : landmarks_along_walls(truth, s.landmarks_along_walls, rng)) landmarks.push_back(p);
  return World(std::move(truth), std::move(landmarks));
}

}  // namespace

// The explorer plans for the robots and the sensor the scenario describes: their radius, the range,
// goals that see their unseen cell from well within range, and that count as reached close enough.
// A short range leaves narrow unseen bands along walls the robot passed at its radius: unknown space
// that narrow still counts as a frontier.
exploration::ExplorationOptions explorer_options(const Scenario& s) {
  exploration::ExplorationOptions o = s.exploration;
  const double range = s.range.max_range_m;
  o.traversability.robot_radius_m = s.robot.radius_m;
  o.sensor_range_m = range;
  o.targets.observe_range_m = std::min(o.targets.observe_range_m, 0.6 * range);
  o.reach_tolerance_m = std::min(o.reach_tolerance_m, 0.3 * range);
  o.targets.max_observe_range_m = std::max(o.targets.observe_range_m, range - 2.0 * o.planning_resolution_m);
  o.targets.frontiers.min_unknown_width_m = std::min(o.targets.frontiers.min_unknown_width_m, 0.3 * range);
  return o;
}

Simulation::Simulation(const Scenario& scenario, mapping::OccupancyGrid truth, SimulationSetup setup)
    : scenario_(scenario),
      setup_(std::move(setup)),
      world_(make_world(scenario, std::move(truth))),
      rng_(scenario.seed),
      merged_(world_.geometry()),
      exchange_(scenario.robot_count, world_.geometry()),
      explorer_(scenario.robot_count, explorer_options(scenario)) {
  validate_scenario(scenario_);
  // A run that writes a replay shows why each robot chose its target: the strategy reports its scores.
  explorer_.record_decisions(scenario_.html_replay);
  {
    // A sensor that does not reach past the cell the robot stands in can never show it a place to go.
    const double cell = std::max(world_.geometry().resolution(), scenario_.exploration.planning_resolution_m);
    if (scenario_.range.max_range_m <= cell) {
      throw InputError(fmt::format(
          "sensors.range.max_range: {} m does not reach beyond the robot's own cell ({} m): it cannot observe anything "
          "to explore", scenario_.range.max_range_m, cell));
    }
  }
  core::Random placement_rng = rng_.fork(1);
  scenario_.starts = place_robots(scenario_, world_, placement_rng);
  scenario_.robot_count = int(scenario_.starts.size());
  const int n = scenario_.robot_count;
  if (n > 64) throw InputError("robots: at most 64 robots");
  robots_.resize(std::size_t(n));
  setup_.robots.resize(std::size_t(n));
  for (int i = 0; i < n; ++i) {
    Robot& robot = robots_[std::size_t(i)];
    const RobotSetup& how = setup_.robots[std::size_t(i)];
    robot.truth = scenario_.starts[std::size_t(i)];
    robot.driver = how.driver;
    robot.odometry_error = how.odometry_error;
    robot.motion_rng = how.motion_rng ? how.motion_rng : std::make_shared<core::Random>(rng_.fork(100 + std::uint64_t(i)));
    robot.sensor_rng = how.sensor_rng ? how.sensor_rng : std::make_shared<core::Random>(rng_.fork(200 + std::uint64_t(i)));
    robot.detector_rng = how.detector_rng ? how.detector_rng : robot.sensor_rng;
  }
  explored_ = std::any_of(robots_.begin(), robots_.end(), [](const Robot& r) { return !r.driver; });

  // Map frames: one shared world frame, or one per robot, its origin at the robot's start.
  aligner_ = merging::make_map_aligner(scenario_.merging, scenario_.merging_settings, scenario_.merge_method_settings);
  if (aligner_->shared_frame()) {
    frame_origin_ = {core::Transform2::identity()};
    frame_geometry_ = {world_.geometry()};
  } else {
    const auto& g = world_.geometry();
    for (int i = 0; i < n; ++i) {
      const core::Pose2& start = robots_[std::size_t(i)].truth;
      robots_[std::size_t(i)].frame = i;
      frame_origin_.push_back(start.as_transform());
      if (const auto& own = setup_.robots[std::size_t(i)].map_geometry) {
        frame_geometry_.push_back(*own);
        continue;
      }
      // Large enough to hold the whole world around the start, however the frame is turned.
      double reach = 0.0;
      for (const auto& corner : {Eigen::Vector2d(0, 0), Eigen::Vector2d(g.width(), 0), Eigen::Vector2d(0, g.height()),
                                 Eigen::Vector2d(g.width(), g.height())}) {
        reach = std::max(reach, (g.grid_to_world(corner) - start.position()).norm());
      }
      const int cells = 2 * int(std::ceil((reach + 1.0) / g.resolution()));
      const double half = 0.5 * cells * g.resolution();
      frame_geometry_.emplace_back(g.resolution(), cells, cells, core::Pose2(-half, -half, 0.0));
    }
  }
  {
    std::vector<core::GridGeometry> geometries;
    for (const Robot& r : robots_) geometries.push_back(frame_geometry_[std::size_t(r.frame)]);
    exchange_ = MapExchange(geometries);
  }
  last_attempt_.assign(std::size_t(n), std::vector<int>(std::size_t(n), std::numeric_limits<int>::min() / 2));

  localization::LocalizerContext context;
  context.options = scenario_.localization_options;
  context.options.process_noise_xy = scenario_.noise.position_m;
  context.options.process_noise_theta = scenario_.noise.heading_rad;
  context.options.range_noise = scenario_.landmark_sensor.range_noise_m;
  context.options.bearing_noise = scenario_.landmark_sensor.bearing_noise_rad;
  context.options.scan_range_noise = scenario_.range.noise_m;
  context.options.known_associations = scenario_.landmark_sensor.report_ids && scenario_.localization_options.known_associations;
  // `mcl` localizes on the known map, which is only meaningful in the world frame.
  if (aligner_->shared_frame()) context.known_map = std::make_shared<const mapping::OccupancyGrid>(world_.truth());
  const core::Params localizer_params = localization::localizer_options(scenario_.localization, scenario_.localization_settings);
  for (int i = 0; i < n; ++i) {
    Robot& robot = robots_[std::size_t(i)];
    context.global_localization = std::find(scenario_.lost_robots.begin(), scenario_.lost_robots.end(), i + 1) !=
                                  scenario_.lost_robots.end();
    // Each robot knows its start and the landmark map in its own map frame.
    const core::Transform2 to_frame = frame_origin(i).inverse();
    context.initial_pose = core::Pose2::from_transform(to_frame * robot.truth.as_transform());
    context.known_landmarks.clear();
    for (std::size_t k = 0; k < world_.landmarks().size(); ++k) {
      context.known_landmarks.push_back({int(k), to_frame.apply(world_.landmarks()[k]), Eigen::Matrix2d::Zero()});
    }
    context.seed = rng_.fork(300 + std::uint64_t(i)).seed();
    const auto& make = setup_.robots[std::size_t(i)].localizer;
    context.params = localizer_params;  // the scenario's localizer's, for a robot's own maker too
    robot.localizer = make ? make(context) : localization::make_localizer(scenario_.localization, context);
    robot.map = mapping::OccupancyGrid(frame_geometry_[std::size_t(robot.frame)]);
  }
  if (aligner_->needs_landmark_estimates() && !robots_.front().localizer->estimates_landmarks()) {
    throw InputError(landmark_merging_problem(scenario_));
  }
  if (scenario_.path_planner != "wave") {
    planning::PlanPathOptions plan;
    plan.planner = scenario_.path_planner;
    plan.planner_settings = scenario_.planner_settings;
    // The same clearance the explorer keeps, so the paths it gets are ones it accepts.
    plan.space.robot_radius_m = scenario_.exploration.traversability.robot_radius_m +
                                scenario_.exploration.traversability.safety_margin_m;
    plan.search.time_budget_s = scenario_.planner_time_s;
    plan.search.iteration_budget = scenario_.planner_iterations;
    plan.search.seed = scenario_.seed;
    explorer_.set_path_provider([plan](const mapping::OccupancyGrid& map, const Eigen::Vector2d& from,
                                       const Eigen::Vector2d& to) {
      const planning::PlanResult r = planning::plan_path(map, from, to, plan);
      return r.success() ? r.path : std::vector<Eigen::Vector2d>{};
    });
  }
  if (setup_.measure_coverage) {
    std::vector<Eigen::Vector2d> start_points;
    for (const auto& p : scenario_.starts) start_points.push_back(p.position());
    observable_ = world_.observable_space(start_points, scenario_.robot.radius_m, scenario_.range.max_range_m);
  }
  sensed_by_.assign(std::size_t(world_.geometry().cell_count()), 0);
  previous_links_.assign(std::size_t(n), std::vector<char>(std::size_t(n), 0));

  const auto t0 = Clock::now();
  sense_and_map();
  communicate();
  decide();
  measure();
  timing_.total += seconds_since(t0);
}

Simulation::~Simulation() = default;

std::vector<core::Pose2> Simulation::true_poses() const {
  std::vector<core::Pose2> out;
  for (const Robot& r : robots_) out.push_back(r.truth);
  return out;
}

std::vector<core::Pose2> Simulation::estimated_poses() const {
  std::vector<core::Pose2> out;
  for (const Robot& r : robots_) out.push_back(r.localizer->pose());
  return out;
}

const Detection* Simulation::detection(int i, int other) const {
  for (const Detection& d : robots_[std::size_t(i)].detections) {
    if (d.other == other) return &d;
  }
  return nullptr;
}

bool Simulation::finished(int i) const {
  const Robot& r = robots_[std::size_t(i)];
  return r.driver ? !r.command.has_value() : explorer_.finished(i);
}

bool Simulation::all_finished() const {
  if (std::none_of(robots_.begin(), robots_.end(), [](const Robot& r) { return bool(r.driver); }))
    return explorer_.all_finished();
  for (int i = 0; i < scenario_.robot_count; ++i)
    if (!finished(i)) return false;
  return true;
}

bool Simulation::done() const { return step_ >= scenario_.steps || all_finished(); }

void Simulation::sense_and_map() {
  const int n = scenario_.robot_count;
  auto t0 = Clock::now();
  std::vector<localization::RangeScan> scans(static_cast<std::size_t>(n));
  std::vector<std::vector<localization::LandmarkObservation>> landmark_obs(static_cast<std::size_t>(n));
  const std::vector<core::Pose2> truths = true_poses();
  for (int i = 0; i < n; ++i) {
    Robot& robot = robots_[std::size_t(i)];
    auto& rng = *robot.sensor_rng;
    scans[std::size_t(i)] = read_ranges(world_, robot.truth, scenario_.range, rng);
    if (!world_.landmarks().empty()) {
      landmark_obs[std::size_t(i)] = read_landmarks(world_, robot.truth, scenario_.landmark_sensor, rng);
    }
    robot.detections = detect_robots(world_, i, truths, scenario_.detector, *robot.detector_rng);
  }
  timing_.sensing += seconds_since(t0);

  t0 = Clock::now();
  for (int i = 0; i < n; ++i) {
    Robot& robot = robots_[std::size_t(i)];
    const auto t_robot = Clock::now();
    auto& loc = *robot.localizer;
    loc.observe_truth(core::Pose2::from_transform(frame_origin(i).inverse() * robot.truth.as_transform()));
    if (!landmark_obs[std::size_t(i)].empty()) loc.update_landmarks(landmark_obs[std::size_t(i)]);
    loc.update_scan(scans[std::size_t(i)], robot.map);
    if (scenario_.localization_options.use_robot_detections) {
      for (const auto& d : robot.detections) {
        if (robots_[std::size_t(d.other)].frame != robot.frame) continue;  // its estimate means nothing here
        const auto& other = *robots_[std::size_t(d.other)].localizer;
        loc.update_robot({d.other, d.range, d.bearing, other.pose(), other.covariance()});
      }
    }
    robot.track.localization_s += seconds_since(t_robot);
  }
  // Collaborative localization (León et al., eq. (15)): the detected robot learns from its detector.
  if (scenario_.localization_options.use_robot_detections) {
    for (int i = 0; i < n; ++i) {
      for (const auto& d : robots_[std::size_t(i)].detections) {
        if (robots_[std::size_t(d.other)].frame != robots_[std::size_t(i)].frame) continue;
        const auto& detector = *robots_[std::size_t(i)].localizer;
        robots_[std::size_t(d.other)].localizer->update_detected_by({i, d.range, d.bearing, scenario_.detector.range_noise_m,
                                                               scenario_.detector.bearing_noise_rad, detector.pose(),
                                                               detector.covariance()});
      }
    }
  }
  timing_.localization += seconds_since(t0);

  t0 = Clock::now();
  for (int i = 0; i < n; ++i) {
    const core::Pose2 est = robots_[std::size_t(i)].localizer->pose();
    const auto& scan = scans[std::size_t(i)];
    const std::uint64_t bit = std::uint64_t{1} << i;
    auto& own = robots_[std::size_t(i)].map;
    const core::Pose2 world = in_world(i, est);
    mapping::for_each_beam(est, scan, [&](const Eigen::Vector2d& from, const Eigen::Vector2d& end, bool hit) {
      own.integrate_ray(from, end, hit, [&](int cell, bool changed) {
        if (changed) exchange_.touched(i, cell);
      });
      // The evaluation's merged map is in the world frame: the simulator knows where each frame lies.
      merged_.integrate_ray(world.position(), frame_origin(i).apply(end), hit,
                            [&](int cell, bool) { sensed_by_[std::size_t(cell)] |= bit; });
    });
  }
  timing_.mapping += seconds_since(t0);
}

void Simulation::communicate() {
  const auto t0 = Clock::now();
  const int n = scenario_.robot_count;
  std::vector<std::vector<Detection>> detections;
  for (const Robot& r : robots_) detections.push_back(r.detections);
  links_ = communication_links(world_, true_poses(), detections, scenario_.communication);
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      if (!links_[std::size_t(i)][std::size_t(j)]) continue;
      const bool new_link = !previous_links_[std::size_t(i)][std::size_t(j)];
      if (new_link) ++meetings_;
      if (setup_.on_meeting) {
        if (new_link) {
          events_.push_back({step_, "meeting", i, j, "the experiment's exchange"});
          setup_.on_meeting(*this, i, j);
        }
        continue;
      }
      Robot &a = robots_[std::size_t(i)], &b = robots_[std::size_t(j)];
      if (a.frame != b.frame) try_merge(i, j);
      if (a.frame != b.frame) {
        if (new_link) events_.push_back({step_, "meeting", i, j, "in different frames: no map exchanged"});
        continue;
      }
      const std::int64_t bytes = exchange_.exchange(i, a.map, j, b.map);
      bytes_sent_ += bytes;
      if (new_link) events_.push_back({step_, "meeting", i, j, std::to_string(bytes) + " bytes exchanged"});
    }
  }
  previous_links_ = links_;
  timing_.communication += seconds_since(t0);
}

void Simulation::decide() {
  const auto t0 = Clock::now();
  for (int i = 0; i < scenario_.robot_count; ++i) {
    Robot& r = robots_[std::size_t(i)];
    if (!r.driver) continue;
    r.command = r.driver->next({step_, r.truth, r.localizer->pose()});
    if (!r.command && !r.was_finished) events_.push_back({step_, "finished", i, -1, "the end of its drive"});
    r.was_finished = !r.command;
  }
  if (!explored_) {
    timing_.exploration += seconds_since(t0);
    return;
  }
  std::vector<exploration::ExplorerRobot> views;
  for (const Robot& r : robots_) {
    exploration::ExplorerRobot view{&r.map, r.localizer->pose(), {}};
    for (const auto& b : r.bumped) view.bumped_robots.push_back(b.second);
    views.push_back(std::move(view));
  }
  // Robots coordinate only when they can talk and share a map frame.
  auto links = links_;
  for (std::size_t i = 0; i < links.size(); ++i)
    for (std::size_t j = 0; j < links.size(); ++j) links[i][j] = links[i][j] && robots_[i].frame == robots_[j].frame;
  explorer_.update(views, links);
  for (int i = 0; i < scenario_.robot_count; ++i) {
    if (robots_[std::size_t(i)].driver) continue;
    const bool f = explorer_.finished(i);
    bool& was = robots_[std::size_t(i)].was_finished;
    if (f && !was) events_.push_back({step_, "finished", i, -1, "no reachable frontier left"});
    was = f;
  }
  timing_.exploration += seconds_since(t0);
}

void Simulation::measure() {
  const auto t0 = Clock::now();
  std::int64_t known = 0;
  const auto& cells = observable_.observable;
  if (setup_.measure_coverage) {
    for (int idx : cells) known += merged_.log_odds_at(idx) != 0.0f;
    coverage_.push_back(cells.empty() ? 1.0 : double(known) / double(cells.size()));
  }
  for (int i = 0; i < scenario_.robot_count; ++i) {
    const Robot& robot = robots_[std::size_t(i)];
    RobotTrack& t = robots_[std::size_t(i)].track;
    t.truth.push_back(robot.truth);
    t.estimate.push_back(in_world(i, robot.localizer->pose()));
    t.covariance.push_back(localization::rotate_pose_covariance(robot.localizer->covariance(), frame_origin(i).rotation()));
  }
  timing_.metrics += seconds_since(t0);
}

core::Pose2 Simulation::in_world(int i, const core::Pose2& frame_pose) const {
  return core::Pose2::from_transform(frame_origin(i) * frame_pose.as_transform());
}

void Simulation::step() {
  if (done()) return;
  const auto t_step = Clock::now();
  ++step_;
  const auto t0 = Clock::now();
  std::vector<core::Pose2> truths = true_poses();
  for (int i = 0; i < scenario_.robot_count; ++i) {
    Robot& robot = robots_[std::size_t(i)];
    auto& loc = *robot.localizer;
    // Two blocked moves in a row: back away from the obstacle before following the path again.
    int& streak = robot.blocked_streak;
    Command cmd;
    if (robot.driver) {
      cmd = robot.command.value_or(Command{});
    } else {
      std::vector<Eigen::Vector2d> bumped;
      for (const auto& b : robot.bumped) bumped.push_back(b.second);
      cmd = streak >= 2 ? clear_on_map(escape_command(loc.pose(), robot.map, scenario_.period_s, bumped, scenario_.robot.radius_m),
                                       loc.pose(), robot.map,
                                       scenario_.robot, scenario_.period_s)
                        : follow_path(loc.pose(), explorer_.path(i), robot.map, scenario_.robot, scenario_.period_s,
                                      scenario_.lookahead_m);
    }
    MoveResult mv = move_robot(world_, i, truths, scenario_.robot, cmd, scenario_.period_s,
                               robot.odometry_error ? MotionNoise{0.0, 0.0} : scenario_.noise, *robot.motion_rng);
    if (robot.odometry_error) {
      mv.pose.theta = core::normalize_angle(mv.pose.theta);
      mv.odometry = misreport_odometry(mv.odometry, *robot.odometry_error, *robot.motion_rng);
    }
    robot.truth = truths[std::size_t(i)] = mv.pose;
    auto& t = robot.track;
    t.odometry.push_back(mv.odometry);
    t.distance_m += mv.distance_m;
    streak = mv.blocked ? streak + 1 : (streak >= 2 ? 0 : streak);
    if (streak > 3) streak = 0;  // the escape did not help either: follow the path again
    if (mv.blocked) {
      ++t.blocked_moves;
      events_.push_back({step_, "blocked", i, -1,
                         mv.contact ? "move stopped by a wall at " + core::format_point(*mv.contact) : "move stopped by a robot"});
    }
    const auto t_predict = Clock::now();
    loc.predict(mv.odometry);
    t.localization_s += seconds_since(t_predict);
    if (mv.contact) mark_contact(robot, *mv.contact);
    if (mv.robot) {
      // Where the bumper puts the other robot: its offset from this one, seen from the estimate.
      const core::Pose2 est = loc.pose();
      const Eigen::Vector2d offset = truths[std::size_t(*mv.robot)].position() - mv.pose.position();
      const double turn = est.theta - mv.pose.theta, c = std::cos(turn), sn = std::sin(turn);
      robot.bumped.emplace_back(step_, est.position() + Eigen::Vector2d(c * offset.x() - sn * offset.y(), sn * offset.x() + c * offset.y()));
    }
    const int keep = scenario_.exploration.detour_after_steps;
    std::erase_if(robot.bumped, [&](const auto& b) { return b.first <= step_ - keep; });
  }
  timing_.motion += seconds_since(t0);
  sense_and_map();
  communicate();
  decide();
  measure();
  timing_.total += seconds_since(t_step);
}

// A bumper: what stopped the robot is a wall on its own map, where its estimate puts the contact,
// so that its paths go around it from now on. The scan may never see it (a speck between two beams,
// something below the laser's plane).
void Simulation::mark_contact(Robot& robot, const Eigen::Vector2d& contact) {
  const Eigen::Vector2d offset = contact - robot.truth.position();
  if (offset.norm() < 1e-9) return;
  // A little past the contact, inside the square that was touched.
  const Eigen::Vector2d inside = offset + 0.25 * world_.geometry().resolution() * offset.normalized();
  const double c = std::cos(robot.truth.theta), s = std::sin(robot.truth.theta);
  const Eigen::Vector2d relative(c * inside.x() + s * inside.y(), -s * inside.x() + c * inside.y());  // the robot's frame
  const Eigen::Vector2d at = robot.localizer->pose().transform(relative);
  if (const auto cell = robot.map.geometry().world_to_cell(at)) {
    if (robot.map.state(*cell) != mapping::CellState::Occupied) ++robot.track.contacts_marked;
    robot.map.set_state(*cell, mapping::CellState::Occupied);
  }
}

void Simulation::run_to_end(const ProgressCallback& progress, const std::function<void(const Simulation&)>& on_step) {
  if (on_step) on_step(*this);
  while (!done()) {
    step();
    if (progress) progress(step_, scenario_.steps, coverage());
    if (on_step) on_step(*this);
  }
}

RunResult Simulation::run(const ProgressCallback& progress, const std::function<void(const Simulation&)>& on_step) {
  run_to_end(progress, on_step);
  return result();
}

}  // namespace fleetmap::sim
