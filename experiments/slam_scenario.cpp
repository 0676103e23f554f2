#include "experiments/slam_scenario.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "core/format.h"
#include "core/angle.h"
#include "core/error.h"
#include "experiments/slam_experiment.h"
#include "io/file_io.h"
#include "io/file_kind.h"
#include "io/yaml_reader.h"
#include "sim/scenario.h"
#include "sim/scenario_yaml.h"

namespace fleetmap::experiments {

namespace {

using core::deg2rad;
using core::rad2deg;

// A list of [x, y] points under `key`.
std::vector<Eigen::Vector2d> points_at(const YAML::Node& n, const io::YamlMap& m, const std::string& key) {
  if (!n.IsSequence()) throw InputError(m.where(key) + ": expected a list of [x, y] points, got " + io::describe_node(n));
  std::vector<Eigen::Vector2d> out;
  for (const auto& item : n) {
    double x = 0.0, y = 0.0;
    if (!item.IsSequence() || item.size() != 2 || !item[0].IsScalar() || !item[1].IsScalar() ||
        !YAML::convert<double>::decode(item[0], x) || !YAML::convert<double>::decode(item[1], y) || !std::isfinite(x) ||
        !std::isfinite(y)) {
      throw InputError(m.where_node(item) + ": key '" + m.full_key(key) + "': expected [x, y] in metres, got " +
                       io::describe_node(item));
    }
    out.emplace_back(x, y);
  }
  return out;
}

std::vector<Eigen::Vector2d> points(io::YamlMap& m, const std::string& key) {
  const auto n = m.node(key);
  if (!n) return {};
  return points_at(*n, m, key);
}

// The method's own block (`polynomial: {order: 2}`): each key a declared parameter, set in `params`
// and `settings`. Older files write a pair of parameters K_min and K_max as `K: [minimum, maximum]`
// (D'Alfonso et al.'s `rho: [0.08, 0.24]`).
void read_method_block(io::YamlMap& m, core::Params& params, core::Settings& settings) {
  const auto set = [&](const std::string& key, const std::string& value, const std::string& where) {
    io::set_declared(params, settings, key, value, where);
  };
  for (const auto& key : m.keys()) {
    const auto node = m.node(key);
    if (node->IsSequence() && params.declares(key + "_min") && params.declares(key + "_max")) {
      const auto v = m.numbers(key, 2);
      if (!(v[1] >= v[0])) {
        throw InputError(m.where(key) + ": expected [minimum, maximum] with minimum <= maximum, got [" + core::exact(v[0]) +
                         ", " + core::exact(v[1]) + "]");
      }
      set(key + "_min", core::exact(v[0]), m.where(key));
      set(key + "_max", core::exact(v[1]), m.where(key));
      continue;
    }
    if (!node->IsScalar()) throw InputError(m.where(key) + ": expected a value, got " + io::describe_node(*node));
    set(key, node->Scalar(), m.where(key));
  }
}

}  // namespace

std::vector<mapping::WallSegment> room_walls(const SlamRoom& room) {
  std::vector<mapping::WallSegment> out;
  const auto add = [&](const std::vector<Eigen::Vector2d>& polygon) {
    for (std::size_t i = 0; i < polygon.size(); ++i) out.push_back({polygon[i], polygon[(i + 1) % polygon.size()]});
  };
  add(room.boundary);
  for (const auto& o : room.obstacles) add(o);
  return out;
}

SlamScenario parse_slam_scenario(const std::string& text, const std::string& source) {
  const YAML::Node root = io::parse_yaml(text, source);
  if (!root || root.IsNull()) throw InputError(source + ": empty scenario file");
  io::check_yaml_file_kind(root, source, io::YamlFileKind::SlamScenario);
  io::YamlMap top(root, source);
  SlamScenario s;
  const auto method = top.member("method", {s.method, s.method_settings}, slam_method_names(),
                                  [](const std::string& name) { return slam_method_options(name); });
  s.method = method.name;
  s.method_settings = method.settings;
  s.seed = top.seed("seed", 1);
  s.runs = int(top.number("runs", s.runs, kSlamRunsRange));
  s.steps = int(top.integer("steps", s.steps, 1, 1'000'000));
  s.period_s = top.number("period", s.period_s, 1e-6, 3600.0);
  {
    auto room = top.map("room");
    if (!room.has("boundary")) throw InputError(top.where("room") + ": needs 'boundary', a polygon of [x, y] points");
    s.room.boundary = points(room, "boundary");
    if (s.room.boundary.size() < 3) throw InputError(room.where("boundary") + ": a polygon needs at least 3 points");
    if (const auto obstacles = room.node("obstacles")) {
      if (!obstacles->IsSequence()) {
        throw InputError(room.where("obstacles") + ": expected a list of polygons, got " + io::describe_node(*obstacles));
      }
      for (const auto& o : *obstacles) {
        s.room.obstacles.push_back(points_at(o, room, "obstacles"));
        if (s.room.obstacles.back().size() < 3) {
          throw InputError(room.where_node(o) + ": key 'room.obstacles': a polygon needs at least 3 points");
        }
      }
    }
    s.room.resolution_m = room.number("resolution", s.room.resolution_m, 1e-3, 1.0);
    room.finish();
  }
  {
    auto robots = top.map("robots");
    s.robot.radius_m = robots.number("radius", s.robot.radius_m, 1e-3, 100.0);
    s.robot.max_speed_mps = robots.number("max_speed", s.robot.max_speed_mps, 0.0, 100.0);
    s.robot.max_turn_rate_rps = deg2rad(robots.number("max_turn_rate_deg", rad2deg(s.robot.max_turn_rate_rps), 0.0, 36000.0));
    const auto team = robots.node("team");
    if (!team || !team->IsSequence() || team->size() == 0) {
      throw InputError(robots.where("team") + ": expected a list of robots ({name, start, path, speed})");
    }
    for (std::size_t i = 0; i < team->size(); ++i) {
      io::YamlMap r((*team)[i], source, "robots.team[" + std::to_string(i) + "]");
      SlamRobot robot;
      robot.name = r.text("name", std::string("r").append(std::to_string(i + 1)));
      // Names become file names (map_<name>.png) and table columns.
      const bool plain = !robot.name.empty() && robot.name.size() <= 32 &&
                         std::all_of(robot.name.begin(), robot.name.end(), [](char c) {
                           return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
                         });
      if (!plain) {
        throw InputError(r.where("name") + ": expected a name of up to 32 letters, digits, _ or -, got " +
                         io::describe_node(*r.node("name")));
      }
      for (const auto& other : s.robots) {
        if (other.name == robot.name) throw InputError(r.where("name") + ": two robots are named '" + robot.name + "'");
      }
      if (!r.has("start")) throw InputError(robots.where("team") + ": robot " + std::to_string(i + 1) + " needs 'start: [x, y, heading_deg]'");
      const auto start = r.numbers("start", 3);
      robot.start = core::Pose2(start[0], start[1], core::normalize_angle(deg2rad(start[2])));
      robot.path = points(r, "path");
      if (robot.path.empty()) throw InputError(r.where("path") + ": needs at least one waypoint");
      robot.speed_mps = r.number("speed", robot.speed_mps, 1e-6, 100.0);
      r.finish();
      s.robots.push_back(std::move(robot));
    }
    robots.finish();
  }
  s.noise = sim::read_motion_noise(top.map("noise"), s.noise);
  {
    auto sensors = top.map("sensors");
    auto range = sensors.map("range");
    s.range.angles_rad.clear();
    for (double a : range.numbers("angles_deg")) s.range.angles_rad.push_back(core::normalize_angle(deg2rad(a)));
    if (s.range.angles_rad.empty()) s.range.angles_rad = {deg2rad(-90.0), deg2rad(-45.0), 0.0, deg2rad(45.0), deg2rad(90.0)};
    s.range.max_range_m = range.number("max_range", s.range.max_range_m, 1e-3, 1e6);
    s.range.noise_m = range.number("noise", s.range.noise_m, 0.0, 100.0);
    range.finish();
    s.camera = sim::read_robot_detector(sensors.map("camera"), s.camera);
    sensors.finish();
  }
  {
    auto p0 = top.map("initial_sigma");
    s.initial_sigma_xy = p0.number("xy", s.initial_sigma_xy, 0.0, 1e3);
    s.initial_sigma_heading = p0.number("heading", s.initial_sigma_heading, 0.0, 10.0);
    s.sampled_start = p0.boolean("sampled", s.sampled_start);
    p0.finish();
  }
  {
    auto ex = top.map("exchange");
    s.exchange = ex.boolean("enabled", s.exchange);
    s.segment_tolerance_m = ex.number("segment_tolerance", s.segment_tolerance_m, 1e-6, 10.0);
    s.grid_patch_resolution_m = ex.number("grid_resolution", s.grid_patch_resolution_m, 1e-3, 10.0);
    ex.finish();
  }
  s.single_robot = top.text("single_robot", s.single_robot);
  s.paper_table = top.boolean("paper_table", s.paper_table);
  // A block named after a method holds its parameters; only the chosen method's is read.
  for (const auto& name : slam_method_names()) {
    if (!top.has(name)) continue;
    if (name != s.method) {
      throw InputError(top.where(name) + ": holds the parameters of method '" + name + "', but the method is '" + s.method + "'");
    }
    auto block = top.map(name);
    core::Params params = slam_method_options(s.method, s.method_settings);
    read_method_block(block, params, s.method_settings);
    block.finish();
  }
  top.finish();
  try {
    validate_slam_scenario(s);
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
  return s;
}

SlamScenario load_slam_scenario(const std::filesystem::path& path) {
  return parse_slam_scenario(io::read_file(path, 16 << 20), path.string());
}

void validate_slam_scenario(const SlamScenario& s) {
  if (const auto names = slam_method_names(); std::find(names.begin(), names.end(), s.method) == names.end()) {
    throw InputError("method: unknown value '" + s.method + "' (valid: " + core::join(names) + ")");
  }
  if (s.runs < 1) throw InputError("runs: need at least one run, got " + std::to_string(s.runs));
  if (s.steps < 1) throw InputError("steps: need at least one step, got " + std::to_string(s.steps));
  if (s.robots.empty()) throw InputError("robots.team: need at least one robot");
  if (s.room.boundary.size() < 3) throw InputError("room.boundary: a polygon needs at least 3 points");
  if (s.range.angles_rad.empty()) throw InputError("sensors.range.angles_deg: needs at least one sensor");
  for (std::size_t i = 0; i < s.robots.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (s.robots[i].name == s.robots[j].name) throw InputError("robots.team: two robots are named '" + s.robots[i].name + "'");
    }
  }
  if (!s.single_robot.empty() &&
      std::none_of(s.robots.begin(), s.robots.end(), [&](const SlamRobot& r) { return r.name == s.single_robot; })) {
    throw InputError("single_robot: no robot is named '" + s.single_robot + "'");
  }
  make_slam_method(s.method, s.method_settings);  // the method's parameters, alone and together
}

}  // namespace fleetmap::experiments
