#include "experiments/landmark_scenario.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/angle.h"
#include "core/error.h"
#include "experiments/slam_experiment.h"
#include "io/yaml_reader.h"
#include "localization/localizer.h"
#include "sim/scenario.h"
#include "sim/scenario_yaml.h"

namespace fleetmap::experiments {

namespace {

using core::deg2rad;
using core::rad2deg;
namespace limits = sim::limits;

constexpr const char* kExperiment = "landmark_alignment";

std::vector<Eigen::Vector2d> point_list(io::YamlMap& m, const std::string& key) {
  std::vector<Eigen::Vector2d> out;
  const auto n = m.node(key);
  if (!n) return out;
  if (!n->IsSequence()) throw InputError(m.where(key) + ": expected a list of [x, y] points, got " + io::describe_node(*n));
  for (const auto& item : *n) {
    double x = 0.0, y = 0.0;
    if (!item.IsSequence() || item.size() != 2 || !YAML::convert<double>::decode(item[0], x) ||
        !YAML::convert<double>::decode(item[1], y) || !std::isfinite(x) || !std::isfinite(y)) {
      throw InputError(m.where_node(item) + ": key '" + m.full_key(key) + "': expected [x, y] in metres, got " +
                       io::describe_node(item));
    }
    out.emplace_back(x, y);
  }
  return out;
}

std::vector<LandmarkField> read_fields(io::YamlMap& lm, const std::string& source) {
  std::vector<LandmarkField> out;
  const auto fields = lm.node("fields");
  if (!fields || !fields->IsSequence() || fields->size() == 0) {
    throw InputError(lm.where("fields") + ": expected a list of {area: [x0, y0, x1, y1], count: N}");
  }
  for (std::size_t i = 0; i < fields->size(); ++i) {
    io::YamlMap f((*fields)[i], source, lm.full_key("fields") + "[" + std::to_string(i) + "]");
    const auto area = f.numbers("area", 4);
    out.push_back({{std::min(area[0], area[2]), std::min(area[1], area[3])},
                   {std::max(area[0], area[2]), std::max(area[1], area[3])},
                   int(f.integer("count", 0, 0, 100000))});
    f.finish();
  }
  return out;
}

LandmarkCase read_case(const YAML::Node& node, const std::string& source, const std::string& prefix) {
  io::YamlMap m(node, source, prefix);
  LandmarkCase c;
  c.name = m.text("name", "");
  if (c.name.empty()) throw InputError(m.where("name") + ": every case needs a name");
  c.steps = int(m.integer("steps", c.steps, 1, 1'000'000));
  for (double s : m.numbers("rendezvous")) {
    if (s != std::floor(s) || s < 1 || s > c.steps) {
      throw InputError(m.where("rendezvous") + ": expected steps from 1 to " + std::to_string(c.steps) + ", got " +
                       fmt::format("{:g}", s));
    }
    c.rendezvous.push_back(int(s));
  }
  std::sort(c.rendezvous.begin(), c.rendezvous.end());
  if (c.rendezvous.empty()) c.rendezvous.push_back(c.steps);
  if (m.has("landmarks")) {
    auto lm = m.map("landmarks");
    c.fields = read_fields(lm, source);
    lm.finish();
  }
  const auto robots = m.node("robots");
  if (!robots || !robots->IsSequence() || robots->size() < 2) {
    throw InputError(m.where("robots") + ": expected a list of at least two robots ({name, start, path}), the leader first");
  }
  for (std::size_t i = 0; i < robots->size(); ++i) {
    io::YamlMap r((*robots)[i], source, m.full_key("robots") + "[" + std::to_string(i) + "]");
    LandmarkRobot robot;
    robot.name = r.text("name", "robot" + std::to_string(i + 1));
    if (!r.has("start")) throw InputError(r.where("start") + ": needs 'start: [x, y, heading_deg]'");
    const auto start = r.numbers("start", 3);
    robot.start = core::Pose2(start[0], start[1], core::normalize_angle(deg2rad(start[2])));
    robot.path = point_list(r, "path");
    if (robot.path.empty()) throw InputError(r.where("path") + ": needs at least one waypoint");
    r.finish();
    c.robots.push_back(std::move(robot));
  }
  m.finish();
  return c;
}

}  // namespace

bool is_landmark_scenario(const std::string& text, const std::string& source) {
  const YAML::Node root = io::parse_yaml(text, source);
  return root.IsMap() && root["experiment"] && root["experiment"].IsScalar() &&
         root["experiment"].as<std::string>() == kExperiment;
}

LandmarkExperimentOptions parse_landmark_options(const std::string& text, const std::string& source) {
  io::YamlMap top(io::parse_yaml(text, source), source);
  LandmarkExperimentOptions o;
  if (const std::string e = top.text("experiment", ""); e != kExperiment) {
    throw InputError(top.where("experiment") + ": expected '" + kExperiment + "', got '" + e + "'");
  }
  o.seed = top.seed("seed", o.seed);
  o.runs = int(top.integer("runs", o.runs, 1, 100000));
  o.period_s = top.number("period", o.period_s, 1e-3, 60.0);
  o.speed_mps = top.number("speed", o.speed_mps, 1e-3, 100.0);
  // The particles of every robot's fastslam2, checked against that localizer's declaration.
  if (const auto n = top.node("particles")) {
    core::Params fastslam2 = localization::localizer_options("fastslam2");
    try {
      fastslam2.set("particles", n->IsScalar() ? n->Scalar() : io::describe_node(*n));
    } catch (const InputError& e) {
      throw InputError(top.where("particles") + ": " + e.what());
    }
    o.particles = int(fastslam2.number("particles"));
  }
  o.noise = sim::read_motion_noise(top.map("noise"), o.noise);
  {
    auto sensors = top.map("sensors");
    auto lm = sensors.map("landmarks");
    o.sensor.max_range_m = lm.number("max_range", o.sensor.max_range_m, limits::kDetectorRange);
    o.sensor.range_noise_m = lm.number("range_noise", o.sensor.range_noise_m, limits::kNoiseMetres);
    o.sensor.bearing_noise_rad = deg2rad(lm.number("bearing_noise_deg", rad2deg(o.sensor.bearing_noise_rad), limits::kAngleDeg));
    o.signature_range = lm.number("signature_range", o.signature_range, 1e-6, 1e6);
    o.signature_noise = lm.number("signature_noise", o.signature_noise, 0.0, 1e6);
    lm.finish();
    o.camera = sim::read_robot_detector(sensors.map("camera"), o.camera);
    sensors.finish();
  }
  {
    auto a = top.map("alignment");
    auto& l = o.alignment;
    l.signature_threshold = a.number("signature_threshold", l.signature_threshold, 1e-9, 1e6);
    l.geometric_threshold = a.number("geometric_threshold", l.geometric_threshold, 1e-9, 1e6);
    l.support_threshold = a.number("support_threshold", l.support_threshold, 1e-9, 1e6);
    l.min_supports = int(a.integer("min_supports", l.min_supports, 2, 100000));
    l.overlap_threshold = int(a.integer("overlap_threshold", l.overlap_threshold, 0, 100000));
    l.duplicate_distance = a.number("duplicate_distance", l.duplicate_distance, 0.0, 1e6);
    l.refit_supports = a.boolean("refit_supports", l.refit_supports);
    a.finish();
  }
  {
    if (top.has("landmarks")) {
      auto lm = top.map("landmarks");
      o.fields = read_fields(lm, source);
      lm.finish();
    }
  }
  {
    const auto cases = top.node("cases");
    if (!cases || !cases->IsSequence() || cases->size() == 0) throw InputError(top.where("cases") + ": expected a list of cases");
    for (std::size_t i = 0; i < cases->size(); ++i) {
      o.cases.push_back(read_case((*cases)[i], source, "cases[" + std::to_string(i) + "]"));
      for (std::size_t j = 0; j < i; ++j) {
        if (o.cases[j].name == o.cases[i].name) throw InputError(top.where("cases") + ": two cases are named '" + o.cases[i].name + "'");
      }
      if (o.cases[i].fields.empty() && o.fields.empty()) {
        throw InputError(top.where("cases") + ": case '" + o.cases[i].name +
                         "' has no landmarks: give it 'landmarks: {fields: [...]}' or give the file a top-level 'landmarks'");
      }
    }
  }
  {
    auto p = top.map("parts");
    std::vector<std::string> names;
    for (const auto& c : o.cases) names.push_back(c.name);
    const auto pick = [&](io::YamlMap& m, const std::string& key) { return m.has(key) ? m.choice(key, "", names) : std::string(); };
    o.table1 = pick(p, "table1");
    o.little_overlap = pick(p, "little_overlap");
    o.large_overlap = pick(p, "large_overlap");
    o.overlap_small = pick(p, "overlap_small");
    o.overlap_large = pick(p, "overlap_large");
    {
      auto n = p.map("noise");
      o.noise_case = pick(n, "case");
      if (n.has("range_noise")) {
        o.noise_levels = n.numbers("range_noise");
        for (double v : o.noise_levels) {
          if (!(v >= 0.0 && v <= 1000.0)) throw InputError(n.where("range_noise") + ": expected noise levels from 0 to 1000 m");
        }
      }
      n.finish();
    }
    if (const auto merges = p.node("merges")) {
      if (!merges->IsSequence()) throw InputError(p.where("merges") + ": expected a list of case names");
      for (const auto& m : *merges) {
        const std::string name = m.IsScalar() ? m.Scalar() : "";
        if (std::find(names.begin(), names.end(), name) == names.end()) {
          throw InputError(p.where_node(m) + ": key 'parts.merges': no case is named '" + name + "'");
        }
        o.merges.push_back(name);
      }
    }
    p.finish();
  }
  top.finish();
  // Robots must meet: on their noise-free paths, every follower within the camera's range of the
  // leader at every rendezvous (checked before anything runs or is written).
  for (const auto& c : o.cases) {
    std::vector<std::vector<core::Pose2>> planned;
    for (const auto& r : c.robots) {
      planned.push_back({r.start});
      for (const auto& u : path_commands(r.start, r.path, o.speed_mps, c.steps, o.period_s, o.robot.max_turn_rate_rps)) {
        planned.back().push_back(localization::integrate_motion(planned.back().back(), u));
      }
    }
    for (int k : c.rendezvous) {
      for (std::size_t j = 1; j < c.robots.size(); ++j) {
        const double d = (planned[0][std::size_t(k)].position() - planned[j][std::size_t(k)].position()).norm();
        if (d > o.camera.max_range_m) {
          throw InputError(fmt::format("{}: case '{}': robots {} and {} would be {:.1f} m apart at the rendezvous of step {}, "
                                       "beyond the camera's range of {:g} m: move their paths' ends closer",
                                       source, c.name, c.robots[0].name, c.robots[j].name, d, k, o.camera.max_range_m));
        }
      }
    }
  }
  return o;
}

}  // namespace fleetmap::experiments
