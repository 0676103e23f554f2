#include "cli/slam_log_command.h"

#include <fmt/format.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "cli/progress.h"
#include "core/error.h"
#include "core/format.h"
#include "experiments/log_slam.h"
#include "io/file_io.h"
#include "io/laser_log.h"
#include "io/map_image.h"
#include "io/map_io.h"
#include "localization/relation_metric.h"
#include "viz/render.h"

namespace fleetmap::cli {

namespace fs = std::filesystem;

namespace {

double cpu_seconds() { return double(std::clock()) / double(CLOCKS_PER_SEC); }

double peak_memory_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) / 1024.0;  // kilobytes on Linux
}

// "mit-csail.clf.gz" -> "mit-csail".
std::string log_name(const fs::path& log) {
  fs::path p = log.filename();
  if (p.extension() == ".gz") p = p.stem();
  if (p.extension() == ".clf" || p.extension() == ".log") p = p.stem();
  return p.string();
}

const char* kOutputs[] = {"map.yaml", "map.pgm", "map.png", "trajectory.txt", "metrics.json"};

std::string trajectory_text(const experiments::LogSlamResult& r) {
  std::string out;
  for (std::size_t i = 0; i < r.trajectory.size(); ++i) {
    const core::Pose2& p = r.trajectory[i];
    out += fmt::format("{} {:.6f} {:.6f} {:.6f}\n", r.timestamps[i], p.x, p.y, p.theta);
  }
  return out;
}

cv::Mat map_picture(const experiments::LogSlamResult& r, const std::string& method, const std::string& title) {
  viz::Overlays o;
  viz::PathOverlay path;
  for (const auto& p : r.trajectory) path.points.push_back(p.position());
  path.color = viz::palette_color(0);
  path.label = method + " trajectory";
  o.paths.push_back(std::move(path));
  if (!r.trajectory.empty()) {
    o.poses.push_back({r.trajectory.front(), 0.3, viz::palette_color(0), "start", true});
    o.poses.push_back({r.trajectory.back(), 0.3, viz::palette_color(0), "end", false});
  }
  viz::RenderOptions ro;
  ro.title = title;
  ro.crop_margin_m = 1.0;
  return viz::render_map(r.map, o, ro);
}

}  // namespace

std::string slam_log_method_names() { return core::join(experiments::log_slam_methods()); }

std::string slam_log_help() {
  return "With --log, runs one SLAM method over a real robot's laser log (CARMEN FLASER / RAWLASER1 / ROBOTLASER1\n"
         "with ODOM, plain or gzip; DP-SLAM's Odometry / Laser) and writes to --out: map.yaml + map.pgm (map_server),\n"
         "map.png (the map with the trajectory, scale bar and metre axes), trajectory.txt (one line per scan:\n"
         "`timestamp x y theta`, the scan's timestamp as the log writes it, the laser's pose in metres and radians,\n"
         "the first scan at the origin) and metrics.json (scans, distance travelled, wall and CPU time, real-time\n"
         "factor = log duration / CPU time, peak memory, the method's counters). --relations FILE (lines\n"
         "`t1 t2 x y z roll pitch yaw`, Kuemmerle et al. 2009) adds the mean and standard deviation of the\n"
         "translational and absolute rotational errors over the relations. Same log, method and seed: the same\n"
         "files, byte for byte, but for metrics.json's times and memory.\n"
         "Methods (--method): " + slam_log_method_names() + "\n"
         "Example: fleetmap slam --log mit-csail.clf.gz --relations mit-csail.relations.txt --out out/csail";
}

int run_slam_log(const SlamLogFlags& f) {
  const fs::path log(f.log);
  const fs::path out = f.out.empty() ? fs::path("out") / ("slam_" + log_name(log)) : fs::path(f.out);
  core::Settings settings;
  for (const auto& text : f.set) {
    const auto a = core::parse_param_assignment(text, "--set " + text);
    if (a.family != "localization") {
      throw InputError("--set " + text + ": slam --log takes localization.KEY=VALUE, not " + a.family + "." + a.key);
    }
    settings.emplace_back(a.key, a.value);
  }
  const core::Params params = localization::localizer_options(f.method, settings);  // refused before anything is written
  std::vector<fs::path> inputs{log};
  if (!f.relations.empty()) inputs.emplace_back(f.relations);
  io::OutputFolder folder(out, "slam", std::vector<std::string>(std::begin(kOutputs), std::end(kOutputs)), inputs,
                          "--out " + out.string());
  std::vector<io::Relation> relations;
  if (!f.relations.empty()) relations = io::read_relations(f.relations);

  experiments::LogSlamOptions o;
  o.method = f.method;
  o.localizer_settings = settings;
  if (f.seed) o.seed = *f.seed;
  const auto wall0 = std::chrono::steady_clock::now();
  const double cpu0 = cpu_seconds();
  ProgressBar bar(!f.quiet);
  const experiments::LogSlamResult r = experiments::run_log_slam(
      [&] { return std::make_unique<io::LaserLogReader>(log); }, o,
      [&](std::size_t done, std::size_t total) {
        if (done % 16 == 0 || done == total) bar.update(long(done), long(total), "scans");
      });
  bar.finish();
  const double cpu_s = cpu_seconds() - cpu0;
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();

  nlohmann::ordered_json m;
  m["log"] = log.filename().string();
  m["format"] = r.format;
  m["method"] = o.method;
  for (const auto& spec : params.specs()) m["parameters"][spec.name] = params.value_text(spec.name);
  m["seed"] = o.seed;
  m["scans"] = r.trajectory.size();
  m["log_duration_s"] = r.log_duration_s;
  m["distance_m"] = r.distance_m;
  m["max_range_m"] = r.max_range_m;
  m["wall_time_s"] = wall_s;
  m["cpu_time_s"] = cpu_s;
  m["real_time_factor"] = cpu_s > 0.0 ? r.log_duration_s / cpu_s : 0.0;
  m["peak_memory_mb"] = peak_memory_mb();
  for (const auto& [name, value] : r.counters) m["counters"][name] = value;

  std::string relation_line;
  if (!f.relations.empty()) {
    std::vector<localization::TimedPose> trajectory;
    for (std::size_t i = 0; i < r.trajectory.size(); ++i) trajectory.push_back({r.times_s[i], r.trajectory[i]});
    // Logs' times need not rise (the Intel lab's go back four times): relation_errors wants them sorted.
    std::stable_sort(trajectory.begin(), trajectory.end(), [](const auto& a, const auto& b) { return a.time_s < b.time_s; });
    std::vector<localization::ReferenceRelation> reference;
    for (const auto& rel : relations) reference.push_back({rel.t1, rel.t2, rel.t1_tolerance, rel.t2_tolerance, rel.motion});
    const auto e = localization::relation_errors(trajectory, reference);
    for (std::size_t i = 0; i < relations.size(); ++i) {
      if (!e.matched_each[i]) {
        const auto& rel = relations[i];
        throw InputError(fmt::format("{}:{}: relation {} -> {} names a time that matches no scan of {}", f.relations, rel.line,
                                     rel.t1_text, rel.t2_text, log.string()));
      }
    }
    constexpr double kDeg = 180.0 / std::numbers::pi;
    auto& j = m["relations"];
    j["file"] = fs::path(f.relations).filename().string();
    j["given"] = e.relations;
    j["matched"] = e.matched;
    j["translation_mean_m"] = e.translation_mean_m;
    j["translation_std_m"] = e.translation_std_m;
    j["rotation_mean_rad"] = e.rotation_mean_rad;
    j["rotation_std_rad"] = e.rotation_std_rad;
    j["rotation_mean_deg"] = e.rotation_mean_rad * kDeg;
    j["rotation_std_deg"] = e.rotation_std_rad * kDeg;
    relation_line = fmt::format("relations: {} of {} matched; translation {:.4f} ± {:.4f} m, rotation {:.3f} ± {:.3f} deg\n",
                                e.matched, e.relations, e.translation_mean_m, e.translation_std_m, e.rotation_mean_rad * kDeg,
                                e.rotation_std_rad * kDeg);
  }

  folder.claim();
  io::save_map_yaml(r.map, out / "map.yaml");
  io::write_image(out / "map.png", map_picture(r, o.method, fmt::format("{}: {}", log.filename().string(), o.method)));
  io::write_file_atomic(out / "trajectory.txt", trajectory_text(r));
  io::write_file_atomic(out / "metrics.json", m.dump(2) + "\n");
  folder.finish(std::vector<std::string>(std::begin(kOutputs), std::end(kOutputs)));

  if (f.quiet) {
    fmt::print("{}\n", (out / "metrics.json").string());
    return 0;
  }
  fmt::print("{} ({}, {} scans, {:.1f} s of log): {}, {:.1f} m travelled\n", log.filename().string(), r.format,
             r.trajectory.size(), r.log_duration_s, o.method, r.distance_m);
  fmt::print("time: {:.2f} s CPU ({:.1f} x real time), {:.2f} s wall; peak memory {:.0f} MB\n", cpu_s,
             cpu_s > 0.0 ? r.log_duration_s / cpu_s : 0.0, wall_s, peak_memory_mb());
  fmt::print("{}", relation_line);
  std::string names;
  for (const char* n : kOutputs) names += std::string(" ") + n;
  fmt::print("all outputs in {}/:{}\n", out.string(), names);
  return 0;
}

}  // namespace fleetmap::cli
