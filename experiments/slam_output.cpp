#include "experiments/slam_output.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <sstream>

#include <fmt/format.h>
#include "io/file_io.h"
#include "io/map_image.h"
#include "localization/metrics.h"
#include "io/map_io.h"
#include "viz/render.h"

namespace fleetmap::experiments {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Metric {
  std::string key;
  std::string label;
  const char* format;
  std::function<double(const SlamRobotResult&)> value;
};

const std::vector<Metric>& metrics() {
  static const std::vector<Metric> kMetrics = {
      {"mu", "mu_j (D'Alfonso et al.'s form: e^T P e)", "{:.3g}", [](const SlamRobotResult& r) { return r.localization.dalfonso_mu; }},
      {"nees", "NEES, standard (e^T P^-1 e; 3 when consistent)", "{:.3g}",
       [](const SlamRobotResult& r) { return r.localization.average_nees.value_or(kNaN); }},
      {"nu_m", "nu_j, m (D'Alfonso et al.'s form: per polynomial the sum of its distances, mean over polynomials)", "{:.3g}",
       [](const SlamRobotResult& r) { return r.mapping.nu; }},
      {"mean_distance_m", "mean distance of the map to the true walls, m", "{:.3g}",
       [](const SlamRobotResult& r) { return r.mapping.mean_distance; }},
      {"position_rmse_m", "position RMSE, m", "{:.3g}", [](const SlamRobotResult& r) { return r.localization.position_rmse; }},
      {"dead_reckoning_rmse_m", "position RMSE of dead reckoning on the same runs, m", "{:.3g}",
       [](const SlamRobotResult& r) { return r.dead_reckoning_rmse; }},
      {"walls_mapped_pct", "true walls within 0.1 m of the map, %", "{:.3g}",
       [](const SlamRobotResult& r) { return 100.0 * r.boundary_coverage; }},
      {"polynomials", "polynomials in the map", "{:.3g}", [](const SlamRobotResult& r) { return double(r.polynomials); }},
      {"tau_ms", "tau_j, ms per step", "{:.3g}", [](const SlamRobotResult& r) { return 1e3 * r.tau_s; }},
      {"diverged_steps", "steps with P(k|k-1) > K P0 (diverging)", "{:.3g}",
       [](const SlamRobotResult& r) {
         for (const auto& [k, v] : r.counters) {
           if (k == "diverged_steps") return v;
         }
         return kNaN;
       }},
  };
  return kMetrics;
}

// D'Alfonso et al. Table 1, by robot order (r1, r2, r3).
const std::map<std::string, std::vector<std::string>>& paper_values() {
  static const std::map<std::string, std::vector<std::string>> kPaper = {
      {"mu", {"1.66e-06", "4.66e-07", "1.02e-06"}},
      {"nu_m", {"0.17", "0.19", "0.34"}},
      {"tau_ms", {"610 (Matlab, i7 Q720)", "660", "620"}},
  };
  return kPaper;
}

std::string fmt(const char* format, double v) {
  if (std::isnan(v)) return "n/a";
  return fmt::format(fmt::runtime(format), v);
}

// The values of one metric for robot `name` over the runs.
std::vector<double> values(const std::vector<SlamRunResult>& runs, const std::string& name, const Metric& m) {
  std::vector<double> out;
  for (const auto& run : runs) {
    for (const auto& r : run.robots) {
      if (r.name != name) continue;
      const double v = m.value(r);
      if (!std::isnan(v)) out.push_back(v);
    }
  }
  return out;
}

struct Column {
  std::string name;   // robot
  std::string title;  // column header
  const std::vector<SlamRunResult>* runs;
  std::string mode;   // "team" or "alone"
};

std::vector<Column> columns(const SlamSetup& setup, const SlamCampaign& c) {
  std::vector<Column> out;
  for (const auto& r : setup.scenario.robots) {
    out.push_back({r.name, r.name, &c.team, setup.scenario.exchange ? "team" : "team, no exchange"});
  }
  if (!setup.scenario.single_robot.empty() && !c.alone.empty()) {
    out.push_back({setup.scenario.single_robot, setup.scenario.single_robot + " alone", &c.alone, "alone"});
  }
  return out;
}

std::string csv_text(std::string s) {
  if (s.find_first_of(",\"") == std::string::npos) return s;
  std::string q = "\"";
  for (char ch : s) {
    if (ch == '"') q += '"';
    q += ch;
  }
  return q + "\"";
}

}  // namespace

MeanStd mean_std(const std::vector<double>& v) {
  MeanStd out;
  out.count = int(v.size());
  if (v.empty()) return out;
  double sum = 0.0;
  for (double x : v) sum += x;
  out.mean = sum / double(v.size());
  if (v.size() < 2) return out;
  double sq = 0.0;
  for (double x : v) sq += (x - out.mean) * (x - out.mean);
  out.std = std::sqrt(sq / double(v.size() - 1));
  return out;
}

namespace {

// Text inside a Markdown table cell: a '|' would end the cell.
std::string markdown_cell(const std::string& text) {
  std::string out;
  for (char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

}  // namespace

std::string slam_table_markdown(const SlamSetup& setup, const SlamCampaign& c, bool paper_columns) {
  const auto cols = columns(setup, c);
  std::ostringstream md;
  md << "# Table 1: " << setup.scenario.method << " SLAM, mean ± standard deviation over " << c.team.size()
     << " runs\n\n";
  md << "| index |";
  for (const auto& col : cols) md << " " << col.title << " |";
  md << "\n|---|";
  for (std::size_t i = 0; i < cols.size(); ++i) md << "---|";
  md << "\n";
  for (const auto& m : metrics()) {
    md << "| " << markdown_cell(m.label) << " |";
    for (const auto& col : cols) {
      const MeanStd s = mean_std(values(*col.runs, col.name, m));
      md << " " << (s.count ? fmt(m.format, s.mean) + " ± " + fmt(m.format, s.std) : std::string("n/a")) << " |";
    }
    md << "\n";
    const auto paper = paper_values().find(m.key);
    if (paper_columns && paper != paper_values().end()) {
      md << "| " << m.key << ", D'Alfonso et al. Table 1 |";
      for (std::size_t i = 0; i < cols.size(); ++i) {
        md << " " << (cols[i].mode != "alone" && i < paper->second.size() ? paper->second[i] : std::string()) << " |";
      }
      md << "\n";
    }
  }
  // Consistency: the mean of N runs' NEES against its 95% chi-square band.
  md << "\n## Consistency\n\n"
     << "A consistent filter's NEES is chi2(3) at every step. Each run's NEES above is its mean over "
     << setup.scenario.steps + 1 << " steps; these are strongly correlated in time, so a run's mean is taken as one "
     << "chi2(3) value (the widest band) and the mean of N runs must lie in chi2(3N)/N's 95% band "
     << "(Bar-Shalom et al. 2001); with independent steps the band would be chi2(3N(k_f+1))/(N(k_f+1))'s, narrower.\n\n";
  for (const auto& col : cols) {
    std::vector<double> v;
    for (const auto& run : *col.runs) {
      for (const auto& r : run.robots) {
        if (r.name == col.name && r.localization.average_nees) v.push_back(*r.localization.average_nees);
      }
    }
    if (v.empty()) continue;
    const double mean = mean_std(v).mean;
    const auto band = localization::average_chi_square_band(3, long(v.size()));
    const auto narrow = localization::average_chi_square_band(3, long(v.size()) * (setup.scenario.steps + 1));
    md << fmt::format("- {}: mean NEES {:.3g} over {} runs, {} the band [{:.3g}, {:.3g}] (independent steps: [{:.3g}, {:.3g}])\n",
                      col.title, mean, v.size(), band.contains(mean) ? "inside" : (mean > band.upper ? "above" : "below"),
                      band.lower, band.upper, narrow.lower, narrow.upper);
  }
  // Bytes per rendezvous message, polynomials against the equivalent grid patch.
  std::vector<double> per_run, polys, bytes, grid;
  for (const auto& run : c.team) {
    per_run.push_back(double(run.rendezvous.size()));
    for (const auto& r : run.rendezvous) {
      polys.push_back(r.polynomials);
      bytes.push_back(double(r.bytes));
      grid.push_back(double(r.grid_bytes));
    }
  }
  md << "\n## Rendezvous\n\n";
  if (bytes.empty()) {
    md << "No rendezvous" << (setup.scenario.exchange ? "" : " (exchange disabled)") << ".\n";
  } else {
    const MeanStd b = mean_std(bytes), g = mean_std(grid), p = mean_std(polys), n = mean_std(per_run);
    md << fmt::format(
        "{:.2f} messages per run (one each way per meeting); per message {:.1f} polynomials, {:.0f} ± {:.0f} bytes; "
        "the equivalent occupancy-grid patch (bounding box, {:.2f} m cells, 1 byte each) {:.0f} ± {:.0f} bytes, "
        "{:.1f} times as many.\n",
        n.mean, p.mean, b.mean, b.std, setup.scenario.grid_patch_resolution_m, g.mean, g.std,
        b.mean > 0.0 ? g.mean / b.mean : 0.0);
  }
  return md.str();
}

std::string slam_table_csv(const SlamSetup& setup, const SlamCampaign& c) {
  std::ostringstream csv;
  csv << "metric,robot,mode,mean,std,runs\n";
  for (const auto& m : metrics()) {
    for (const auto& col : columns(setup, c)) {
      const MeanStd s = mean_std(values(*col.runs, col.name, m));
      csv << m.key << "," << csv_text(col.name) << "," << csv_text(col.mode) << ","
          << fmt::format("{:.9g},{:.9g},{}", s.mean, s.std, s.count) << "\n";
    }
  }
  return csv.str();
}

std::string slam_runs_csv(const SlamCampaign& c) {
  std::ostringstream csv;
  csv << "run,robot,mode";
  for (const auto& m : metrics()) csv << "," << m.key;
  csv << ",nees_steps";
  // The method's counters, by the names of the first robot's.
  std::vector<std::string> counter_names;
  if (!c.team.empty() && !c.team.front().robots.empty()) {
    for (const auto& [name, value] : c.team.front().robots.front().counters) counter_names.push_back(name);
  }
  for (const auto& name : counter_names) csv << "," << name;
  csv << "\n";
  for (const auto* runs : {&c.team, &c.alone}) {
    for (const auto& run : *runs) {
      for (const auto& r : run.robots) {
        csv << run.run << "," << csv_text(r.name) << "," << (runs == &c.alone ? "alone" : run.exchange ? "team" : "team, no exchange");
        for (const auto& m : metrics()) {
          csv << fmt::format(",{:.9g}", m.value(r));
        }
        csv << "," << r.localization.nees_steps;
        for (const auto& name : counter_names) {
          double v = kNaN;
          for (const auto& [key, value] : r.counters) {
            if (key == name) v = value;
          }
          csv << fmt::format(",{:.9g}", v);
        }
        csv << "\n";
      }
    }
  }
  return csv.str();
}

std::string slam_rendezvous_csv(const SlamCampaign& c) {
  std::ostringstream csv;
  csv << "run,step,sender,receiver,polynomials,bytes,grid_patch_bytes\n";
  for (const auto& run : c.team) {
    for (const auto& r : run.rendezvous) {
      csv << run.run << "," << r.step << "," << r.sender << "," << r.receiver << "," << r.polynomials << "," << r.bytes
          << "," << r.grid_bytes << "\n";
    }
  }
  return csv.str();
}

cv::Mat render_slam_robot(const SlamSetup& setup, const SlamRunResult& run, int robot, const std::string& title) {
  SlamRoom picture = setup.scenario.room;
  picture.resolution_m = 0.02;  // a picture's resolution; the walls are drawn as lines on top
  const mapping::OccupancyGrid room = rasterize_room(picture, 0.3);
  const SlamRobotResult& r = run.robots[std::size_t(robot)];
  const viz::Color green{44, 160, 44}, red{214, 39, 40}, blue{31, 119, 180}, purple{148, 103, 189};
  viz::Overlays o;
  const auto closed = [](std::vector<Eigen::Vector2d> polygon) {
    polygon.push_back(polygon.front());
    return polygon;
  };
  o.paths.push_back({closed(setup.scenario.room.boundary), red, "true walls", 2, false});
  for (const auto& obstacle : setup.scenario.room.obstacles) o.paths.push_back({closed(obstacle), red, "", 2, false});
  for (std::size_t i = 0; i < r.map_curves.size(); ++i) {
    o.paths.push_back({r.map_curves[i], green, i == 0 ? "mapped polynomials" : "", 3, false});
  }
  std::vector<Eigen::Vector2d> truth, estimate;
  for (const auto& p : r.truth) truth.push_back(p.position());
  for (const auto& p : r.estimate) estimate.push_back(p.position());
  o.paths.push_back({truth, blue, "true path", 2, false});
  o.paths.push_back({estimate, red, "estimated path", 2, true});
  // Where this robot met another (the robot's true position at the step).
  std::vector<Eigen::Vector2d> meetings;
  int scenario_index = -1;
  for (std::size_t i = 0; i < setup.scenario.robots.size(); ++i) {
    if (setup.scenario.robots[i].name == r.name) scenario_index = int(i);
  }
  for (const auto& m : run.rendezvous) {
    if (m.receiver == scenario_index && m.step < int(r.truth.size())) meetings.push_back(r.truth[std::size_t(m.step)].position());
  }
  if (!meetings.empty()) o.points.push_back({meetings, purple, "rendezvous (received a map)", 6});
  if (!r.truth.empty()) o.poses.push_back({r.truth.back(), setup.scenario.robot.radius_m, blue, ""});
  viz::RenderOptions options;
  options.title = title;
  options.target_size_px = 1000;
  return viz::render_map(room, o, options);
}

std::vector<std::string> slam_output_files(const SlamScenario& s) {
  std::vector<std::string> names = {"table1.md", "table1.csv", "runs.csv", "rendezvous.csv"};
  for (const auto& r : s.robots) names.push_back("map_" + r.name + ".png");
  if (!s.single_robot.empty()) names.push_back("map_" + s.single_robot + "_alone.png");
  return names;
}

std::vector<std::filesystem::path> write_slam_outputs(const SlamSetup& setup, const SlamCampaign& c,
                                                      const std::filesystem::path& dir, bool paper_columns) {
  io::ensure_directory(dir);
  std::vector<std::filesystem::path> written;
  const auto text = [&](const std::string& name, const std::string& content) {
    io::write_file_atomic(dir / name, content);
    written.push_back(dir / name);
  };
  text("table1.md", slam_table_markdown(setup, c, paper_columns));
  text("table1.csv", slam_table_csv(setup, c));
  text("runs.csv", slam_runs_csv(c));
  text("rendezvous.csv", slam_rendezvous_csv(c));
  if (!c.team.empty()) {
    const SlamRunResult& first = c.team.front();
    for (std::size_t i = 0; i < first.robots.size(); ++i) {
      const std::string name = "map_" + first.robots[i].name + ".png";
      const std::string title = first.robots[i].name + ": " + setup.scenario.method + " SLAM" +
                                (setup.scenario.exchange ? " with map exchange" : "") + ", run " +
                                std::to_string(first.run + 1);
      io::write_image(dir / name, render_slam_robot(setup, first, int(i), title));
      written.push_back(dir / name);
    }
  }
  if (!c.alone.empty() && !c.alone.front().robots.empty()) {
    const SlamRunResult& first = c.alone.front();
    const std::string name = "map_" + first.robots[0].name + "_alone.png";
    io::write_image(dir / name, render_slam_robot(setup, first, 0,
                                                       first.robots[0].name + " alone: single-robot " +
                                                           setup.scenario.method + " SLAM, run " + std::to_string(first.run + 1)));
    written.push_back(dir / name);
  }
  return written;
}

}  // namespace fleetmap::experiments
