#include "sim/scenario.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "core/angle.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/yaml_reader.h"
#include "exploration/strategy.h"
#include "merging/merge.h"
#include "planning/planner.h"

namespace fleetmap::sim {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
using core::deg2rad;
using core::rad2deg;

std::vector<std::vector<double>> number_rows(core::YamlMap& m, const std::string& key, std::size_t lo, std::size_t hi,
                                             const std::string& shape) {
  std::vector<std::vector<double>> rows;
  const auto n = m.node(key);
  if (!n) return rows;
  if (!n->IsSequence()) throw InputError(m.where(key) + ": expected a list of " + shape + ", got " + core::describe_node(*n));
  for (const auto& item : *n) {
    std::vector<double> row;
    if (item.IsSequence() && item.size() >= lo && item.size() <= hi) {
      for (const auto& v : item) {
        double d = 0.0;
        if (!v.IsScalar() || !YAML::convert<double>::decode(v, d) || !std::isfinite(d)) {
          row.clear();
          break;
        }
        row.push_back(d);
      }
    }
    if (row.size() < lo) {
      throw InputError(m.where_node(item) + ": key '" + m.full_key(key) + "': expected " + shape + ", got " +
                       core::describe_node(item));
    }
    rows.push_back(row);
  }
  return rows;
}

std::string fmt(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.15g", v);
  return buf;
}


}  // namespace

std::vector<std::string> merging_names() { return {"known", "rendezvous", "overlap"}; }

std::vector<std::string> path_planner_names() {
  std::vector<std::string> names = {"wave"};
  for (const auto& n : planning::planner_names()) names.push_back(n);
  return names;
}

MotionNoise read_motion_noise(core::YamlMap noise, const MotionNoise& fallback) {
  MotionNoise n;
  n.position_m = noise.number("position", fallback.position_m, 0.0, 100.0);
  n.heading_rad = deg2rad(noise.number("heading_deg", rad2deg(fallback.heading_rad), 0.0, 360.0));
  noise.finish();
  return n;
}

RobotDetectorOptions read_robot_detector(core::YamlMap det, const RobotDetectorOptions& fallback) {
  RobotDetectorOptions d = fallback;
  d.max_range_m = det.number("max_range", fallback.max_range_m, 0.0, 1e6);
  d.fov_rad = deg2rad(det.number("fov_deg", rad2deg(fallback.fov_rad), 0.0, 360.0));
  d.range_noise_m = det.number("range_noise", fallback.range_noise_m, 0.0, 100.0);
  d.bearing_noise_rad = deg2rad(det.number("bearing_noise_deg", rad2deg(fallback.bearing_noise_rad), 0.0, 360.0));
  det.finish();
  return d;
}

Scenario parse_scenario(const std::string& text, const std::string& source, const std::filesystem::path& base_dir) {
  const YAML::Node root = core::parse_yaml(text, source);
  if (!root || root.IsNull()) throw InputError(source + ": empty scenario file");
  core::YamlMap top(root, source);
  Scenario s;
  s.base_dir = base_dir;
  s.map = top.text("map", s.map);
  if (s.map.empty()) throw InputError(top.where("map") + ": expected a map name or file");
  s.seed = std::uint64_t(top.integer("seed", 1, 0));
  s.steps = int(top.integer("steps", s.steps, 1, 10'000'000));
  s.period_s = top.number("period", s.period_s, 1e-6, 3600.0);

  // robots: a count (packed cluster), `random: N`, or `starts: [[x, y, heading_deg], ...]`.
  if (const auto r = top.node("robots"); r && r->IsScalar()) {
    s.robot_count = int(top.integer("robots", 4, 1, 64));
  } else {
    auto robots = top.map("robots");
    const bool has_count = robots.has("count"), has_random = robots.has("random"), has_starts = robots.has("starts");
    if (int(has_count) + int(has_random) + int(has_starts) > 1) {
      throw InputError(robots.where(has_starts ? "starts" : "random") +
                       ": give only one of 'count' (a cluster), 'random: N' or 'starts'");
    }
    s.robot_count = int(robots.integer("count", s.robot_count, 1, 64));
    if (has_random) {
      s.placement = Placement::Random;
      s.robot_count = int(robots.integer("random", 4, 1, 64));
    }
    for (const auto& row : number_rows(robots, "starts", 2, 3, "[x, y] or [x, y, heading_deg]")) {
      s.starts.emplace_back(row[0], row[1], row.size() > 2 ? deg2rad(row[2]) : 0.0);
    }
    if (has_starts) {
      if (s.starts.empty()) throw InputError(robots.where("starts") + ": needs at least one start pose");
      if (s.starts.size() > 64) throw InputError(robots.where("starts") + ": at most 64 robots");
      s.placement = Placement::List;
      s.robot_count = int(s.starts.size());
    }
    if (const auto at = robots.numbers("cluster_at", 2); !at.empty()) s.cluster_at = Eigen::Vector2d(at[0], at[1]);
    s.min_separation_m = robots.number("min_separation", s.min_separation_m, 0.0, 1e6);
    s.robot.radius_m = robots.number("radius", s.robot.radius_m, 1e-3, 100.0);
    s.robot.max_speed_mps = robots.number("max_speed", s.robot.max_speed_mps, 0.0, 100.0);
    s.robot.max_turn_rate_rps = deg2rad(robots.number("max_turn_rate_deg", rad2deg(s.robot.max_turn_rate_rps), 0.0, 36000.0));
    robots.finish();
  }

  s.noise = read_motion_noise(top.map("noise"), s.noise);
  {
    auto sensors = top.map("sensors");
    auto range = sensors.map("range");
    s.range.beams = int(range.integer("beams", s.range.beams, 1, 100000));
    for (double a : range.numbers("angles_deg")) s.range.angles_rad.push_back(deg2rad(a));
    if (range.has("angles_deg") && s.range.angles_rad.empty()) throw InputError(range.where("angles_deg") + ": needs at least one angle");
    s.range.max_range_m = range.number("max_range", s.range.max_range_m, 1e-3, 1e6);
    s.range.noise_m = range.number("noise", s.range.noise_m, 0.0, 100.0);
    range.finish();
    auto lm = sensors.map("landmarks");
    s.landmark_sensor.max_range_m = lm.number("max_range", s.landmark_sensor.max_range_m, 0.0, 1e6);
    s.landmark_sensor.range_noise_m = lm.number("range_noise", s.landmark_sensor.range_noise_m, 0.0, 100.0);
    s.landmark_sensor.bearing_noise_rad =
        deg2rad(lm.number("bearing_noise_deg", rad2deg(s.landmark_sensor.bearing_noise_rad), 0.0, 360.0));
    s.landmark_sensor.report_ids = lm.boolean("report_ids", s.landmark_sensor.report_ids);
    lm.finish();
    s.detector = read_robot_detector(sensors.map("robots"), s.detector);
    sensors.finish();
  }
  {
    auto lm = top.map("landmarks");
    for (const auto& row : number_rows(lm, "points", 2, 2, "[x, y]")) s.landmarks.emplace_back(row[0], row[1]);
    s.landmarks_along_walls = lm.number("along_walls", 0.0, 0.0, 100.0);
    lm.finish();
  }
  if (const auto l = top.node("localization"); l && l->IsScalar()) {
    s.localization = top.text("localization", s.localization);
  } else {
    auto loc = top.map("localization");
    s.localization = loc.text("method", s.localization);
    auto& o = s.localization_options;
    o.known_associations = loc.boolean("known_associations", o.known_associations);
    o.association_gate = loc.number("association_gate", o.association_gate, 0.0, 1e6);
    o.use_robot_detections = loc.boolean("robot_detections", o.use_robot_detections);
    o.initial_xy = loc.number("initial_sigma_xy", o.initial_xy, 0.0, 1e3);
    o.initial_theta = deg2rad(loc.number("initial_sigma_heading_deg", rad2deg(o.initial_theta), 0.0, 360.0));
    o.mcl_particles = int(loc.integer("mcl_particles", o.mcl_particles, 1, 1000000));
    o.rbpf_particles = int(loc.integer("rbpf_particles", o.rbpf_particles, 1, 10000));
    for (double r : loc.numbers("lost_robots")) {
      if (r != std::floor(r) || r < 1) {
        throw InputError(loc.where("lost_robots") + ": expected robot numbers from 1, got " + fmt(r));
      }
      s.lost_robots.push_back(int(r));
    }
    loc.finish();
  }
  {
    auto comm = top.map("communication");
    s.communication.range_m = comm.number("range", s.communication.range_m, 0.0, kInf, true);
    s.communication.line_of_sight = comm.boolean("line_of_sight", s.communication.line_of_sight);
    comm.finish();
  }
  {
    auto ex = top.map("exploration");
    auto& e = s.exploration;
    e.strategy = ex.choice("strategy", e.strategy, exploration::strategy_names());
    e.strategy_options.beta = ex.number("beta", e.strategy_options.beta, 0.0, 1e6);
    e.strategy_options.directional_weight = ex.number("directional_weight", e.strategy_options.directional_weight, 0.0, 1e6);
    e.wave.eight_connected = ex.boolean("eight_connected", e.wave.eight_connected);
    e.wave.occupancy_weight = ex.number("occupancy_weight", e.wave.occupancy_weight, 0.0, 1e6);
    e.stall_steps = int(ex.integer("stall_steps", e.stall_steps, 1, 1'000'000));
    e.targets.piece_radius_m = ex.number("piece_radius", e.targets.piece_radius_m, 1e-3, 1e6);
    e.targets.frontiers.min_region_cells = int(ex.integer("min_frontier_cells", e.targets.frontiers.min_region_cells, 1, 1'000'000));
    e.traversability.safety_margin_m = ex.number("safety_margin", e.traversability.safety_margin_m, 0.0, 100.0);
    e.planning_resolution_m = ex.number("planning_resolution", e.planning_resolution_m, 0.0, 100.0);
    s.path_planner = ex.choice("path_planner", s.path_planner, path_planner_names());
    s.planner_time_s = ex.number("planner_time", s.planner_time_s, 1e-3, 3600.0);
    ex.finish();
  }
  if (const auto m = top.node("merging"); m && m->IsScalar()) {
    s.merging = top.choice("merging", s.merging, merging_names());
  } else {
    auto merge = top.map("merging");
    s.merging = merge.choice("mode", s.merging, merging_names());
    s.merge_method = merge.choice("method", s.merge_method, merging::merge_method_names());
    s.merge_min_confidence = merge.number("min_confidence", s.merge_min_confidence, 0.0, 1.0);
    s.merge_attempt_every = int(merge.integer("attempt_every", s.merge_attempt_every, 1, 1'000'000));
    merge.finish();
  }
  s.lookahead_m = top.number("lookahead", s.lookahead_m, 0.0, 1e6);
  top.finish();
  validate_scenario(s);
  return s;
}

Scenario load_scenario(const std::filesystem::path& path) {
  return parse_scenario(core::read_file(path, 16 << 20), path.string(), path.parent_path());
}

void validate_scenario(const Scenario& s) {
  if (s.robot_count < 1) throw InputError("robots: need at least one robot, got " + std::to_string(s.robot_count));
  if (s.robot_count > 64) throw InputError("robots: at most 64 robots, got " + std::to_string(s.robot_count));
  if (s.steps < 1) throw InputError("steps: need at least one step, got " + std::to_string(s.steps));
  const auto non_negative = [](double v, const char* key) {
    if (!(v >= 0.0)) throw InputError(std::string(key) + ": must not be negative, got " + fmt(v));
  };
  non_negative(s.noise.position_m, "noise.position");
  non_negative(s.noise.heading_rad, "noise.heading_deg");
  non_negative(s.range.noise_m, "sensors.range.noise");
  non_negative(s.communication.range_m, "communication.range");
  non_negative(s.detector.max_range_m, "sensors.robots.max_range");
  non_negative(s.landmark_sensor.max_range_m, "sensors.landmarks.max_range");
  non_negative(s.landmark_sensor.range_noise_m, "sensors.landmarks.range_noise");
  non_negative(s.detector.range_noise_m, "sensors.robots.range_noise");
  if (!(s.range.max_range_m > 0.0)) throw InputError("sensors.range.max_range: must be positive, got " + fmt(s.range.max_range_m));
  if (!(s.robot.radius_m > 0.0)) throw InputError("robots.radius: must be positive, got " + fmt(s.robot.radius_m));
  if (!(s.period_s > 0.0)) throw InputError("period: must be positive, got " + fmt(s.period_s));
  const auto check_name = [](const std::string& key, const std::string& value, const std::vector<std::string>& valid) {
    if (std::find(valid.begin(), valid.end(), value) != valid.end()) return;
    std::string names;
    for (const auto& v : valid) names += (names.empty() ? "" : ", ") + v;
    throw InputError(key + ": unknown value '" + value + "' (valid: " + names + ")");
  };
  check_name("exploration.strategy", s.exploration.strategy, exploration::strategy_names());
  check_name("localization", s.localization, localization::localizer_names());
  for (int r : s.lost_robots) {
    if (s.localization != "mcl") throw InputError("localization.lost_robots: only 'mcl' can start without its pose, not '" + s.localization + "'");
    const int count = s.placement == Placement::List ? int(s.starts.size()) : s.robot_count;
    if (r < 1 || r > count) throw InputError("localization.lost_robots: robot " + std::to_string(r) + " does not exist (robots 1.." + std::to_string(count) + ")");
  }
  check_name("merging", s.merging, merging_names());
  check_name("merging.method", s.merge_method, merging::merge_method_names());
  check_name("exploration.path_planner", s.path_planner, path_planner_names());
  if (!(s.planner_time_s > 0.0)) throw InputError("exploration.planner_time: must be positive, got " + fmt(s.planner_time_s));
}

std::string scenario_to_yaml(const Scenario& s) {
  std::ostringstream y;
  y << "# fleetmap scenario\n";
  y << "map: " << core::yaml_quoted(s.map) << "\n";
  y << "seed: " << s.seed << "\nsteps: " << s.steps << "\nperiod: " << fmt(s.period_s) << "\n";
  y << "robots:\n";
  switch (s.placement) {
    case Placement::Cluster: y << "  count: " << s.robot_count << "\n"; break;
    case Placement::Random: y << "  random: " << s.robot_count << "\n"; break;
    case Placement::List:
      y << "  starts:\n";
      for (const auto& p : s.starts) y << "    - [" << fmt(p.x) << ", " << fmt(p.y) << ", " << fmt(rad2deg(p.theta)) << "]\n";
      break;
  }
  if (s.cluster_at) y << "  cluster_at: [" << fmt(s.cluster_at->x()) << ", " << fmt(s.cluster_at->y()) << "]\n";
  y << "  min_separation: " << fmt(s.min_separation_m) << "\n  radius: " << fmt(s.robot.radius_m)
    << "\n  max_speed: " << fmt(s.robot.max_speed_mps) << "\n  max_turn_rate_deg: " << fmt(rad2deg(s.robot.max_turn_rate_rps)) << "\n";
  y << "noise:\n  position: " << fmt(s.noise.position_m) << "\n  heading_deg: " << fmt(rad2deg(s.noise.heading_rad)) << "\n";
  y << "sensors:\n  range:\n";
  if (!s.range.angles_rad.empty()) {
    y << "    angles_deg: [";
    for (std::size_t i = 0; i < s.range.angles_rad.size(); ++i) y << (i ? ", " : "") << fmt(rad2deg(s.range.angles_rad[i]));
    y << "]\n";
  }
  y << "    beams: " << s.range.beams << "\n    max_range: " << fmt(s.range.max_range_m) << "\n    noise: " << fmt(s.range.noise_m) << "\n";
  y << "  landmarks:\n    max_range: " << fmt(s.landmark_sensor.max_range_m) << "\n    range_noise: " << fmt(s.landmark_sensor.range_noise_m)
    << "\n    bearing_noise_deg: " << fmt(rad2deg(s.landmark_sensor.bearing_noise_rad))
    << "\n    report_ids: " << (s.landmark_sensor.report_ids ? "true" : "false") << "\n";
  y << "  robots:\n    max_range: " << fmt(s.detector.max_range_m) << "\n    fov_deg: " << fmt(rad2deg(s.detector.fov_rad))
    << "\n    range_noise: " << fmt(s.detector.range_noise_m) << "\n    bearing_noise_deg: " << fmt(rad2deg(s.detector.bearing_noise_rad)) << "\n";
  y << "landmarks:\n";
  if (!s.landmarks.empty()) {
    y << "  points:\n";
    for (const auto& p : s.landmarks) y << "    - [" << fmt(p.x()) << ", " << fmt(p.y()) << "]\n";
  }
  y << "  along_walls: " << fmt(s.landmarks_along_walls) << "\n";
  const auto& o = s.localization_options;
  y << "localization:\n  method: " << s.localization << "\n  known_associations: " << (o.known_associations ? "true" : "false")
    << "\n  association_gate: " << fmt(o.association_gate) << "\n  robot_detections: " << (o.use_robot_detections ? "true" : "false")
    << "\n  initial_sigma_xy: " << fmt(o.initial_xy) << "\n  initial_sigma_heading_deg: " << fmt(rad2deg(o.initial_theta)) << "\n";
  y << "  mcl_particles: " << o.mcl_particles << "\n  rbpf_particles: " << o.rbpf_particles << "\n";
  if (!s.lost_robots.empty()) {
    y << "  lost_robots: [";
    for (std::size_t i = 0; i < s.lost_robots.size(); ++i) y << (i ? ", " : "") << s.lost_robots[i];
    y << "]\n";
  }
  y << "communication:\n  range: " << fmt(s.communication.range_m) << "\n  line_of_sight: " << (s.communication.line_of_sight ? "true" : "false") << "\n";
  const auto& e = s.exploration;
  y << "exploration:\n  strategy: " << e.strategy << "\n  beta: " << fmt(e.strategy_options.beta)
    << "\n  directional_weight: " << fmt(e.strategy_options.directional_weight)
    << "\n  eight_connected: " << (e.wave.eight_connected ? "true" : "false") << "\n  occupancy_weight: " << fmt(e.wave.occupancy_weight)
    << "\n  stall_steps: " << e.stall_steps << "\n  piece_radius: " << fmt(e.targets.piece_radius_m)
    << "\n  min_frontier_cells: " << e.targets.frontiers.min_region_cells << "\n  safety_margin: " << fmt(e.traversability.safety_margin_m)
    << "\n  planning_resolution: " << fmt(e.planning_resolution_m) << "\n  path_planner: " << s.path_planner << "\n  planner_time: " << fmt(s.planner_time_s) << "\n";
  y << "merging:\n  mode: " << s.merging << "\n  method: " << s.merge_method << "\n  min_confidence: "
    << fmt(s.merge_min_confidence) << "\n  attempt_every: " << s.merge_attempt_every << "\n";
  y << "lookahead: " << fmt(s.lookahead_m) << "\n";
  return y.str();
}

}  // namespace fleetmap::sim
