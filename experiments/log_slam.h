#pragma once
// SLAM on a real robot's laser log: one of fleetmap's localizers that map (scan matching, the
// Rao-Blackwellized particle filter, grid FastSLAM) run over every scan of the log in order, as
// León et al. compare them on real data, and the trajectory and map they make.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/transform2.h"
#include "io/laser_log.h"
#include "localization/localizer.h"
#include "mapping/occupancy_grid.h"

namespace fleetmap::experiments {

struct LogSlamOptions {
  std::string method = "scan-matching";  // a registered localizer that maps (log_slam_methods())
  double resolution_m = 0.05;            // of the map
  // Beams are used up to this range (a longer return counts as no return beyond it): far returns
  // cost time and add little to an indoor map. Cartographer's 2D default.
  double mapping_range_m = 30.0;
  std::uint64_t seed = 1;
  // The method's own parameters (localization::localizer_options), as given.
  core::Settings localizer_settings;
  io::LaserLogOptions log;
  // The grid the method maps into (the methods that keep their own start from it). A miss moves a
  // cell's odds by about a fifth of a hit's, as Cartographer's 0.49 against 0.55: a real scan's
  // end points scatter over a cell or two around a wall (range noise, the pose's error, grazing
  // beams), so the beams of later scans cross a wall's cells about as often as they end in them,
  // and misses as strong as hits (the simulator's 0.30 against 0.75) erase it.
  mapping::OccupancyGridOptions map = [] {
    mapping::OccupancyGridOptions m;
    m.miss_probability = 0.45;
    return m;
  }();
  // Particles and noise. A real robot's odometry over the motion between two scans is far less
  // sure than the simulator's default: 5 cm and 0.05 rad (3 degrees) per step, the scale of
  // GMapping's defaults for scans a few tens of centimetres apart.
  localization::LocalizerOptions localizer = [] {
    localization::LocalizerOptions o;
    o.process_noise_xy = 0.05;
    o.process_noise_theta = 0.05;
    // MIT CSAIL's odometry (training log): heading errors of 1.4 degrees rms on steps turning under
    // 2 degrees, 3 on steps of 5-20, 11 on steps of 20-90 (up to 19): about 0.3 of the turn.
    o.turn_noise_per_rad = 0.3;
    // Intel's odometry (training log): 0.075 m rms off GMapping's motion on its steps of about 1 m.
    o.drive_noise_per_m = 0.075;
    return o;
  }();
};

// The localizers a log can be run with: the registered ones that build a map of their own.
std::vector<std::string> log_slam_methods();

struct LogSlamResult {
  std::string format;                    // the log's ("CARMEN", "DP-SLAM")
  std::vector<std::string> timestamps;   // per scan, as the log writes it
  std::vector<double> times_s;
  std::vector<core::Pose2> trajectory;   // per scan, the laser's estimated pose; the first at the origin
  std::vector<core::Pose2> odometry;     // per scan, the raw odometry in the same frame (for comparison)
  mapping::OccupancyGrid map;            // the method's map, in the trajectory's frame
  double distance_m = 0.0;               // along the estimated trajectory
  double log_duration_s = 0.0;           // last scan's time - first's (0 for logs without times)
  double max_range_m = 0.0;              // what the reader took as "no return"
  std::vector<std::pair<std::string, double>> counters;  // the localizer's
};

// Reads the log (three streaming passes: the maximum range, the odometry's extent for the map, and
// the scans) and runs the method scan by scan: the odometry between two scans drives its
// prediction (as an arc; a sideways slip odometry reports is lost), the scan its update.
// `progress(scans_done, scans_in_log)` after each scan. Throws InputError for a bad log or method.
LogSlamResult run_log_slam(const std::function<std::unique_ptr<io::LaserLogReader>()>& open_log,
                           const LogSlamOptions& options,
                           const std::function<void(std::size_t done, std::size_t total)>& progress = {});

}  // namespace fleetmap::experiments
