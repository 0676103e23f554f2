#include "sim/run_output.h"

#include <opencv2/imgproc.hpp>

#include <dlfcn.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>

#include <fmt/format.h>
#include "core/angle.h"
#include "core/error.h"
#include "io/file_io.h"
#include "localization/metrics.h"
#include "io/map_image.h"
#include "io/map_io.h"
#include "io/octomap_io.h"
#include "sim/run_metrics.h"
#include "sim/video_module.h"
#include "viz/render.h"

namespace fleetmap::sim {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

json optional_int(const std::optional<int>& v) { return v ? json(*v) : json(nullptr); }
// JSON has no infinity: an unlimited range is written as the string "inf".
json range_value(double v) { return std::isinf(v) ? json("inf") : json(v); }

std::string title(const RunResult& r, const std::string& map_label) {
  return fmt::format("{}: {} robot{}, {}", map_label, r.scenario.robot_count, r.scenario.robot_count == 1 ? "" : "s",
                     r.scenario.exploration.strategy);
}

std::vector<Eigen::Vector2d> positions(const std::vector<core::Pose2>& poses) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(poses.size());
  for (const auto& p : poses) out.push_back(p.position());
  return out;
}

// Pictures of maps hold the known cells plus a metre around them.
viz::RenderOptions render_options(const std::string& t) {
  viz::RenderOptions o;
  o.title = t;
  o.crop_margin_m = 1.0;
  return o;
}

const viz::Color kLegendGrey{90, 90, 90};

// Legend rows for the marks every robot shares.
void add_pose_legend(viz::Overlays& o) {
  o.legend.push_back({viz::LegendItem::Ring, kLegendGrey, "start"});
  o.legend.push_back({viz::LegendItem::Disc, kLegendGrey, "final pose"});
}

}  // namespace

namespace {

json map_quality_json(const mapping::MapQuality& q) {
  return {{"known_cells", q.known_cells},
          {"wrong_cell_share", q.wrong_cell_share},
          {"wall_cells", q.wall_cells},
          {"mean_wall_distance_m", q.mean_wall_distance_m},
          {"misplaced_wall_share", q.misplaced_wall_share}};
}

// One entry per robot: start, distance, blocked moves, localization quality, localizer counters.
json per_robot_json(const RunResult& r, const RunTotals& totals) {
  json per_robot = json::array();
  for (std::size_t i = 0; i < r.robots.size(); ++i) {
    const auto& t = r.robots[i];
    const auto& loc = totals.per_robot[i];
    json robot = {{"robot", i + 1},
                  {"start", {t.truth.front().x, t.truth.front().y, core::rad2deg(t.truth.front().theta)}},
                  {"distance_m", t.distance_m},
                  {"blocked_moves", t.blocked_moves},
                  {"blocked_share", t.truth.size() > 1 ? double(t.blocked_moves) / double(t.truth.size() - 1) : 0.0},
                  {"contacts_marked", t.contacts_marked},
                  {"position_rmse_m", loc.position_rmse},
                  {"heading_rmse_deg", core::rad2deg(loc.heading_rmse)},
                  // Standard NEES (e^T P^-1 e) averaged over the steps with a positive-definite P,
                  // with its two-sided 95% chi-square band; D'Alfonso et al.'s mu (e^T P e) beside it.
                  {"nees", loc.average_nees ? json(*loc.average_nees) : json(nullptr)},
                  {"nees_steps", loc.nees_steps},
                  {"nees_band_95", {loc.nees_band.lower, loc.nees_band.upper}},
                  {"nees_inside_band", loc.nees_inside_band},
                  {"dalfonso_mu", loc.dalfonso_mu}};
    if (i < r.robot_map_quality.size()) robot["map_quality"] = map_quality_json(r.robot_map_quality[i]);
    for (const auto& [name, value] : t.localizer_counters) robot["localizer"][name] = value;
    per_robot.push_back(robot);
  }
  return per_robot;
}

// Every attempt to bring a teammate's map into a robot's frame.
json merges_json(const RunResult& r) {
  json merges = json::array();
  for (const auto& m : r.merges) {
    json e = {{"step", m.step}, {"receiver", m.receiver + 1}, {"sender", m.sender + 1}, {"method", m.method},
              {"merged", m.merged}, {"confidence", m.confidence}};
    if (m.merged) {
      e["rotation_error_deg"] = m.rotation_error_deg;
      e["position_error_m"] = m.position_error_m;
    } else {
      e["reason"] = m.reason;
    }
    merges.push_back(e);
  }
  return merges;
}

json exploration_json(const RunResult& r) {
  return {{"assignment_rounds", r.exploration.assignment_rounds},
          {"waves", r.exploration.waves},
          {"targets_reached", r.exploration.targets_reached},
          {"targets_given_up", r.exploration.targets_given_up},
          {"given_up_stalled", r.exploration.given_up_stalled},
          {"given_up_unreachable", r.exploration.given_up_unreachable},
          {"unobservable_frontiers", r.exploration.unobservable},
          {"frontiers_abandoned", r.exploration.frontiers_abandoned},
          {"paths_replanned", r.exploration.paths_replanned},
          {"detours", r.exploration.detours},
          {"yields", r.exploration.yields},
          {"path_planner", r.scenario.path_planner},
          {"planner_paths", r.exploration.provider_paths},
          {"planner_fallbacks", r.exploration.provider_fallbacks}};
}

// The observable space left unobserved: its area, and its largest regions with the reason each was left.
json unexplored_json(const RunResult& r) {
  constexpr std::size_t kListed = 10;
  double area = 0.0;
  json largest = json::array();
  for (const auto& u : r.unexplored) {
    area += u.area_m2;
    if (largest.size() < kListed)
      largest.push_back({{"area_m2", u.area_m2}, {"centre", {u.centre_m.x(), u.centre_m.y()}}, {"reason", u.reason}});
  }
  return {{"m2", area}, {"regions", r.unexplored.size()}, {"largest", std::move(largest)}};
}

json timing_json(const RunResult& r) {
  const auto& tm = r.timing;
  return {{"total_s", tm.total},           {"motion_s", tm.motion},
          {"sensing_s", tm.sensing},       {"localization_s", tm.localization},
          {"mapping_s", tm.mapping},       {"communication_s", tm.communication},
          {"exploration_s", tm.exploration}, {"metrics_s", tm.metrics},
          {"per_step_ms", r.steps > 0 ? 1000.0 * tm.total / r.steps : 0.0}};
}

}  // namespace

json metrics_json(const RunResult& r, const std::string& map_label) {
  const Scenario& s = r.scenario;
  json j;
  j["map"] = map_label;
  j["robots"] = s.robot_count;
  j["strategy"] = s.exploration.strategy;
  j["localization"] = s.localization;
  j["merging"] = s.merging;
  j["communication_range_m"] = range_value(s.communication.range_m);
  j["seed"] = s.seed;
  j["step_limit"] = s.steps;
  j["period_s"] = s.period_s;
  j["steps"] = r.steps;
  j["finished"] = r.finished;
  j["coverage"] = r.coverage.empty() ? 0.0 : r.coverage.back();
  j["steps_to_95"] = optional_int(r.steps_to_95);
  j["steps_to_99"] = optional_int(r.steps_to_99);
  const RunTotals totals = run_totals(r);
  j["distance_m"] = totals.distance_m;
  j["position_rmse_m"] = totals.position_rmse_m;
  j["blocked_moves"] = totals.blocked_moves;
  j["blocked_share"] = r.steps > 0 && !r.robots.empty() ? double(totals.blocked_moves) / (double(r.steps) * double(r.robots.size())) : 0.0;
  j["redundancy"] = r.redundancy;
  j["bytes_sent"] = r.bytes_sent;
  j["meetings"] = r.meetings;
  const auto& sp = r.space;
  j["space"] = {{"observable_cells", sp.observable_cells},
                {"observable_m2", double(sp.observable_cells) * sp.cell_area_m2},
                {"free_m2", double(sp.free_cells) * sp.cell_area_m2},
                {"pose_cells", sp.pose_cells},
                {"unreachable_observable_m2", double(sp.unreachable_cells) * sp.cell_area_m2},
                {"seen_unreachable_m2", double(sp.seen_unreachable.size()) * sp.cell_area_m2},
                {"largest_region_pose_cells", sp.largest_region_pose_cells},
                {"start_regions", sp.start_regions},
                {"observable_share_of_free", sp.free_cells > 0 ? double(sp.observable_cells) / double(sp.free_cells) : 0.0}};
  if (const std::string warning = reachable_space_warning(r); !warning.empty()) j["space"]["warning"] = warning;
  j["unexplored"] = unexplored_json(r);
  j["landmarks"] = r.landmarks.size();
  j["map_quality"] = map_quality_json(r.map_quality);
  j["per_robot"] = per_robot_json(r, totals);
  j["merges"] = merges_json(r);
  j["merges_made"] = totals.merges_made;
  j["merges_refused"] = totals.merges_refused;
  std::map<std::string, int> event_counts;
  for (const auto& e : r.events) ++event_counts[e.kind];
  j["events"] = event_counts;
  j["exploration"] = exploration_json(r);
  j["coverage_curve"] = r.coverage;
  j["timing"] = timing_json(r);
  return j;
}

cv::Mat render_merged(const RunResult& r, const std::string& map_label, const viz::Overlays& extra) {
  viz::Overlays o;
  const bool show_estimates = r.scenario.localization != "ideal";
  for (std::size_t i = 0; i < r.robots.size(); ++i) {
    const auto colour = viz::palette_color(int(i));
    const auto& t = r.robots[i];
    const std::string name = "robot " + std::to_string(i + 1);
    o.paths.push_back({positions(t.truth), colour, name + (show_estimates ? " (true)" : ""), 2, false});
    if (show_estimates) o.paths.push_back({positions(t.estimate), colour, name + " (estimate)", 1, true});
    o.poses.push_back({t.truth.front(), r.scenario.robot.radius_m, colour, "", true});
    o.poses.push_back({t.truth.back(), r.scenario.robot.radius_m, colour, ""});
  }
  add_pose_legend(o);
  if (!r.landmarks.empty()) o.points.push_back({r.landmarks, {200, 0, 200}, "landmarks", 3});
  if (!r.space.seen_unreachable.empty()) {
    // Seen, counted in the coverage, but beyond where a robot fits (through a gap, in a corner).
    viz::CellsOverlay seen{{}, {255, 160, 40}, "seen, not reachable", 0.45};
    for (int idx : r.space.seen_unreachable) seen.cells.push_back(r.merged.geometry().cell_of_index(idx));
    o.cells.push_back(std::move(seen));
  }
  o.cells.insert(o.cells.end(), extra.cells.begin(), extra.cells.end());
  o.paths.insert(o.paths.end(), extra.paths.begin(), extra.paths.end());
  o.points.insert(o.points.end(), extra.points.begin(), extra.points.end());
  o.poses.insert(o.poses.end(), extra.poses.begin(), extra.poses.end());
  o.legend.insert(o.legend.end(), extra.legend.begin(), extra.legend.end());
  const std::string numbers = fmt::format(", {} steps, {:.1f}%", r.steps, 100.0 * (r.coverage.empty() ? 0.0 : r.coverage.back()));
  return viz::render_map(r.merged, o, render_options(title(r, map_label) + numbers));
}

cv::Mat render_robot(const RunResult& r, int robot, const std::string& map_label) {
  const auto& t = r.robots[std::size_t(robot)];
  const auto colour = viz::palette_color(robot);
  // The robot's map is in its own frame; its estimates were recorded in the world's.
  const core::Transform2 to_frame = r.robot_frames[std::size_t(robot)].inverse();
  std::vector<Eigen::Vector2d> trajectory;
  for (const auto& p : t.estimate) trajectory.push_back(to_frame.apply(p.position()));
  const core::Pose2 first = core::Pose2::from_transform(to_frame * t.estimate.front().as_transform());
  const core::Pose2 last = core::Pose2::from_transform(to_frame * t.estimate.back().as_transform());
  viz::Overlays o;
  o.paths.push_back({trajectory, colour, "trajectory (estimate)", 2, false});
  o.poses.push_back({first, r.scenario.robot.radius_m, colour, "start", true});
  o.poses.push_back({last, r.scenario.robot.radius_m, colour, "robot " + std::to_string(robot + 1) + " at the end"});
  return viz::render_map(r.robot_maps[std::size_t(robot)], o,
                             render_options(map_label + ": robot " + std::to_string(robot + 1) + "'s map"));
}

std::vector<std::string> run_output_files(const Scenario& scenario) {
  std::vector<std::string> names = {"merged.png"};
  const int robots = scenario.placement == Placement::List ? int(scenario.starts.size()) : scenario.robot_count;
  for (int i = 1; i <= robots; ++i) {
    for (const char* ext : {".png", ".pgm", ".yaml"}) names.push_back("robot_" + std::to_string(i) + ext);
  }
  for (const char* n : {"metrics.json", "map.pgm", "map.yaml", "map.bt", "scenario.yaml"}) names.push_back(n);
  if (scenario.html_replay) names.push_back("replay.html");
  return names;
}

std::vector<fs::path> write_run_outputs(const RunResult& r, const std::string& map_label, const fs::path& dir) {
  return write_run_outputs(r, map_label, dir, viz::Overlays{});
}

std::vector<fs::path> write_run_outputs(const RunResult& r, const std::string& map_label, const fs::path& dir,
                                        const viz::Overlays& extra) {
  io::ensure_directory(dir);
  std::vector<fs::path> written;
  const auto add = [&](const fs::path& p) { written.push_back(p); };
  io::write_image(dir / "merged.png", render_merged(r, map_label, extra));
  add(dir / "merged.png");
  for (std::size_t i = 0; i < r.robot_maps.size(); ++i) {
    const fs::path p = dir / ("robot_" + std::to_string(i + 1) + ".png");
    io::write_image(p, render_robot(r, int(i), map_label));
    add(p);
    // The robot's own map as map_server files, in its own frame: what `fleetmap merge` takes.
    const fs::path yaml = dir / ("robot_" + std::to_string(i + 1) + ".yaml");
    io::save_map_yaml(r.robot_maps[i], yaml);
    for (const auto& f : io::map_output_files(yaml)) add(f);
  }
  io::write_file_atomic(dir / "metrics.json", metrics_json_text(r, map_label));
  add(dir / "metrics.json");
  io::save_map_yaml(r.merged, dir / "map.yaml");
  add(dir / "map.pgm");
  add(dir / "map.yaml");
  io::save_octomap(r.merged, dir / "map.bt");
  add(dir / "map.bt");
  io::write_file_atomic(dir / "scenario.yaml", scenario_to_yaml(r.scenario, dir));
  add(dir / "scenario.yaml");
  return written;
}

namespace {

struct VideoCodec {
  const char* name;
  char fourcc[4];
};

// Codecs per extension, the preferred first.
const std::vector<VideoCodec>& codecs_for(const std::string& extension) {
  static const std::vector<VideoCodec> kMp4 = {{"H.264", {'a', 'v', 'c', '1'}}, {"MPEG-4 Part 2", {'m', 'p', '4', 'v'}}};
  static const std::vector<VideoCodec> kWebm = {{"VP9", {'V', 'P', '9', '0'}}, {"VP8", {'V', 'P', '8', '0'}}};
  static const std::vector<VideoCodec> kNone;
  return extension == ".mp4" ? kMp4 : extension == ".webm" ? kWebm : kNone;
}

struct VideoModule {
  fleetmap_video_open_fn open = nullptr;
  fleetmap_video_write_fn write = nullptr;
  fleetmap_video_close_fn close = nullptr;
};

// Where the video module is looked for, in order: $FLEETMAP_VIDEO_MODULE; beside the running
// program and in its ../lib/fleetmap (an installed fleetmap, whatever its prefix); where the build
// wrote it; where `cmake --install` puts it under the configured prefix.
std::vector<fs::path> video_module_candidates() {
  std::vector<fs::path> out;
  if (const char* env = std::getenv("FLEETMAP_VIDEO_MODULE"); env && *env) out.emplace_back(env);
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    out.push_back(exe.parent_path() / FLEETMAP_VIDEO_MODULE_NAME);
    out.push_back(exe.parent_path().parent_path() / "lib" / "fleetmap" / FLEETMAP_VIDEO_MODULE_NAME);
  }
  out.emplace_back(FLEETMAP_VIDEO_MODULE_BUILD);
  out.emplace_back(FLEETMAP_VIDEO_MODULE_INSTALL);
  return out;
}

// The module, loaded on first use (a RunVideo being made).
const VideoModule& video_module() {
  static const VideoModule module = [] {
    std::string tried;
    const auto note = [&](const fs::path& path, const std::string& why) {
      tried += (tried.empty() ? "" : ", ") + path.string() + (why.empty() ? "" : " (" + why + ")");
    };
    for (const auto& path : video_module_candidates()) {
      std::error_code ec;
      if (!fs::is_regular_file(path, ec)) {
        note(path, "");
        continue;
      }
      void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!handle) {
        const char* why = dlerror();
        note(path, why ? why : "cannot load");
        continue;
      }
      VideoModule m;
      m.open = reinterpret_cast<fleetmap_video_open_fn>(dlsym(handle, "fleetmap_video_open"));
      m.write = reinterpret_cast<fleetmap_video_write_fn>(dlsym(handle, "fleetmap_video_write"));
      m.close = reinterpret_cast<fleetmap_video_close_fn>(dlsym(handle, "fleetmap_video_close"));
      if (m.open && m.write && m.close) return m;  // stays loaded for the program's life
      dlclose(handle);
      note(path, "not fleetmap's video module");
    }
    throw Error(std::string("cannot write a video: fleetmap's video module ") + FLEETMAP_VIDEO_MODULE_NAME +
                " was not found (looked at " + tried + "); set FLEETMAP_VIDEO_MODULE to its path");
  }();
  return module;
}

}  // namespace

const std::vector<std::string>& video_extensions() {
  static const std::vector<std::string> kExtensions = {".mp4", ".webm"};
  return kExtensions;
}

struct RunVideo::Impl {
  fs::path path, tmp;
  double fps = 12.0;
  const VideoModule* module = nullptr;
  void* writer = nullptr;  // the module's, open from the first frame until finish()
  cv::Size size;
  int frames = 0;
  std::string codec, note;
};

RunVideo::RunVideo(fs::path path, double fps) : impl_(std::make_unique<Impl>()) {
  if (codecs_for(path.extension().string()).empty()) {
    throw InputError(path.string() + ": a video is .mp4 (H.264) or .webm (VP9), not '" + path.extension().string() + "'");
  }
  impl_->path = std::move(path);
  impl_->tmp = impl_->path;
  impl_->tmp.replace_extension(".partial" + impl_->path.extension().string());
  impl_->fps = fps;
  impl_->module = &video_module();  // before the run: a missing module is said at once
}

RunVideo::~RunVideo() {
  if (impl_ && impl_->writer) {
    impl_->module->close(impl_->writer);
    std::error_code ec;
    fs::remove(impl_->tmp, ec);
  }
}

const std::string& RunVideo::codec() const { return impl_->codec; }
const std::string& RunVideo::fallback_note() const { return impl_->note; }

void RunVideo::add_frame(const Simulation& sim, const std::string& map_label) {
  viz::Overlays o;
  for (int i = 0; i < sim.scenario().robot_count; ++i) {
    const auto colour = viz::palette_color(i);
    const auto& truth = sim.track(i).truth;
    o.paths.push_back({positions(truth), colour, "robot " + std::to_string(i + 1), 2, false});
    // The plan is in the robot's own map frame; the picture is in the world's.
    auto plan = sim.path(i);
    for (auto& p : plan) p = sim.frame_origin(i).apply(p);
    if (!plan.empty() && !sim.track(i).estimate.empty()) {
      plan.insert(plan.begin(), sim.track(i).estimate.back().position());
      o.paths.push_back({plan, colour, "", 1, true});
    }
    if (!truth.empty()) o.poses.push_back({truth.front(), sim.scenario().robot.radius_m, colour, "", true});
    o.poses.push_back({sim.true_poses()[std::size_t(i)], sim.scenario().robot.radius_m, colour, ""});
  }
  // Every frame has the same legend rows, so frames keep one size.
  o.legend.push_back({viz::LegendItem::Dashed, kLegendGrey, "planned path"});
  o.legend.push_back({viz::LegendItem::Ring, kLegendGrey, "start"});
  o.legend.push_back({viz::LegendItem::Disc, kLegendGrey, "robot now"});
  viz::RenderOptions ro;
  ro.title = fmt::format("{}: step {}, {:.1f}%", map_label, sim.step_count(), 100.0 * sim.coverage());
  ro.max_size_px = 1600;
  cv::Mat frame = viz::render_map(sim.merged_map(), o, ro);
  if (!impl_->writer) {
    // Even dimensions keep every codec happy; a little room for longer titles later.
    impl_->size = cv::Size(frame.cols + 40 + (frame.cols % 2), frame.rows + (frame.rows % 2));
    io::ensure_directory(impl_->path.parent_path());
    const auto& codecs = codecs_for(impl_->path.extension().string());
    for (const auto& c : codecs) {
      impl_->writer = impl_->module->open(impl_->tmp.c_str(), c.fourcc, impl_->fps, impl_->size.width, impl_->size.height);
      if (impl_->writer) {
        impl_->codec = c.name;
        break;
      }
      impl_->note += fmt::format("{}OpenCV's FFmpeg cannot write {} ({:.4s})", impl_->note.empty() ? "" : "; ", c.name, std::string_view(c.fourcc, 4));
    }
    if (!impl_->writer) {
      throw Error(impl_->path.string() + ": cannot open a video writer: " + impl_->note);
    }
    if (!impl_->note.empty()) impl_->note += "; wrote " + impl_->codec;
  }
  // A frame larger than the first (a longer title) is shrunk to fit, never cut.
  if (frame.cols > impl_->size.width || frame.rows > impl_->size.height) {
    const double f = std::min(double(impl_->size.width) / frame.cols, double(impl_->size.height) / frame.rows);
    cv::resize(frame, frame, {}, f, f, cv::INTER_AREA);
  }
  cv::Mat padded(impl_->size, CV_8UC3, cv::Scalar(255, 255, 255));
  frame.copyTo(padded(cv::Rect(0, 0, std::min(frame.cols, impl_->size.width), std::min(frame.rows, impl_->size.height))));
  if (impl_->module->write(impl_->writer, padded.data, padded.step, padded.cols, padded.rows) != 0) {
    throw Error(impl_->path.string() + ": cannot write a frame");
  }
  ++impl_->frames;
}

void RunVideo::finish() {
  if (!impl_->writer || impl_->frames == 0) throw Error(impl_->path.string() + ": no frames to write");
  impl_->module->close(impl_->writer);
  impl_->writer = nullptr;
  std::error_code ec;
  fs::rename(impl_->tmp, impl_->path, ec);
  if (ec) throw Error(impl_->path.string() + ": cannot move the video into place (" + ec.message() + ")");
}

}  // namespace fleetmap::sim
