#include "experiments/corridor_output.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/format.h"
#include "io/file_io.h"
#include "io/map_image.h"
#include "io/map_io.h"
#include "viz/render.h"

namespace fleetmap::experiments {

namespace {

std::string num(double v, int decimals) {
  return core::fixed(v, decimals);
}

// The runs of the first seed with this lap count, one per method in the options' order.
std::vector<const CorridorRun*> runs_with_laps(const CorridorResult& r, int laps) {
  std::vector<const CorridorRun*> out;
  for (const auto& run : r.runs)
    if (run.laps == laps && run.seed == r.options.seed) out.push_back(&run);
  return out;
}

// One cell of Table I: the value of one seed, or the mean and sample standard deviation over the
// seeds of this method and lap count.
std::string cell(const CorridorResult& r, const CorridorRun& first, double (*value)(const CorridorRun&), double scale,
                 int decimals, const std::string& unit) {
  std::vector<double> v;
  for (const auto& run : r.runs)
    if (run.method == first.method && run.laps == first.laps) v.push_back(scale * value(run));
  if (v.size() < 2) return num(scale * value(first), decimals) + unit;
  double mean = 0.0, spread = 0.0;
  for (double x : v) mean += x / double(v.size());
  for (double x : v) spread += (x - mean) * (x - mean) / double(v.size() - 1);
  return num(mean, decimals) + unit + " ± " + num(std::sqrt(spread), decimals) + unit;
}

// The true walls' faces: wall cells with a free 4-neighbour inside the loop, in `geometry`'s cells.
std::vector<core::Cell> wall_faces(const mapping::OccupancyGrid& truth, const core::GridGeometry& geometry,
                                   const core::Transform2& truth_to_geometry = {}) {
  std::vector<core::Cell> out;
  const auto& g = truth.geometry();
  for (int y = 1; y + 1 < g.height(); ++y) {
    for (int x = 1; x + 1 < g.width(); ++x) {
      if (truth.state({x, y}) != mapping::CellState::Occupied) continue;
      bool face = false;
      for (const core::Cell n : {core::Cell{x + 1, y}, core::Cell{x - 1, y}, core::Cell{x, y + 1}, core::Cell{x, y - 1}}) {
        face = face || truth.state(n) == mapping::CellState::Free;
      }
      if (!face) continue;
      const auto c = geometry.world_to_cell(truth_to_geometry.apply(g.cell_center({x, y})));
      if (c) out.push_back(*c);
    }
  }
  return out;
}

std::vector<Eigen::Vector2d> positions(const std::vector<core::Pose2>& poses) {
  std::vector<Eigen::Vector2d> out;
  for (const auto& p : poses) out.push_back(p.position());
  return out;
}

std::string laps_text(int laps) { return std::to_string(laps) + (laps == 1 ? " lap" : " laps"); }

std::string error_name(double deg) {
  std::string s = num(deg, 1);
  for (char& c : s)
    if (c == '.') c = 'p';
  return s;
}

}  // namespace

std::string corridor_table_markdown(const CorridorResult& r) {
  std::ostringstream md;
  for (int laps : r.options.laps) {
    const auto runs = runs_with_laps(r, laps);
    md << "**" << laps_text(laps) << "** ";
    if (r.options.seeds > 1) {
      md << "(seeds " << r.options.seed << "-" << r.options.seed + std::uint64_t(r.options.seeds - 1)
         << ": mean ± standard deviation)";
    } else {
      md << "(seed " << r.options.seed << ")";
    }
    md << "\n\n| | Real |";
    for (const auto* run : runs) md << " " << run->method << " |";
    md << "\n|---|---|";
    for (std::size_t i = 0; i < runs.size(); ++i) md << "---|";
    const auto row = [&](double (*value)(const CorridorRun&), double scale, int decimals, const std::string& unit) {
      for (const auto* run : runs) md << " " << cell(r, *run, value, scale, decimals, unit) << " |";
    };
    md << "\n| Length (m) | " << num(r.real.length_m, 1) << " |";
    row([](const CorridorRun& c) { return c.dimensions.length_m; }, 1.0, 2, "");
    md << "\n| Error length | |";
    row([](const CorridorRun& c) { return c.length_error; }, 100.0, 1, "%");
    md << "\n| Height (m) | " << num(r.real.height_m, 1) << " |";
    row([](const CorridorRun& c) { return c.dimensions.height_m; }, 1.0, 2, "");
    md << "\n| Error height | |";
    row([](const CorridorRun& c) { return c.height_error; }, 100.0, 1, "%");
    md << "\n| Final position error (m) | |";
    row([](const CorridorRun& c) { return c.final_position_error_m; }, 1.0, 2, "");
    md << "\n\n";
  }
  return md.str();
}

std::string corridor_table_csv(const CorridorResult& r) {
  std::ostringstream csv;
  csv << "method,seed,laps,real_length_m,real_height_m,length_m,height_m,length_error_pct,height_error_pct,"
         "final_position_error_m,seconds\n";
  for (const auto& run : r.runs) {
    csv << run.method << "," << run.seed << "," << run.laps << "," << num(r.real.length_m, 3) << "," << num(r.real.height_m, 3) << ","
        << num(run.dimensions.length_m, 3) << "," << num(run.dimensions.height_m, 3) << ","
        << num(100.0 * run.length_error, 2) << "," << num(100.0 * run.height_error, 2) << ","
        << num(run.final_position_error_m, 3) << "," << num(run.seconds, 3) << "\n";
  }
  return csv.str();
}

std::string detection_merge_markdown(const CorridorResult& r) {
  std::ostringstream md;
  md << "| Orientation error in the detection (deg) | Rotation error of the merge (deg) | Other's start misplaced by (m) "
        "| Other's walls: mean distance to a true wall (m) | Other's wall cells > 0.3 m off |\n|---|---|---|---|---|\n";
  for (const auto& m : r.merges) {
    md << "| " << num(m.orientation_error_deg, 1) << " | " << num(m.rotation_error_deg, 2) << " | "
       << num(m.far_end_error_m, 2) << " | " << num(m.mean_wall_distance_m, 3) << " | "
       << num(100.0 * m.misplaced_wall_share, 1) << "% |\n";
  }
  return md.str();
}

std::string detection_merge_csv(const CorridorResult& r) {
  std::ostringstream csv;
  csv << "orientation_error_deg,rotation_error_deg,far_end_error_m,mean_wall_distance_m,misplaced_wall_share\n";
  for (const auto& m : r.merges) {
    csv << num(m.orientation_error_deg, 3) << "," << num(m.rotation_error_deg, 3) << "," << num(m.far_end_error_m, 3)
        << "," << num(m.mean_wall_distance_m, 4) << "," << num(m.misplaced_wall_share, 4) << "\n";
  }
  return csv.str();
}

nlohmann::json corridor_json(const CorridorResult& r) {
  nlohmann::json j;
  j["experiment"] = "leon_corridor";
  j["seed"] = r.options.seed;
  j["real"] = {{"length_m", r.real.length_m}, {"height_m", r.real.height_m}};
  j["runs"] = nlohmann::json::array();
  for (const auto& run : r.runs) {
    j["runs"].push_back({{"method", run.method},
                         {"seed", run.seed},
                         {"laps", run.laps},
                         {"found", run.dimensions.found},
                         {"length_m", run.dimensions.length_m},
                         {"height_m", run.dimensions.height_m},
                         {"length_error", run.length_error},
                         {"height_error", run.height_error},
                         {"final_position_error_m", run.final_position_error_m},
                         {"seconds", run.seconds}});
  }
  j["merge_by_detection"] = nlohmann::json::array();
  for (const auto& m : r.merges) {
    j["merge_by_detection"].push_back({{"orientation_error_deg", m.orientation_error_deg},
                                       {"rotation_error_deg", m.rotation_error_deg},
                                       {"far_end_error_m", m.far_end_error_m},
                                       {"mean_wall_distance_m", m.mean_wall_distance_m},
                                       {"misplaced_wall_share", m.misplaced_wall_share}});
  }
  return j;
}

std::vector<std::string> corridor_output_files(const CorridorOptions& o) {
  std::vector<std::string> names = {"corridor_table.md", "corridor_table.csv", "corridor.json"};
  for (const auto& method : o.methods) {
    for (int laps : o.laps) names.push_back("corridor_" + method + "_" + std::to_string(laps) + "lap.png");
  }
  if (!o.detection_errors_deg.empty()) {
    names.push_back("merge_detection.md");
    names.push_back("merge_detection.csv");
    for (double e : o.detection_errors_deg) names.push_back("merge_detection_" + error_name(e) + "deg.png");
  }
  return names;
}

std::vector<std::filesystem::path> write_corridor_outputs(const CorridorResult& r, const std::filesystem::path& dir) {
  io::ensure_directory(dir);
  std::vector<std::filesystem::path> written;
  const auto text = [&](const std::string& name, const std::string& bytes) {
    io::write_file_atomic(dir / name, bytes);
    written.push_back(dir / name);
  };
  text("corridor_table.md", "# León et al., Table I: dimensional error of the corridor loop\n\n" + corridor_table_markdown(r));
  text("corridor_table.csv", corridor_table_csv(r));
  text("corridor.json", corridor_json(r).dump(2) + "\n");
  const viz::Color red{220, 40, 40}, green{40, 160, 60}, blue{40, 90, 220};
  for (const auto& run : r.runs) {
    if (run.seed != r.options.seed) continue;  // pictures of the first seed
    viz::Overlays o;
    o.cells.push_back({wall_faces(r.truth, run.map.geometry()), red, "true walls", 0.55});
    o.paths.push_back({positions(run.truth), green, "true path", 1, false});
    o.paths.push_back({positions(run.estimate), blue, "estimated path", 1, true});
    viz::RenderOptions ro;
    ro.crop_margin_m = 1.0;
    ro.title = run.method + ", " + laps_text(run.laps) + ": length " + num(run.dimensions.length_m, 2) + " m, height " +
               num(run.dimensions.height_m, 2) + " m";
    const auto path = dir / ("corridor_" + run.method + "_" + std::to_string(run.laps) + "lap.png");
    io::write_image(path, viz::render_map(run.map, o, ro));
    written.push_back(path);
  }
  if (!r.merges.empty()) {
    text("merge_detection.md", detection_merge_markdown(r));
    text("merge_detection.csv", detection_merge_csv(r));
    for (const auto& m : r.merges) {
      viz::Overlays o;
      o.cells.push_back({wall_faces(r.truth, m.merged.geometry()), red, "true walls", 0.55});
      o.paths.push_back({positions(r.master_path), green, "master (true path)", 1, false});
      o.paths.push_back({positions(r.other_path), blue, "other (true path)", 1, false});
      o.poses.push_back({r.meeting_master, 0.3, green, "master at the meeting"});
      o.poses.push_back({r.meeting_other, 0.3, blue, "other at the meeting"});
      viz::RenderOptions ro;
      ro.title = "merge by detection, orientation error " + num(m.orientation_error_deg, 1) + " deg";
      ro.crop_margin_m = 1.0;
      const auto path = dir / ("merge_detection_" + error_name(m.orientation_error_deg) + "deg.png");
      io::write_image(path, viz::render_map(m.merged, o, ro));
      written.push_back(path);
    }
  }
  return written;
}

}  // namespace fleetmap::experiments
