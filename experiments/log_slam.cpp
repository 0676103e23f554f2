#include "experiments/log_slam.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/angle.h"
#include "core/error.h"
#include "core/format.h"
#include "core/suggest.h"
#include "localization/submap_grid.h"
#include "mapping/range_scan.h"

namespace fleetmap::experiments {

namespace {

localization::LocalizerContext context_for(const LogSlamOptions& o) {
  localization::LocalizerContext c;
  c.options = o.localizer;
  c.params = localization::localizer_options(o.method, o.localizer_settings);
  c.seed = o.seed;
  return c;  // the first scan at the origin; no known map, no landmarks
}

// The arc a differential drive follows from `from` to `to` in `dt`: the turn is the heading change,
// the length the chord's along the arc (a sideways slip odometry reports is left out).
localization::Odometry arc_between(const core::Pose2& from, const core::Pose2& to, double dt) {
  const core::Pose2 step = from.inverse().compose(to);
  const double turn = step.theta, chord = std::hypot(step.x, step.y);
  const double half = 0.5 * turn;
  const double length = std::abs(half) < 1e-9 ? chord : chord * half / std::sin(half);
  const double sign = step.x < 0.0 ? -1.0 : 1.0;
  return {sign * length / dt, turn / dt, dt};
}

// The scan with returns beyond `range` counted as no return there.
mapping::RangeScan cut(const mapping::RangeScan& scan, double range) {
  mapping::RangeScan out = scan;
  out.max_range = range > 0.0 && (scan.max_range <= 0.0 || range < scan.max_range) ? range : scan.max_range;
  for (auto& r : out.ranges) {
    if (r && *r >= out.max_range) r.reset();
  }
  return out;
}

// The map of the whole log at the final poses, each scan inserted once into one probability grid
// with the submaps' hit and miss odds (a grazing ray does not erase a wall), then given the states a
// map_server map holds: occupied when its hits outweigh its misses (above 0.5), free below 0.45
// (five scans more free than occupied), unknown between.
mapping::OccupancyGrid final_map(const std::function<std::unique_ptr<io::LaserLogReader>()>& open_log,
                                 const std::vector<core::Pose2>& trajectory, double reach, double resolution) {
  localization::SubmapGridOptions go;
  go.resolution_m = resolution;
  localization::SubmapGrid grid(go);
  auto log = open_log();
  std::size_t i = 0;
  std::vector<Eigen::Vector2d> hits;
  while (const auto s = log->next()) {
    if (i >= trajectory.size()) break;
    const core::Pose2& pose = trajectory[i++];
    hits.clear();
    for (std::size_t b = 0; b < s->scan.ranges.size(); ++b) {
      const auto& r = s->scan.ranges[b];
      if (!r || *r > reach) continue;
      hits.push_back(pose.transform(*r * Eigen::Vector2d(std::cos(s->scan.angles[b]), std::sin(s->scan.angles[b]))));
    }
    grid.insert(pose.position(), hits);
  }
  mapping::OccupancyGridOptions mo;
  mo.hit_probability = go.hit_probability;
  mo.miss_probability = go.miss_probability;
  mo.min_probability = go.min_probability;
  mo.max_probability = go.max_probability;
  mo.occupied_threshold = 0.5;
  mo.free_threshold = 0.45;
  const int w = std::max(grid.width(), 1), h = std::max(grid.height(), 1);
  mapping::OccupancyGrid map(core::GridGeometry(resolution, w, h, core::Pose2(grid.min_x() * resolution, grid.min_y() * resolution, 0.0)), mo);
  for (int y = 0; y < grid.height(); ++y) {
    for (int x = 0; x < grid.width(); ++x) {
      if (!grid.known(x + grid.min_x(), y + grid.min_y())) continue;
      const double p = grid.probability(x + grid.min_x(), y + grid.min_y());
      map.set_log_odds(core::Cell{x, y}, float(std::log(p / (1.0 - p))));
    }
  }
  return map;
}

}  // namespace

std::vector<std::string> log_slam_methods() {
  std::vector<std::string> names;
  for (const auto& name : localization::localizer_names()) {
    try {
      if (localization::make_localizer(name, context_for({}))->uses_scans()) names.push_back(name);
    } catch (const std::exception&) {
      // Needs what a log does not give (a known map, landmarks): not a method for logs.
    }
  }
  return names;
}

LogSlamResult run_log_slam(const std::function<std::unique_ptr<io::LaserLogReader>()>& open_log,
                           const LogSlamOptions& o,
                           const std::function<void(std::size_t, std::size_t)>& progress) {
  const auto methods = log_slam_methods();
  if (std::find(methods.begin(), methods.end(), o.method) == methods.end()) {
    throw InputError("method '" + o.method + "'" + core::did_you_mean(o.method, methods) +
                     ": not a method for a laser log (valid: " + core::join(methods) + ")");
  }
  if (!(o.resolution_m > 0.0) || !std::isfinite(o.resolution_m)) {
    throw InputError(fmt::format("resolution {}: expected metres per cell above 0", o.resolution_m));
  }
  // The map's extent: the odometry's, grown by the mapping range and by a quarter of the path's own
  // extent for the drift the method will correct.
  double lo_x = INFINITY, hi_x = -INFINITY, lo_y = INFINITY, hi_y = -INFINITY;
  double max_range = 0.0;
  std::size_t scans = 0;
  {
    auto log = open_log();
    std::optional<core::Pose2> first;
    while (const auto s = log->next()) {
      ++scans;
      if (!first) first = s->odometry;
      const core::Pose2 p = first->inverse().compose(s->odometry);
      lo_x = std::min(lo_x, p.x), hi_x = std::max(hi_x, p.x), lo_y = std::min(lo_y, p.y), hi_y = std::max(hi_y, p.y);
      max_range = std::max(max_range, s->scan.max_range);
    }
  }
  const double reach = std::min(o.mapping_range_m > 0.0 ? o.mapping_range_m : max_range, max_range > 0.0 ? max_range : o.mapping_range_m);
  const double drift = 0.25 * std::max(hi_x - lo_x, hi_y - lo_y);
  const double margin = reach + drift + 1.0;
  const int width = int(std::ceil((hi_x - lo_x + 2.0 * margin) / o.resolution_m));
  const int height = int(std::ceil((hi_y - lo_y + 2.0 * margin) / o.resolution_m));
  if (double(width) * double(height) > 4e8) {
    throw InputError(fmt::format("the log's map would be {} x {} cells at {} m: give a coarser --resolution", width, height,
                                 o.resolution_m));
  }
  LogSlamResult out;
  auto localizer = localization::make_localizer(o.method, context_for(o));
  const bool own_map = !localizer->ignores_own_map();
  // A method that keeps a map of its own is handed a grid of one cell, which it does not read.
  mapping::OccupancyGrid map(core::GridGeometry(o.resolution_m, own_map ? width : 1, own_map ? height : 1,
                                                core::Pose2(lo_x - margin, lo_y - margin, 0.0)),
                             o.map);
  auto log = open_log();
  std::optional<core::Pose2> first_odometry, previous_odometry;
  double previous_time = 0.0, period = 0.0;
  while (const auto s = log->next()) {
    if (!first_odometry) {
      first_odometry = s->odometry;
      out.format = log->format();
      out.max_range_m = log->max_range_m();
    } else {
      // A log whose time stands still or goes back (the Intel lab's, four times) took the scan
      // one scan period after the last all the same.
      const double dt = s->time_s > previous_time ? s->time_s - previous_time : (period > 0.0 ? period : 1.0);
      period = dt;
      localizer->predict(arc_between(*previous_odometry, s->odometry, dt));
    }
    const mapping::RangeScan scan = cut(s->scan, reach);
    localizer->update_scan(scan, map);
    const core::Pose2 pose = localizer->pose();
    if (own_map) mapping::insert_scan(map, pose, scan);
    out.trajectory.push_back(pose);
    out.odometry.push_back(first_odometry->inverse().compose(s->odometry));
    out.timestamps.push_back(s->timestamp);
    out.times_s.push_back(s->time_s);
    previous_odometry = s->odometry;
    previous_time = s->time_s;
    if (progress) progress(out.trajectory.size(), scans);
  }
  if (auto revised = localizer->finish_trajectory(); revised && revised->size() == out.trajectory.size()) {
    out.trajectory = std::move(*revised);
  }
  for (std::size_t i = 1; i < out.trajectory.size(); ++i) {
    out.distance_m += (out.trajectory[i].position() - out.trajectory[i - 1].position()).norm();
  }
  out.log_duration_s = out.times_s.empty() ? 0.0 : out.times_s.back() - out.times_s.front();
  out.counters = localizer->counters();
  // The method's state is not needed for the final map: its memory and the map's are not held at once.
  localizer.reset();
  map = mapping::OccupancyGrid();
  out.map = final_map(open_log, out.trajectory, reach, o.resolution_m);
  return out;
}

}  // namespace fleetmap::experiments
