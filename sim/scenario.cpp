#include "sim/scenario.h"
#include "sim/scenario_yaml.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <sstream>

#include <fmt/format.h>
#include "core/format.h"
#include "core/angle.h"
#include "core/error.h"
#include "core/params.h"
#include "core/suggest.h"
#include "io/file_io.h"
#include "io/file_kind.h"
#include "io/map_io.h"
#include "io/yaml_reader.h"
#include "exploration/strategy.h"
#include "maps/builtin_maps.h"
#include "merging/map_aligner.h"
#include "merging/merge.h"
#include "planning/planner.h"

namespace fleetmap::sim {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
using core::deg2rad;
using core::rad2deg;

std::vector<std::vector<double>> number_rows(io::YamlMap& m, const std::string& key, std::size_t lo, std::size_t hi,
                                             const std::string& shape) {
  std::vector<std::vector<double>> rows;
  const auto n = m.node(key);
  if (!n) return rows;
  if (!n->IsSequence()) throw InputError(m.where(key) + ": expected a list of " + shape + ", got " + io::describe_node(*n));
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
                       io::describe_node(item));
    }
    rows.push_back(row);
  }
  return rows;
}

std::string fmt(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return fmt::format("{:.15g}", v);
}


}  // namespace

std::vector<std::string> merging_names() { return merging::map_aligner_registry().names(); }

core::Params path_planner_options(const std::string& name) {
  // The wave's steepest descent is no registered planner and has no parameters.
  return name == "wave" ? core::Params("path planner 'wave'", {}) : planning::planner_registry().params(name);
}

std::vector<std::string> path_planner_names() {
  // OMPL's PRM* grows its roadmap for fixed wall-clock times in two threads: runs would not repeat.
  std::vector<std::string> names = {"wave"};
  for (const auto& n : planning::planner_names()) {
    if (n != "prmstar") names.push_back(n);
  }
  return names;
}

MotionNoise read_motion_noise(io::YamlMap noise, const MotionNoise& fallback) {
  MotionNoise n;
  n.position_m = noise.number("position", fallback.position_m, limits::kNoiseMetres);
  n.heading_rad = deg2rad(noise.number("heading_deg", rad2deg(fallback.heading_rad), limits::kAngleDeg));
  noise.finish();
  return n;
}

RobotDetectorOptions read_robot_detector(io::YamlMap det, const RobotDetectorOptions& fallback) {
  RobotDetectorOptions d = fallback;
  d.max_range_m = det.number("max_range", fallback.max_range_m, limits::kDetectorRange);
  d.fov_rad = deg2rad(det.number("fov_deg", rad2deg(fallback.fov_rad), limits::kAngleDeg));
  d.range_noise_m = det.number("range_noise", fallback.range_noise_m, limits::kNoiseMetres);
  d.bearing_noise_rad = deg2rad(det.number("bearing_noise_deg", rad2deg(fallback.bearing_noise_rad), limits::kAngleDeg));
  det.finish();
  return d;
}

namespace {

// The sections of a scenario file, each read into `s` (every key checked, errors name the key).
void read_robots(io::YamlMap& top, Scenario& s) {
  // robots: a count (packed cluster), `random: N`, or `starts: [[x, y, heading_deg], ...]`.
  if (const auto r = top.node("robots"); r && r->IsScalar()) {
    s.robot_count = int(top.number("robots", 4, limits::kRobots));
  } else {
    auto robots = top.map("robots");
    // node() marks a key as known, so that a message about an unknown key lists all three.
    const bool has_count = robots.node("count").has_value(), has_random = robots.node("random").has_value(),
               has_starts = robots.node("starts").has_value();
    if (int(has_count) + int(has_random) + int(has_starts) > 1) {
      throw InputError(robots.where(has_starts ? "starts" : "random") +
                       ": give only one of 'count' (a cluster), 'random: N' or 'starts'");
    }
    s.robot_count = int(robots.number("count", s.robot_count, limits::kRobots));
    if (has_random) {
      s.placement = Placement::Random;
      s.robot_count = int(robots.number("random", 4, limits::kRobots));
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
    s.min_separation_m = robots.number("min_separation", s.min_separation_m, limits::kSeparation);
    s.robot.radius_m = robots.number("radius", s.robot.radius_m, limits::kRadius);
    s.robot.max_speed_mps = robots.number("max_speed", s.robot.max_speed_mps, limits::kSpeed);
    s.robot.max_turn_rate_rps = deg2rad(robots.number("max_turn_rate_deg", rad2deg(s.robot.max_turn_rate_rps), limits::kTurnRateDeg));
    robots.finish();
  }
}

void read_sensors(io::YamlMap& top, Scenario& s) {
  auto sensors = top.map("sensors");
  auto range = sensors.map("range");
  s.range.beams = int(range.number("beams", s.range.beams, limits::kBeams));
  for (double a : range.numbers("angles_deg")) s.range.angles_rad.push_back(deg2rad(a));
  if (range.has("angles_deg") && s.range.angles_rad.empty()) throw InputError(range.where("angles_deg") + ": needs at least one angle");
  s.range.max_range_m = range.number("max_range", s.range.max_range_m, limits::kSensorRange);
  s.range.noise_m = range.number("noise", s.range.noise_m, limits::kNoiseMetres);
  range.finish();
  auto lm = sensors.map("landmarks");
  s.landmark_sensor.max_range_m = lm.number("max_range", s.landmark_sensor.max_range_m, limits::kDetectorRange);
  s.landmark_sensor.range_noise_m = lm.number("range_noise", s.landmark_sensor.range_noise_m, limits::kNoiseMetres);
  s.landmark_sensor.bearing_noise_rad =
      deg2rad(lm.number("bearing_noise_deg", rad2deg(s.landmark_sensor.bearing_noise_rad), limits::kAngleDeg));
  s.landmark_sensor.report_ids = lm.boolean("report_ids", s.landmark_sensor.report_ids);
  lm.finish();
  s.detector = read_robot_detector(sensors.map("robots"), s.detector);
  sensors.finish();
}

void read_landmarks(io::YamlMap& top, Scenario& s) {
  auto lm = top.map("landmarks");
  for (const auto& row : number_rows(lm, "points", 2, 2, "[x, y]")) s.landmarks.emplace_back(row[0], row[1]);
  s.landmarks_along_walls = lm.number("along_walls", 0.0, limits::kLandmarksPerMetre);
  lm.finish();
}

// The member-specific keys of `localization` before each localizer declared its own parameters, and
// the localizers whose `particles` each set. Old files still read: the key sets `particles` of the
// localizers it named and is ignored by the others, as it always was.
const std::vector<std::pair<std::string, std::vector<std::string>>>& old_particle_keys() {
  static const std::vector<std::pair<std::string, std::vector<std::string>>> kKeys = {
      {"mcl_particles", {"mcl"}}, {"rbpf_particles", {"rbpf", "fastslam-grid"}}, {"fastslam_particles", {"fastslam2"}}};
  return kKeys;
}

// `localization`: a localizer's name, or a mapping of the settings every localizer shares (the
// data association, the start's uncertainty, lost robots), its name (`name`, or `method` as older
// files write it) and the parameters that localizer declares.
void read_localization(io::YamlMap& top, Scenario& s) {
  if (const auto l = top.node("localization"); l && l->IsScalar()) {
    s.localization = top.choice("localization", s.localization, localization::localizer_names());
    s.localization_settings.clear();
    return;
  }
  auto loc = top.map("localization");
  if (loc.has("name") && loc.has("method")) throw InputError(loc.where("method") + ": give the localizer's 'name' only once");
  const std::string name = loc.choice(loc.has("method") ? "method" : "name", s.localization, localization::localizer_names());
  if (name != s.localization) s.localization_settings.clear();
  s.localization = name;
  auto& o = s.localization_options;
  o.known_associations = loc.boolean("known_associations", o.known_associations);
  o.association_gate = loc.number("association_gate", o.association_gate, limits::kGate);
  o.use_robot_detections = loc.boolean("robot_detections", o.use_robot_detections);
  o.initial_xy = loc.number("initial_sigma_xy", o.initial_xy, limits::kInitialSigma);
  o.initial_theta = deg2rad(loc.number("initial_sigma_heading_deg", rad2deg(o.initial_theta), limits::kAngleDeg));
  for (double r : loc.numbers("lost_robots")) {
    if (r != std::floor(r) || r < 1) {
      throw InputError(loc.where("lost_robots") + ": expected robot numbers from 1, got " + fmt(r));
    }
    s.lost_robots.push_back(int(r));
  }
  core::Params params = localization::localizer_options(name, s.localization_settings);
  for (const auto& [old, members] : old_particle_keys()) {
    if (!loc.has(old)) continue;
    const std::string value = loc.text(old, "");
    if (std::find(members.begin(), members.end(), name) == members.end()) continue;
    if (loc.has("particles")) throw InputError(loc.where(old) + ": give 'particles' only (" + old + " is its older name)");
    io::set_declared(params, s.localization_settings, "particles", value, loc.where(old));
  }
  // The localizer's own parameters; a key another localizer declares is named as such, any other
  // unknown key gets the reader's "did you mean" over every key `localization` accepts.
  io::read_declared(loc, params, s.localization_settings);
  const auto others = localization::localizer_registry().parameter_names();
  for (const auto& key : loc.keys()) {
    if (std::find(others.begin(), others.end(), key) != others.end() && !params.declares(key)) {
      throw InputError(loc.where(key) + ": localization '" + name + "' has no parameter '" + key + "'" +
                       (params.specs().empty() ? std::string(" (it has none)") : ""));
    }
  }
  loc.finish();
}

void read_communication(io::YamlMap& top, Scenario& s) {
  auto comm = top.map("communication");
  s.communication.range_m = comm.number("range", s.communication.range_m, limits::kCommRange);
  s.communication.line_of_sight = comm.boolean("line_of_sight", s.communication.line_of_sight);
  comm.finish();
}

void read_exploration(io::YamlMap& top, Scenario& s) {
  auto ex = top.map("exploration");
  auto& e = s.exploration;
  const auto strategy = ex.member("strategy", {e.strategy, e.strategy_settings}, exploration::strategy_names(),
                                  [](const std::string& name) { return exploration::strategy_options(name); });
  e.strategy = strategy.name;
  e.strategy_settings = strategy.settings;
  // The strategies' settings were keys of `exploration` before each strategy declared its own.
  for (const auto& [old, key] : {std::pair{"beta", "beta"}, std::pair{"directional_weight", "weight"}}) {
    if (!ex.has(old)) continue;
    const std::string name = exploration::strategy_options(e.strategy).declares(key) ? e.strategy
                             : std::string(key) == "beta"                             ? "coordinated"
                                                                                      : "directional";
    throw InputError(ex.where(old) + ": the strategy's own settings moved into it: write 'strategy: {name: " + name +
                     ", " + key + ": " + (ex.node(old)->IsScalar() ? ex.node(old)->Scalar() : std::string("VALUE")) + "}'");
  }
  e.wave.eight_connected = ex.boolean("eight_connected", e.wave.eight_connected);
  e.wave.occupancy_weight = ex.number("occupancy_weight", e.wave.occupancy_weight, limits::kWeight);
  e.stall_steps = int(ex.number("stall_steps", e.stall_steps, limits::kCount));
  e.targets.piece_radius_m = ex.number("piece_radius", e.targets.piece_radius_m, limits::kLength);
  e.targets.frontiers.min_region_cells = int(ex.number("min_frontier_cells", e.targets.frontiers.min_region_cells, limits::kCount));
  e.traversability.safety_margin_m = ex.number("safety_margin", e.traversability.safety_margin_m, limits::kMargin);
  e.planning_resolution_m = ex.number("planning_resolution", e.planning_resolution_m, limits::kMargin);
  const auto planner = ex.member("path_planner", {s.path_planner, s.planner_settings}, path_planner_names(), path_planner_options);
  s.path_planner = planner.name;
  s.planner_settings = planner.settings;
  s.planner_time_s = ex.number("planner_time", s.planner_time_s, limits::kPlannerTime);
  s.planner_iterations = int(ex.number("planner_iterations", s.planner_iterations, limits::kPlannerIterations));
  ex.finish();
}

// The settings of merge method `method` in `s`, added empty when it has none.
core::Settings& merge_method_settings_of(Scenario& s, const std::string& method) {
  for (auto& [name, settings] : s.merge_method_settings) {
    if (name == method) return settings;
  }
  return s.merge_method_settings.emplace_back(method, core::Settings{}).second;
}

// `merging`: an aligner's name, or a mapping of its name (`mode`, or `name`), the attempts' pace
// shared by every aligner, and the parameters the aligner declares.
void read_merging(io::YamlMap& top, Scenario& s) {
  if (const auto m = top.node("merging"); m && m->IsScalar()) {
    s.merging = top.choice("merging", s.merging, merging_names());
    s.merging_settings.clear();
    return;
  }
  auto merge = top.map("merging");
  if (merge.has("name") && merge.has("mode")) throw InputError(merge.where("mode") + ": give the aligner's 'name' only once");
  const std::string name = merge.choice(merge.has("mode") ? "mode" : "name", s.merging, merging_names());
  if (name != s.merging) s.merging_settings.clear();
  s.merging = name;
  s.merge_attempt_every = int(merge.number("attempt_every", s.merge_attempt_every, limits::kCount));
  core::Params params = merging::map_aligner_options(name, s.merging_settings);
  io::read_declared(merge, params, s.merging_settings);
  // The merge methods' parameters, a block per method (`features: {ratio: 0.7}`).
  for (const auto& method : merging::merge_method_names()) {
    if (!merge.has(method)) continue;
    auto block = merge.map(method);
    core::Params declared = merging::merge_method_registry().params(method);
    for (const auto& key : block.keys()) {
      const auto node = *block.node(key);
      if (!node.IsScalar()) throw InputError(block.where(key) + ": expected a value, got " + io::describe_node(node));
      io::set_declared(declared, merge_method_settings_of(s, method), key, node.Scalar(), block.where(key));
    }
    block.finish();
  }
  // Files written before the aligners declared their parameters hold `method: auto` and
  // `min_confidence: 0.5` whatever the mode: those defaults are read as before, ignored by the
  // aligners that have no such parameter; another value there is a setting the aligner lacks.
  const std::vector<std::pair<std::string, std::string>> written_by_older = {{"method", "auto"}, {"min_confidence", "0.5"}};
  const auto others = merging::map_aligner_registry().parameter_names();
  for (const auto& key : merge.keys()) {
    if (params.declares(key) || std::find(others.begin(), others.end(), key) == others.end()) continue;
    const auto node = *merge.node(key);
    const bool older_default = std::any_of(written_by_older.begin(), written_by_older.end(), [&](const auto& kv) {
      return kv.first == key && node.IsScalar() && (node.Scalar() == kv.second || (kv.second == "0.5" && node.Scalar() == ".5"));
    });
    if (!older_default) {
      throw InputError(merge.where(key) + ": merging '" + name + "' has no parameter '" + key + "'" +
                       (params.specs().empty() ? std::string(" (it has none)") : ""));
    }
  }
  merge.finish();
}

// A setting's value as a YAML scalar: plain when it reads back as itself, quoted otherwise.
std::string yaml_scalar(const std::string& value) {
  const bool plain = !value.empty() &&
                     value.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.+-") == std::string::npos;
  return plain ? value : io::yaml_quoted(value);
}

// "KEY: VALUE, KEY: VALUE": settings inside a YAML flow mapping.
std::string settings_yaml(const core::Settings& settings) {
  std::string out;
  for (const auto& [key, value] : settings) out += (out.empty() ? "" : ", ") + key + ": " + yaml_scalar(value);
  return out;
}

// A member as a scenario writes it: its name alone, or {name: NAME, KEY: VALUE, ...}.
std::string member_yaml(const std::string& name, const core::Settings& settings) {
  if (settings.empty()) return name;
  return "{name: " + name + ", " + settings_yaml(settings) + "}";
}

}  // namespace

Scenario parse_scenario(const std::string& text, const std::string& source, const std::filesystem::path& base_dir) {
  const YAML::Node root = io::parse_yaml(text, source);
  if (!root || root.IsNull()) throw InputError(source + ": empty scenario file");
  io::check_yaml_file_kind(root, source, io::YamlFileKind::ExploreScenario);
  io::YamlMap top(root, source);
  Scenario s;
  s.base_dir = base_dir;
  s.map = top.text("map", s.map);
  if (s.map.empty()) throw InputError(top.where("map") + ": expected a map name or file");
  s.map_resolution_m = top.number("map_resolution", s.map_resolution_m, io::kResolutionRange);
  s.seed = top.seed("seed", 1);
  s.steps = int(top.number("steps", s.steps, limits::kSteps));
  s.period_s = top.number("period", s.period_s, limits::kPeriod);
  read_robots(top, s);
  s.noise = read_motion_noise(top.map("noise"), s.noise);
  read_sensors(top, s);
  read_landmarks(top, s);
  read_localization(top, s);
  read_communication(top, s);
  read_exploration(top, s);
  read_merging(top, s);
  s.lookahead_m = top.number("lookahead", s.lookahead_m, limits::kLookahead);
  {
    auto outputs = top.map("outputs");
    s.html_replay = outputs.boolean("html", s.html_replay);
    outputs.finish();
  }
  top.finish();
  try {
    validate_scenario(s);
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());  // the key is in the message; the file is here
  }
  return s;
}

Scenario load_scenario(const std::filesystem::path& path) {
  return parse_scenario(io::read_file(path, 16 << 20), path.string(), path.parent_path());
}

const std::deque<ParameterFamily>& parameter_families() {
  static std::mutex mutex;
  static std::deque<ParameterFamily> families = {
      {"strategy", "exploration.strategy", [](const Scenario& s) { return s.exploration.strategy; },
       [](Scenario& s) -> core::Settings& { return s.exploration.strategy_settings; },
       [](const std::string& m) { return exploration::strategy_registry().params(m); },
       [] { return exploration::strategy_registry().parameter_names(); }},
      {"localization", "localization", [](const Scenario& s) { return s.localization; },
       [](Scenario& s) -> core::Settings& { return s.localization_settings; },
       [](const std::string& m) { return localization::localizer_registry().params(m); },
       [] { return localization::localizer_registry().parameter_names(); }},
      {"planner", "exploration.path_planner", [](const Scenario& s) { return s.path_planner; },
       [](Scenario& s) -> core::Settings& { return s.planner_settings; }, path_planner_options,
       [] { return planning::planner_registry().parameter_names(); }},
      {"merging", "merging", [](const Scenario& s) { return s.merging; },
       [](Scenario& s) -> core::Settings& { return s.merging_settings; },
       [](const std::string& m) { return merging::map_aligner_registry().params(m); },
       [] { return merging::map_aligner_registry().parameter_names(); }},
  };
  static std::size_t fixed = families.size();
  // One family per merge method, its only member: its parameters nest under `merging`.
  const std::lock_guard<std::mutex> lock(mutex);
  for (const auto& method : merging::merge_method_names()) {
    const std::string name = "merging." + method;
    if (std::any_of(families.begin() + std::ptrdiff_t(fixed), families.end(), [&](const auto& f) { return f.name == name; })) continue;
    families.push_back({name, name, [method](const Scenario&) { return method; },
                        [method](Scenario& s) -> core::Settings& { return merge_method_settings_of(s, method); },
                        [](const std::string& m) { return merging::merge_method_registry().params(m); },
                        [method] {
                          const core::Params params = merging::merge_method_registry().params(method);
                          std::vector<std::string> out;
                          for (const auto& spec : params.specs()) out.push_back(spec.name);
                          return out;
                        }});
  }
  return families;
}

const ParameterFamily* parameter_family(const std::string& name) {
  for (const auto& f : parameter_families()) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

void set_parameter(Scenario& s, const std::string& assignment, const std::string& what) {
  // The longest family name before the key: merging.features.ratio is the ratio of merging.features.
  const auto a = core::parse_param_assignment(assignment, what);
  const std::string dotted = a.family + "." + a.key;
  const ParameterFamily* family = nullptr;
  for (const auto& f : parameter_families()) {
    if (dotted.rfind(f.name + ".", 0) == 0 && dotted.find('.', f.name.size() + 1) == std::string::npos &&
        (!family || f.name.size() > family->name.size())) {
      family = &f;
    }
  }
  if (!family && parameter_family(a.family)) family = parameter_family(a.family);
  if (!family) {
    std::vector<std::string> names;
    for (const auto& f : parameter_families()) names.push_back(f.name);
    throw InputError(what + ": unknown family '" + a.family + "'" + core::did_you_mean(a.family, names) + " (--set takes " +
                     core::join(names, ".KEY=VALUE, ") + ".KEY=VALUE)");
  }
  const std::string key = dotted.substr(family->name.size() + 1);
  auto& settings = family->settings(s);
  std::erase_if(settings, [&](const auto& kv) { return kv.first == key; });
  settings.emplace_back(key, a.value);
}

void validate_scenario(const Scenario& s) {
  // The same ranges as the parser's, for scenarios made in code or changed by flags.
  const auto check = [](const char* key, double value, const core::Range& range) {
    if (core::parse_in_range(fmt(value), range) || (range.allow_inf && value == kInf)) return;
    throw InputError(std::string(key) + ": expected " + core::expected_text(range) + ", got " + fmt(value));
  };
  const int count = s.placement == Placement::List ? int(s.starts.size()) : s.robot_count;
  check("robots", count, limits::kRobots);
  check("steps", s.steps, limits::kSteps);
  check("period", s.period_s, limits::kPeriod);
  check("robots.min_separation", s.min_separation_m, limits::kSeparation);
  check("robots.radius", s.robot.radius_m, limits::kRadius);
  check("robots.max_speed", s.robot.max_speed_mps, limits::kSpeed);
  check("robots.max_turn_rate_deg", rad2deg(s.robot.max_turn_rate_rps), limits::kTurnRateDeg);
  check("noise.position", s.noise.position_m, limits::kNoiseMetres);
  check("noise.heading_deg", rad2deg(s.noise.heading_rad), limits::kAngleDeg);
  check("sensors.range.beams", s.range.beams, limits::kBeams);
  check("sensors.range.max_range", s.range.max_range_m, limits::kSensorRange);
  check("sensors.range.noise", s.range.noise_m, limits::kNoiseMetres);
  check("sensors.landmarks.max_range", s.landmark_sensor.max_range_m, limits::kDetectorRange);
  check("sensors.landmarks.range_noise", s.landmark_sensor.range_noise_m, limits::kNoiseMetres);
  check("sensors.landmarks.bearing_noise_deg", rad2deg(s.landmark_sensor.bearing_noise_rad), limits::kAngleDeg);
  check("sensors.robots.max_range", s.detector.max_range_m, limits::kDetectorRange);
  check("sensors.robots.fov_deg", rad2deg(s.detector.fov_rad), limits::kAngleDeg);
  check("sensors.robots.range_noise", s.detector.range_noise_m, limits::kNoiseMetres);
  check("sensors.robots.bearing_noise_deg", rad2deg(s.detector.bearing_noise_rad), limits::kAngleDeg);
  check("landmarks.along_walls", s.landmarks_along_walls, limits::kLandmarksPerMetre);
  const auto& o = s.localization_options;
  check("localization.association_gate", o.association_gate, limits::kGate);
  check("localization.initial_sigma_xy", o.initial_xy, limits::kInitialSigma);
  check("localization.initial_sigma_heading_deg", rad2deg(o.initial_theta), limits::kAngleDeg);
  check("communication.range", s.communication.range_m, limits::kCommRange);
  const auto& e = s.exploration;
  check("exploration.occupancy_weight", e.wave.occupancy_weight, limits::kWeight);
  check("exploration.stall_steps", e.stall_steps, limits::kCount);
  check("exploration.piece_radius", e.targets.piece_radius_m, limits::kLength);
  check("exploration.min_frontier_cells", e.targets.frontiers.min_region_cells, limits::kCount);
  check("exploration.safety_margin", e.traversability.safety_margin_m, limits::kMargin);
  check("exploration.planning_resolution", e.planning_resolution_m, limits::kMargin);
  check("exploration.planner_time", s.planner_time_s, limits::kPlannerTime);
  check("exploration.planner_iterations", s.planner_iterations, limits::kPlannerIterations);
  check("merging.attempt_every", s.merge_attempt_every, limits::kCount);
  check("lookahead", s.lookahead_m, limits::kLookahead);
  check("map_resolution", s.map_resolution_m, io::kResolutionRange);
  const auto check_name = [](const std::string& key, const std::string& value, const std::vector<std::string>& valid) {
    if (std::find(valid.begin(), valid.end(), value) != valid.end()) return;
    throw InputError(key + ": unknown value '" + value + "'" + core::did_you_mean(value, valid) + " (valid: " +
                     core::join(valid) + ")");
  };
  check_name("exploration.strategy", s.exploration.strategy, exploration::strategy_names());
  try {
    exploration::strategy_options(s.exploration.strategy, s.exploration.strategy_settings);
  } catch (const InputError& err) {
    throw InputError(std::string("exploration.strategy: ") + err.what());
  }
  check_name("localization", s.localization, localization::localizer_names());
  try {
    localization::localizer_options(s.localization, s.localization_settings);
  } catch (const InputError& err) {
    throw InputError(std::string("localization: ") + err.what());
  }
  for (int r : s.lost_robots) {
    if (s.localization != "mcl") throw InputError("localization.lost_robots: only 'mcl' can start without its pose, not '" + s.localization + "'");
    if (r < 1 || r > count) throw InputError("localization.lost_robots: robot " + std::to_string(r) + " does not exist (robots 1.." + std::to_string(count) + ")");
  }
  // Landmark localizers without landmarks would quietly be dead reckoning.
  if ((s.localization == "ekf" || s.localization == "ekf-slam" || s.localization == "fastslam2") && s.landmarks.empty() &&
      s.landmarks_along_walls <= 0.0) {
    throw InputError("localization '" + s.localization +
                     "' localizes against landmarks, and there are none: add some (landmarks: {along_walls: 0.5} places one "
                     "per 2 m of wall, landmarks: {points: [[x, y]]} where you want them), "
                     "or choose a localizer that needs none (odometry, scan-matching, rbpf, mcl, polynomial)");
  }
  check_name("merging", s.merging, merging_names());
  std::unique_ptr<merging::MapAligner> aligner;
  try {
    aligner = merging::make_map_aligner(s.merging, s.merging_settings, s.merge_method_settings);
  } catch (const InputError& err) {
    throw InputError(std::string("merging: ") + err.what());
  }
  if (aligner->needs_landmark_estimates()) {
    bool estimates = true;  // a localizer that cannot be made without a run is checked by the simulator
    try {
      estimates = localization::make_localizer(s.localization, {})->estimates_landmarks();
    } catch (const std::exception&) {
    }
    if (!estimates) throw InputError(landmark_merging_problem(s));
  }
  check_name("exploration.path_planner", s.path_planner, path_planner_names());
  try {
    core::Params planner = path_planner_options(s.path_planner);
    for (const auto& [key, value] : s.planner_settings) planner.set(key, value);
  } catch (const InputError& err) {
    throw InputError(std::string("exploration.path_planner: ") + err.what());
  }
}

std::string landmark_merging_problem(const Scenario& s) {
  std::vector<std::string> able;
  for (const auto& name : localization::localizer_names()) {
    try {
      if (localization::make_localizer(name, {})->estimates_landmarks()) able.push_back(name);
    } catch (const std::exception&) {
      // A localizer that cannot be made without a run is not one to suggest.
    }
  }
  return "merging '" + s.merging + "' aligns the robots' estimated landmark maps, and localization '" + s.localization +
         "' estimates no landmarks: choose one that does (" + core::join(able) +
         ", with landmarks: --landmarks 0.5) or a merging that needs none (overlap, rendezvous)";
}

std::string map_source(const Scenario& s) {
  namespace fs = std::filesystem;
  const fs::path p = s.map;
  const fs::path in_folder = p.is_relative() && !s.base_dir.empty() ? s.base_dir / p : p;
  std::error_code ec;
  if (maps::is_builtin_map(s.map) && !fs::is_regular_file(in_folder, ec)) return s.map;
  return in_folder.string();
}

std::string scenario_to_yaml(const Scenario& s, const std::filesystem::path& file_dir) {
  namespace fs = std::filesystem;
  std::string map = map_source(s);
  if (!maps::is_builtin_map(map) && !file_dir.empty()) {
    std::error_code ec;
    const fs::path absolute = fs::absolute(map, ec).lexically_normal();
    const fs::path relative = ec ? fs::path() : absolute.lexically_relative(fs::absolute(file_dir, ec).lexically_normal());
    map = (!ec && !relative.empty() ? relative : absolute).string();
  }
  std::ostringstream y;
  y << "# fleetmap scenario\n";
  y << "map: " << io::yaml_quoted(map) << "\nmap_resolution: " << fmt(s.map_resolution_m) << "\n";
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
  for (const auto& [key, value] : s.localization_settings) y << "  " << key << ": " << yaml_scalar(value) << "\n";
  if (!s.lost_robots.empty()) {
    y << "  lost_robots: [";
    for (std::size_t i = 0; i < s.lost_robots.size(); ++i) y << (i ? ", " : "") << s.lost_robots[i];
    y << "]\n";
  }
  y << "communication:\n  range: " << fmt(s.communication.range_m) << "\n  line_of_sight: " << (s.communication.line_of_sight ? "true" : "false") << "\n";
  const auto& e = s.exploration;
  y << "exploration:\n  strategy: {name: " << e.strategy;
  for (const auto& [key, value] : e.strategy_settings) y << ", " << key << ": " << yaml_scalar(value);
  y << "}\n  eight_connected: " << (e.wave.eight_connected ? "true" : "false") << "\n  occupancy_weight: " << fmt(e.wave.occupancy_weight)
    << "\n  stall_steps: " << e.stall_steps << "\n  piece_radius: " << fmt(e.targets.piece_radius_m)
    << "\n  min_frontier_cells: " << e.targets.frontiers.min_region_cells << "\n  safety_margin: " << fmt(e.traversability.safety_margin_m)
    << "\n  planning_resolution: " << fmt(e.planning_resolution_m) << "\n  path_planner: " << member_yaml(s.path_planner, s.planner_settings) << "\n  planner_time: " << fmt(s.planner_time_s)
    << "\n  planner_iterations: " << s.planner_iterations << "\n";
  y << "merging:\n  mode: " << s.merging << "\n  attempt_every: " << s.merge_attempt_every << "\n";
  for (const auto& [key, value] : s.merging_settings) y << "  " << key << ": " << yaml_scalar(value) << "\n";
  for (const auto& [method, settings] : s.merge_method_settings) {
    if (!settings.empty()) y << "  " << method << ": {" << settings_yaml(settings) << "}\n";
  }
  y << "lookahead: " << fmt(s.lookahead_m) << "\n";
  y << "outputs:\n  html: " << (s.html_replay ? "true" : "false") << "\n";
  return y.str();
}

}  // namespace fleetmap::sim
