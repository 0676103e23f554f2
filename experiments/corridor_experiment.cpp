#include "experiments/corridor_experiment.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include "core/angle.h"
#include "core/error.h"
#include "core/format.h"
#include "core/random.h"
#include "io/file_io.h"
#include "io/yaml_reader.h"
#include "localization/localizer.h"
#include "mapping/map_quality.h"
#include "merging/fusion.h"
#include "merging/rendezvous.h"
#include "sim/simulation.h"

namespace fleetmap::experiments {

sim::RangeSensorOptions default_laser() {
  sim::RangeSensorOptions l;
  for (int b = 0; b <= 180; ++b) l.angles_rad.push_back(core::deg2rad(-90.0 + b));
  l.beams = 181;
  l.max_range_m = 8.0;
  l.noise_m = 0.02;
  return l;
}

CorridorOptions::CorridorOptions() : laser(default_laser()) {}

namespace {

constexpr double kWall = 0.3;    // m, wall thickness
constexpr double kMargin = 1.0;  // m, free space around the outer wall

std::string fmt(double v) {
  return fmt::format("{:g}", v);
}

}  // namespace

bool is_corridor_scenario(const std::string& text, const std::string& source) {
  const YAML::Node root = io::parse_yaml(text, source);
  return root.IsMap() && root["experiment"] && root["experiment"].IsScalar() &&
         root["experiment"].as<std::string>() == "leon_corridor";
}

CorridorOptions parse_corridor_options(const std::string& text, const std::string& source) {
  io::YamlMap top(io::parse_yaml(text, source), source);
  CorridorOptions o;
  const std::string experiment = top.text("experiment", "");
  if (experiment != "leon_corridor") {
    throw InputError(top.where("experiment") + ": expected 'leon_corridor', got '" + experiment + "'");
  }
  o.seed = std::uint64_t(top.integer("seed", 1, 0));
  o.seeds = int(top.integer("seeds", o.seeds, 1, 1000));
  {
    auto w = top.map("world");
    o.length_m = w.number("length", o.length_m, 2.0, 1000.0);
    o.height_m = w.number("height", o.height_m, 2.0, 1000.0);
    o.corridor_width_m = w.number("corridor_width", o.corridor_width_m, 0.5, 100.0);
    o.resolution_m = w.number("resolution", o.resolution_m, 0.01, 1.0);
    w.finish();
  }
  {
    auto d = top.map("drive");
    if (d.has("laps")) {
      o.laps.clear();
      for (double l : d.numbers("laps")) {
        if (l != std::floor(l) || l < 1 || l > 100) {
          throw InputError(d.where("laps") + ": expected whole numbers of laps from 1 to 100, got " + fmt(l));
        }
        o.laps.push_back(int(l));
      }
      if (o.laps.empty()) throw InputError(d.where("laps") + ": expected at least one lap count");
      std::sort(o.laps.begin(), o.laps.end());
    }
    o.speed_mps = d.number("speed", o.speed_mps, 0.01, 10.0);
    o.period_s = d.number("period", o.period_s, 0.01, 10.0);
    d.finish();
  }
  {
    auto od = top.map("odometry");
    o.odometry.scale_error = od.number("scale_error", o.odometry.scale_error, -0.5, 0.5);
    o.odometry.turn_bias_deg_per_m = od.number("turn_bias_deg_per_m", o.odometry.turn_bias_deg_per_m, -90.0, 90.0);
    o.odometry.speed_noise = od.number("speed_noise", o.odometry.speed_noise, 0.0, 10.0);
    o.odometry.turn_noise_deg = od.number("turn_noise_deg", o.odometry.turn_noise_deg, 0.0, 90.0);
    od.finish();
  }
  {
    auto l = top.map("laser");
    const int beams = int(l.integer("beams", 181, 2, 10000));
    const double fov = l.number("fov_deg", 180.0, 1.0, 360.0);
    o.laser.max_range_m = l.number("max_range", o.laser.max_range_m, 0.1, 100.0);
    o.laser.noise_m = l.number("noise", o.laser.noise_m, 0.0, 1.0);
    l.finish();
    o.laser.angles_rad.clear();
    for (int b = 0; b < beams; ++b) o.laser.angles_rad.push_back(core::deg2rad(-0.5 * fov + fov * b / (beams - 1)));
    o.laser.beams = beams;
  }
  {
    auto m = top.map("methods");
    if (m.has("list")) {
      o.methods.clear();
      const auto node = *m.node("list");
      if (!node.IsSequence()) throw InputError(m.where("list") + ": expected a list of localizer names");
      for (const auto& n : node) {
        if (!n.IsScalar()) throw InputError(m.where("list") + ": expected a list of localizer names, got an item " + io::describe_node(n));
        o.methods.push_back(n.Scalar());
      }
    }
    // Every other key is a parameter of the localizers in the list that declare it (`particles: 30`
    // sets rbpf's and fastslam-grid's); `rbpf_particles` is its older name.
    if (m.has("rbpf_particles") && m.has("particles")) throw InputError(m.where("rbpf_particles") + ": give 'particles' only (rbpf_particles is its older name)");
    o.localizer_settings.clear();
    for (const auto& key : m.keys()) {
      if (key == "list") continue;
      const auto node = *m.node(key);
      if (!node.IsScalar()) throw InputError(m.where(key) + ": expected a value, got " + io::describe_node(node));
      const std::string name = key == "rbpf_particles" ? "particles" : key;
      bool declared = false;
      for (const auto& method : o.methods) {
        core::Params p = localization::localizer_options(method);  // unknown names: the list's own error
        if (!p.declares(name)) continue;
        declared = true;
        try {
          p.set(name, node.Scalar());
        } catch (const InputError& e) {
          throw InputError(m.where(key) + ": " + e.what());
        }
      }
      if (!declared) {
        throw InputError(m.where(key) + ": no localizer of the list (" + core::join(o.methods) + ") has a parameter '" + name + "'");
      }
      o.localizer_settings.emplace_back(name, node.Scalar());
    }
    m.finish();
  }
  {
    auto mg = top.map("merge_by_detection");
    o.merge_study = mg.boolean("enabled", o.merge_study);
    if (mg.has("orientation_errors_deg")) o.detection_errors_deg = mg.numbers("orientation_errors_deg");
    mg.finish();
  }
  top.finish();
  return o;
}

mapping::OccupancyGrid corridor_world(const CorridorOptions& o) {
  if (2.0 * o.corridor_width_m + 2.0 * kWall >= std::min(o.length_m, o.height_m)) {
    throw InputError("world.corridor_width: " + fmt(o.corridor_width_m) + " m leaves no inner block in a " +
                     fmt(o.length_m) + " m x " + fmt(o.height_m) + " m loop");
  }
  const double total_x = o.length_m + 2.0 * (kWall + kMargin), total_y = o.height_m + 2.0 * (kWall + kMargin);
  const int w = int(std::ceil(total_x / o.resolution_m)), h = int(std::ceil(total_y / o.resolution_m));
  // The free loop spans [0, length] x [0, height]; the grid starts at the margin's outer corner.
  mapping::OccupancyGrid g(core::GridGeometry(o.resolution_m, w, h, core::Pose2(-kWall - kMargin, -kWall - kMargin, 0.0)));
  const double cw = o.corridor_width_m;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector2d p = g.geometry().cell_center({x, y});
      const bool in_outer = p.x() > -kWall && p.x() < o.length_m + kWall && p.y() > -kWall && p.y() < o.height_m + kWall;
      const bool in_loop = p.x() > 0 && p.x() < o.length_m && p.y() > 0 && p.y() < o.height_m;
      const bool in_block = p.x() > cw && p.x() < o.length_m - cw && p.y() > cw && p.y() < o.height_m - cw;
      const bool wall = (in_outer && !in_loop) || in_block;
      g.set_state({x, y}, wall ? mapping::CellState::Occupied : mapping::CellState::Free);
    }
  }
  return g;
}

MapDimensions measure_loop(const mapping::OccupancyGrid& map) {
  const int w = map.width(), h = map.height();
  cv::Mat occupied(h, w, CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (map.state_at(map.geometry().index({x, y})) == mapping::CellState::Occupied) occupied.at<std::uint8_t>(y, x) = 255;
    }
  }
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(occupied, labels, stats, centroids, 8);
  std::vector<cv::Point2f> points;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int l = labels.at<int>(y, x);
      if (l == 0 || stats.at<int>(l, cv::CC_STAT_AREA) < 10) continue;
      points.emplace_back(float(x), float(y));
    }
  }
  (void)n;
  MapDimensions d;
  if (points.size() < 3) return d;
  const cv::RotatedRect r = cv::minAreaRect(points);
  // The outermost occupied cells are the walls' first cells; their centres lie half a cell beyond
  // the faces they bound: the free space between the faces is one cell shorter.
  const double a = (r.size.width - 1.0) * map.resolution(), b = (r.size.height - 1.0) * map.resolution();
  d.found = true;
  d.length_m = std::max(a, b);
  d.height_m = std::min(a, b);
  return d;
}

namespace {

// The loop's centre line, counter-clockwise from the lower-left corner.
std::vector<Eigen::Vector2d> centre_line(const CorridorOptions& o) {
  const double c = 0.5 * o.corridor_width_m;
  return {{c, c}, {o.length_m - c, c}, {o.length_m - c, o.height_m - c}, {c, o.height_m - c}};
}

localization::LocalizerContext context_for(const CorridorOptions& o, const std::string& method, const core::Pose2& start,
                                           std::uint64_t seed) {
  localization::LocalizerContext c;
  c.params = localization::localizer_options(method, localization::localizer_registry().declared(method, o.localizer_settings));
  c.initial_pose = start;
  c.seed = seed;
  // The filters' noise model: one step's odometry error (speed and turn noise over a period).
  c.options.process_noise_xy = std::max(1e-3, o.odometry.speed_noise * o.period_s + std::abs(o.odometry.scale_error) * o.speed_mps * o.period_s);
  c.options.process_noise_theta = std::max(1e-4, core::deg2rad(o.odometry.turn_noise_deg) * o.period_s +
                                                     core::deg2rad(std::abs(o.odometry.turn_bias_deg_per_m)) * o.speed_mps * o.period_s);
  c.options.range_noise = o.laser.noise_m;
  c.options.initial_xy = 0.0;
  c.options.initial_theta = 0.0;
  return c;
}

// One robot's drive on the simulator, and what the experiment keeps of it.
struct Drive {
  std::vector<core::Pose2> truth;     // truth[0] = start, truth[k] after step k (world frame)
  std::vector<core::Pose2> estimate;  // the localizer's, in its map frame
  std::vector<int> lap_end;           // step at which lap i+1 ended
  std::vector<mapping::OccupancyGrid> maps;  // the map at the end of each lap count asked for
  std::vector<double> seconds;               // the localizer's time until then
};

struct DriveSpec {
  core::Pose2 start;
  sim::WaypointDrive way;
  std::string method;      // a registered localizer
  std::uint64_t seed = 0;  // the localizer's
  // Maps in its own frame (its start at the origin) on this grid; none: the world's frame and grid.
  std::optional<core::GridGeometry> own_frame;
};

// Drives one robot along its waypoints on the simulator: a line follower on the true pose, its
// odometry misreported (scale error, turn bias and noise), its odometry and laser noise drawn from
// `rng` (one stream for the whole drive, which drives may share one after the other), localized by
// `spec.method` and mapping at its estimate (or taking the localizer's own map). The map is kept at
// the end of each lap count of `laps` (sorted); a drive that ends early keeps its last map for the rest.
Drive drive(const CorridorOptions& o, const mapping::OccupancyGrid& truth, const DriveSpec& spec,
            const std::shared_ptr<core::Random>& rng, const std::vector<int>& laps) {
  sim::Scenario scenario;
  scenario.seed = o.seed;
  scenario.steps = 100000;
  scenario.period_s = o.period_s;
  scenario.robot_count = 1;
  scenario.placement = sim::Placement::List;
  scenario.starts = {spec.start};
  scenario.robot.radius_m = 0.05;  // a point on the centre line, well clear of the walls
  scenario.robot.max_speed_mps = spec.way.speed_mps;
  scenario.robot.max_turn_rate_rps = spec.way.max_turn_rate_rps;
  scenario.range = o.laser;
  scenario.localization = spec.method;
  scenario.merging = spec.own_frame ? "rendezvous" : "known";
  sim::SimulationSetup how;
  how.measure_coverage = false;
  sim::RobotSetup& robot = how.robots.emplace_back();
  auto driver = std::make_shared<sim::WaypointDriver>(spec.way, o.period_s);
  robot.driver = driver;
  robot.motion_rng = robot.sensor_rng = rng;
  robot.odometry_error = sim::OdometryError{o.odometry.scale_error, core::deg2rad(o.odometry.turn_bias_deg_per_m),
                                            o.odometry.speed_noise, core::deg2rad(o.odometry.turn_noise_deg)};
  robot.localizer = [&](const localization::LocalizerContext& c) {
    return localization::make_localizer(spec.method, context_for(o, spec.method, c.initial_pose, spec.seed));
  };
  robot.map_geometry = spec.own_frame;

  Drive d;
  const auto keep = [&](const sim::Simulation& s) {
    auto mine = s.localizer(0).map_estimate();
    d.maps.push_back(mine ? std::move(*mine) : s.robot_map(0));
    d.seconds.push_back(s.track(0).localization_s);
  };
  std::size_t laps_done = 0;
  sim::Simulation simulation(scenario, truth, std::move(how));
  simulation.run_to_end({}, [&](const sim::Simulation& s) {
    d.truth.push_back(s.true_poses()[0]);
    d.estimate.push_back(s.localizer(0).pose());
    const auto& ends = driver->lap_ends();
    if (ends.size() > laps_done && ends.back() == s.step_count()) {
      laps_done = ends.size();
      for (int l : laps) {
        if (l == int(laps_done)) keep(s);
      }
    }
  });
  d.lap_end = driver->lap_ends();
  if (d.lap_end.size() < std::size_t(spec.way.closed ? spec.way.laps : 1)) d.lap_end.push_back(simulation.step_count());
  while (d.maps.size() < laps.size()) keep(simulation);
  return d;
}

}  // namespace

CorridorResult run_corridor_experiment(const CorridorOptions& o, const CorridorProgress& progress) {
  for (const auto& m : o.methods) {
    const std::vector<std::string> valid = {"ideal", "odometry", "scan-matching", "fastslam-grid", "rbpf"};
    if (std::find(valid.begin(), valid.end(), m) == valid.end()) {
      throw InputError("methods.list: '" + m +
                       "' is not compared here (valid: ideal, odometry, scan-matching, fastslam-grid, rbpf)");
    }
  }
  if (o.laps.empty()) throw InputError("drive.laps: expected at least one lap count");
  CorridorResult result;
  result.options = o;
  result.truth = corridor_world(o);
  result.real = {true, o.length_m, o.height_m};
  const auto& g = result.truth.geometry();
  if (o.seeds < 1) throw InputError("seeds: expected at least 1, got " + std::to_string(o.seeds));
  const int total_work = o.seeds * int(o.methods.size()) + (o.merge_study ? 2 + int(o.detection_errors_deg.size()) : 0);
  int done = 0;

  // Every method drives the same drive: the same seed gives the same odometry and the same scans
  // (the robot steers on its true pose, whatever the method believes).
  const auto line = centre_line(o);
  const core::Pose2 start(line[0].x(), line[0].y(), 0.0);
  const auto way = [&](std::vector<Eigen::Vector2d> waypoints, bool closed, int laps) {
    sim::WaypointDrive w;
    w.waypoints = std::move(waypoints);
    w.closed = closed;
    w.laps = laps;
    w.speed_mps = o.speed_mps;
    w.max_turn_rate_rps = core::deg2rad(45.0);
    w.turn_in_place_rad = core::deg2rad(30.0);
    w.reached_m = 0.3;
    return w;
  };
  for (int k = 0; k < o.seeds; ++k) {
    for (const auto& method : o.methods) {
      const std::uint64_t seed = o.seed + std::uint64_t(k);
      const Drive r = drive(o, result.truth, {start, way(line, true, o.laps.back()), method, seed + 7, std::nullopt},
                            std::make_shared<core::Random>(core::Random(seed).fork(1)), o.laps);
      for (std::size_t i = 0; i < o.laps.size(); ++i) {
        CorridorRun run;
        run.method = method;
        run.seed = seed;
        run.laps = o.laps[i];
        run.map = r.maps[i];
        run.dimensions = measure_loop(run.map);
        run.length_error = std::abs(run.dimensions.length_m - o.length_m) / o.length_m;
        run.height_error = std::abs(run.dimensions.height_m - o.height_m) / o.height_m;
        const int end = r.lap_end[std::size_t(std::min<int>(o.laps[i], int(r.lap_end.size())) - 1)];
        run.truth.assign(r.truth.begin(), r.truth.begin() + end + 1);
        run.estimate.assign(r.estimate.begin(), r.estimate.begin() + end + 1);
        run.final_position_error_m = (run.truth.back().position() - run.estimate.back().position()).norm();
        run.seconds = r.seconds[i];
        result.runs.push_back(std::move(run));
      }
      if (progress) progress(++done, total_work);
    }
  }
  if (!o.merge_study) return result;

  // Merging by detection. From the lower-left corner the master drives the bottom and right
  // corridors, the other the left and top ones; they meet at the upper-right corner. Each maps
  // with scan matching in its own frame: the master's is the world's, the other's has its start at
  // the origin. One stream serves the master's drive, then the other's, then the detection.
  const double c = 0.5 * o.corridor_width_m;
  const core::Pose2 master_start(c + 1.0, c, 0.0);
  const core::Pose2 other_start(c, c + 1.0, std::numbers::pi / 2.0);
  const std::vector<Eigen::Vector2d> master_way = {{o.length_m - c, c}, {o.length_m - c, o.height_m - c - 1.5}};
  const std::vector<Eigen::Vector2d> other_way = {{c, o.height_m - c}, {o.length_m - c - 1.5, o.height_m - c}};
  const auto merge_rng = std::make_shared<core::Random>(core::Random(o.seed).fork(2));
  const double half = std::hypot(g.width_m(), g.height_m()) + 2.0;
  const core::GridGeometry other_geometry(o.resolution_m, int(std::ceil(2.0 * half / o.resolution_m)),
                                          int(std::ceil(2.0 * half / o.resolution_m)), core::Pose2(-half, -half, 0.0));
  const Drive master_run = drive(o, result.truth, {master_start, way(master_way, false, 1), "scan-matching", o.seed + 11,
                                                   std::nullopt},
                                 merge_rng, {1});
  if (progress) progress(++done, total_work);
  const Drive other_run = drive(o, result.truth, {other_start, way(other_way, false, 1), "scan-matching", o.seed + 13,
                                                  other_geometry},
                                merge_rng, {1});
  if (progress) progress(++done, total_work);
  result.master_path = master_run.truth;
  result.other_path = other_run.truth;
  result.meeting_master = master_run.truth.back();
  result.meeting_other = other_run.truth.back();

  // The detection, both ways, from the true poses with the detector's noise.
  const sim::RobotDetectorOptions detector;
  const Eigen::Vector2d d = result.meeting_other.position() - result.meeting_master.position();
  const double range = d.norm() + merge_rng->normal(0.0, detector.range_noise_m);
  const double bearing_mo = core::normalize_angle(std::atan2(d.y(), d.x()) - result.meeting_master.theta +
                                                  merge_rng->normal(0.0, detector.bearing_noise_rad));
  const double bearing_om = core::normalize_angle(std::atan2(-d.y(), -d.x()) - result.meeting_other.theta +
                                                  merge_rng->normal(0.0, detector.bearing_noise_rad));
  // The truth: the other's frame in the world is its start pose.
  const core::Transform2 true_other_to_master = other_start.as_transform();
  result.master_map = master_run.maps.front();
  result.other_map = other_run.maps.front();
  const mapping::OccupancyGrid& master_map = result.master_map;
  const mapping::OccupancyGrid& other_map = result.other_map;
  for (double err_deg : o.detection_errors_deg) {
    DetectionMerge m;
    m.orientation_error_deg = err_deg;
    const core::Transform2 t = merging::rendezvous_transform_matrices(
        master_run.estimate.back(), other_run.estimate.back(), range, bearing_mo,
        core::normalize_angle(bearing_om + core::deg2rad(err_deg)));
    m.rotation_error_deg = core::rad2deg(std::abs(core::normalize_angle(t.rotation() - true_other_to_master.rotation())));
    m.far_end_error_m = (t.apply(Eigen::Vector2d::Zero()) - true_other_to_master.apply(Eigen::Vector2d::Zero())).norm();
    // A grid covering both maps, so the other's map, turned by a wrong orientation, is not cut at
    // the master grid's edge.
    m.merged = merging::fuse_pair(master_map, other_map,
                                  merging::cells_from_world(master_map.geometry(), other_map.geometry(), t)).grid;
    // The other's walls, placed by t, against the true walls.
    mapping::MapQualityOptions quality;
    quality.wall_tolerance_m = 0.3;
    const mapping::MapQuality q = mapping::map_quality(other_map, result.truth, t, quality);
    m.mean_wall_distance_m = q.mean_wall_distance_m;
    m.misplaced_wall_share = q.misplaced_wall_share;
    result.merges.push_back(std::move(m));
    if (progress) progress(++done, total_work);
  }
  return result;
}

}  // namespace fleetmap::experiments
