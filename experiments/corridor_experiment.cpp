#include "experiments/corridor_experiment.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include "core/angle.h"
#include "core/error.h"
#include "core/random.h"
#include "io/file_io.h"
#include "io/yaml_reader.h"
#include "localization/localizer.h"
#include "mapping/map_quality.h"
#include "mapping/range_scan.h"
#include "merging/fusion.h"
#include "merging/rendezvous.h"
#include "sim/world.h"

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
    o.rbpf_particles = int(m.integer("rbpf_particles", o.rbpf_particles, 1, 10000));
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

// Steers the true pose toward waypoint `target`: turn in place when more than 30 degrees off.
localization::Odometry steer(const core::Pose2& truth, const Eigen::Vector2d& target, const CorridorOptions& o) {
  const Eigen::Vector2d d = target - truth.position();
  const double err = core::normalize_angle(std::atan2(d.y(), d.x()) - truth.theta);
  const double max_turn = core::deg2rad(45.0);  // deg/s
  const double omega = std::clamp(err / o.period_s, -max_turn, max_turn);
  const double v = std::abs(err) > core::deg2rad(30.0) ? 0.0 : std::min(o.speed_mps, d.norm() / o.period_s);
  return {v, omega, o.period_s};
}

// One robot's recorded drive: true poses, what its odometry reported, what its laser read.
struct Drive {
  std::vector<core::Pose2> truth;                 // truth[0] = start, truth[k] after step k
  std::vector<localization::Odometry> odometry;  // odometry[k-1]: step k
  std::vector<localization::RangeScan> scans;     // scans[k] at truth[k]
  std::vector<int> lap_end;                       // step at which lap i+1 ends
};

Drive record_drive(const sim::World& world, const CorridorOptions& o, const core::Pose2& start,
                   const std::vector<Eigen::Vector2d>& waypoints, bool closed, int laps, core::Random& rng) {
  Drive d;
  d.truth.push_back(start);
  d.scans.push_back(sim::read_ranges(world, start, o.laser, rng));
  // A closed loop starts on its first waypoint and counts a lap each time it is back there.
  std::size_t next = closed ? 1 : 0;
  int lap = 0;
  const int limit = 100000;
  for (int k = 1; k <= limit; ++k) {
    const core::Pose2& p = d.truth.back();
    if ((waypoints[next] - p.position()).norm() < 0.3) {
      if (!closed && next + 1 == waypoints.size()) break;
      if (closed && next == 0) {
        d.lap_end.push_back(k - 1);
        if (++lap == laps) break;
      }
      next = (next + 1) % waypoints.size();
    }
    const localization::Odometry u = steer(p, waypoints[next], o);
    d.truth.push_back(localization::integrate_motion(p, u));
    d.truth.back().theta = core::normalize_angle(d.truth.back().theta);
    localization::Odometry r = u;
    r.v = u.v * (1.0 + o.odometry.scale_error) + rng.normal(0.0, o.odometry.speed_noise);
    r.omega = u.omega + core::deg2rad(o.odometry.turn_bias_deg_per_m) * std::abs(u.v) +
              rng.normal(0.0, core::deg2rad(o.odometry.turn_noise_deg));
    d.odometry.push_back(r);
    d.scans.push_back(sim::read_ranges(world, d.truth.back(), o.laser, rng));
  }
  if (d.lap_end.size() < std::size_t(closed ? laps : 1)) d.lap_end.push_back(int(d.odometry.size()));
  return d;
}

localization::LocalizerContext context_for(const CorridorOptions& o, const core::Pose2& start, std::uint64_t seed) {
  localization::LocalizerContext c;
  c.initial_pose = start;
  c.seed = seed;
  // The filters' noise model: one step's odometry error (speed and turn noise over a period).
  c.options.process_noise_xy = std::max(1e-3, o.odometry.speed_noise * o.period_s + std::abs(o.odometry.scale_error) * o.speed_mps * o.period_s);
  c.options.process_noise_theta = std::max(1e-4, core::deg2rad(o.odometry.turn_noise_deg) * o.period_s +
                                                     core::deg2rad(std::abs(o.odometry.turn_bias_deg_per_m)) * o.speed_mps * o.period_s);
  c.options.range_noise = o.laser.noise_m;
  c.options.initial_xy = 0.0;
  c.options.initial_theta = 0.0;
  c.options.rbpf_particles = o.rbpf_particles;
  return c;
}

struct Replay {
  std::vector<core::Pose2> estimate;
  std::vector<mapping::OccupancyGrid> maps;  // at each requested step
  double seconds = 0.0;
};

// Replays a drive through a localizer, mapping at its estimate (or taking its own map), and keeps
// the map at each step of `snapshots`.
Replay replay(const Drive& d, const std::string& method, const localization::LocalizerContext& c,
              const core::GridGeometry& geometry, const std::vector<int>& snapshots) {
  Replay r;
  auto loc = localization::make_localizer(method, c);
  mapping::OccupancyGrid own(geometry);
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < d.scans.size(); ++k) {
    if (k > 0) loc->predict(d.odometry[k - 1]);
    loc->observe_truth(d.truth[k]);
    loc->update_scan(d.scans[k], own);
    mapping::insert_scan(own, loc->pose(), d.scans[k]);
    r.estimate.push_back(loc->pose());
    if (std::find(snapshots.begin(), snapshots.end(), int(k)) != snapshots.end()) {
      auto mine = loc->map_estimate();
      r.maps.push_back(mine ? std::move(*mine) : own);
    }
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace

CorridorResult run_corridor_experiment(const CorridorOptions& o, const CorridorProgress& progress) {
  for (const auto& m : o.methods) {
    const std::vector<std::string> valid = {"ideal", "odometry", "scan-matching", "rbpf"};
    if (std::find(valid.begin(), valid.end(), m) == valid.end()) {
      throw InputError("methods.list: '" + m + "' is not compared here (valid: ideal, odometry, scan-matching, rbpf)");
    }
  }
  if (o.laps.empty()) throw InputError("drive.laps: expected at least one lap count");
  CorridorResult result;
  result.options = o;
  result.truth = corridor_world(o);
  result.real = {true, o.length_m, o.height_m};
  const sim::World world(result.truth, {});
  const auto& g = result.truth.geometry();
  const int total_work = int(o.methods.size()) + (o.merge_study ? 2 + int(o.detection_errors_deg.size()) : 0);
  int done = 0;

  // One drive, replayed by every method: the same odometry and the same scans.
  core::Random rng = core::Random(o.seed).fork(1);
  const auto line = centre_line(o);
  const core::Pose2 start(line[0].x(), line[0].y(), 0.0);
  const Drive drive = record_drive(world, o, start, line, true, o.laps.back(), rng);
  std::vector<int> snapshots;
  for (int laps : o.laps) snapshots.push_back(drive.lap_end[std::size_t(std::min<int>(laps, int(drive.lap_end.size())) - 1)]);
  for (const auto& method : o.methods) {
    const Replay r = replay(drive, method, context_for(o, start, o.seed + 7), g, snapshots);
    for (std::size_t i = 0; i < o.laps.size(); ++i) {
      CorridorRun run;
      run.method = method;
      run.laps = o.laps[i];
      run.map = r.maps[i];
      run.dimensions = measure_loop(run.map);
      run.length_error = std::abs(run.dimensions.length_m - o.length_m) / o.length_m;
      run.height_error = std::abs(run.dimensions.height_m - o.height_m) / o.height_m;
      const int end = snapshots[i];
      run.truth.assign(drive.truth.begin(), drive.truth.begin() + end + 1);
      run.estimate.assign(r.estimate.begin(), r.estimate.begin() + end + 1);
      run.final_position_error_m = (run.truth.back().position() - run.estimate.back().position()).norm();
      run.seconds = r.seconds * double(end + 1) / double(drive.scans.size());
      result.runs.push_back(std::move(run));
    }
    if (progress) progress(++done, total_work);
  }
  if (!o.merge_study) return result;

  // Merging by detection. From the lower-left corner the master drives the bottom and right
  // corridors, the other the left and top ones; they meet at the upper-right corner.
  const double c = 0.5 * o.corridor_width_m;
  const core::Pose2 master_start(c + 1.0, c, 0.0);
  const core::Pose2 other_start(c, c + 1.0, std::numbers::pi / 2.0);
  const std::vector<Eigen::Vector2d> master_way = {{o.length_m - c, c}, {o.length_m - c, o.height_m - c - 1.5}};
  const std::vector<Eigen::Vector2d> other_way = {{c, o.height_m - c}, {o.length_m - c - 1.5, o.height_m - c}};
  core::Random merge_rng = core::Random(o.seed).fork(2);
  const Drive master = record_drive(world, o, master_start, master_way, false, 1, merge_rng);
  const Drive other = record_drive(world, o, other_start, other_way, false, 1, merge_rng);
  if (progress) progress(++done, total_work);
  // Each maps with scan matching in its own frame: the master's is the world's, the other's has its
  // start at the origin.
  const Replay master_run = replay(master, "scan-matching", context_for(o, master_start, o.seed + 11), g,
                                   {int(master.scans.size()) - 1});
  const double half = std::hypot(g.width_m(), g.height_m()) + 2.0;
  const core::GridGeometry other_geometry(o.resolution_m, int(std::ceil(2.0 * half / o.resolution_m)),
                                          int(std::ceil(2.0 * half / o.resolution_m)), core::Pose2(-half, -half, 0.0));
  const Replay other_run = replay(other, "scan-matching", context_for(o, core::Pose2(), o.seed + 13), other_geometry,
                                  {int(other.scans.size()) - 1});
  if (progress) progress(++done, total_work);
  result.master_path = master.truth;
  result.other_path = other.truth;
  result.meeting_master = master.truth.back();
  result.meeting_other = other.truth.back();

  // The detection, both ways, from the true poses with the detector's noise.
  const sim::RobotDetectorOptions detector;
  const Eigen::Vector2d d = result.meeting_other.position() - result.meeting_master.position();
  const double range = d.norm() + merge_rng.normal(0.0, detector.range_noise_m);
  const double bearing_mo = core::normalize_angle(std::atan2(d.y(), d.x()) - result.meeting_master.theta +
                                                  merge_rng.normal(0.0, detector.bearing_noise_rad));
  const double bearing_om = core::normalize_angle(std::atan2(-d.y(), -d.x()) - result.meeting_other.theta +
                                                  merge_rng.normal(0.0, detector.bearing_noise_rad));
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
