#include "experiments/landmark_output.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/format.h"
#include "io/file_io.h"
#include "io/map_image.h"
#include "io/map_io.h"
#include "viz/drawing.h"
#include "viz/plot.h"

namespace fleetmap::experiments {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string num(double v, int decimals = 4) { return std::isnan(v) ? "—" : core::fixed(v, decimals); }

// The report a part measures: the last follower's at the last rendezvous.
const FollowerReport* main_report(const LandmarkCaseRun& r) { return r.reports.empty() ? nullptr : &r.reports.back(); }

// Means over runs of one method's outcome from one kind of map; a run where the method found no
// transform counts in `failed` and not in the means.
struct Summary {
  double dx = kNaN, dy = kNaN, theta = kNaN, translation = kNaN, rms_x = kNaN, rms_y = kNaN;
  double dx_pct = kNaN, dy_pct = kNaN, theta_pct = kNaN;  // of the true parameter, failures as 100%
  double translation_min = kNaN, translation_max = kNaN;
  int found = 0, runs = 0;
  double overlap = 0.0, shared = 0.0;  // means
};

double percent(double error, double truth) { return std::abs(truth) > 1e-9 ? std::min(100.0, 100.0 * error / std::abs(truth)) : kNaN; }

Summary summarize(const std::vector<LandmarkCaseRun>& runs, bool data_association, int kind) {
  Summary s;
  double dx = 0, dy = 0, th = 0, tr = 0, rx = 0, ry = 0, px = 0, py = 0, pt = 0;
  for (const auto& run : runs) {
    const FollowerReport* r = main_report(run);
    if (!r) continue;
    ++s.runs;
    s.overlap += r->overlap;
    s.shared += r->shared;
    const MethodOutcome& m = data_association ? r->data_association[kind] : r->observation[kind];
    if (!m.transform) {
      px += 100.0, py += 100.0, pt += 100.0;
      continue;
    }
    ++s.found;
    dx += m.error.dx, dy += m.error.dy, th += m.error.theta, tr += m.error.translation();
    rx += m.landmark_rms_x, ry += m.landmark_rms_y;
    px += percent(m.error.dx, r->truth.translation().x());
    py += percent(m.error.dy, r->truth.translation().y());
    pt += percent(m.error.theta, r->truth.rotation());
    s.translation_min = std::isnan(s.translation_min) ? m.error.translation() : std::min(s.translation_min, m.error.translation());
    s.translation_max = std::isnan(s.translation_max) ? m.error.translation() : std::max(s.translation_max, m.error.translation());
  }
  if (s.runs) s.overlap /= s.runs, s.shared /= s.runs;
  if (s.runs) s.dx_pct = px / s.runs, s.dy_pct = py / s.runs, s.theta_pct = pt / s.runs;
  if (s.found) {
    s.dx = dx / s.found, s.dy = dy / s.found, s.theta = th / s.found, s.translation = tr / s.found;
    s.rms_x = rx / s.found, s.rms_y = ry / s.found;
  }
  return s;
}

std::string found_text(const Summary& s) { return fmt::format("{}/{}", s.found, s.runs); }

std::string matrix_text(const core::Transform2& t, const std::string& indent) {
  const Eigen::Matrix3d m = t.matrix();
  std::string out;
  for (int r = 0; r < 3; ++r) {
    out += indent + fmt::format("{:>9.4f} {:>9.4f} {:>10.4f}\n", m(r, 0), m(r, 1), m(r, 2));
  }
  return out;
}

std::string table1(const LandmarkExperimentResult& r) {
  if (r.table1.empty()) return "";
  const Summary s = summarize(r.table1, false, 0);
  std::string out = fmt::format(
      "## Table I: error of the coordinate transformation (case {}, {} runs; overlap {:.1f} candidate matches, {:.1f} "
      "landmarks in both maps)\n\n",
      r.options.table1, s.runs, s.overlap, s.shared);
  out += "| method | map | dx (m) | dy (m) | theta (rad) | found | paper dx | paper dy | paper theta |\n";
  out += "|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
  const char* paper[4][3] = {{"4.7347", "5.6185", "0.1096"}, {"4.015", "4.9955", "0.1105"}, {"0.3309", "0.4887", "0"},
                             {"0.3938", "0.3386", "0"}};
  int row = 0;
  for (bool da : {false, true}) {
    for (int kind = 0; kind < 2; ++kind, ++row) {
      const Summary m = summarize(r.table1, da, kind);
      out += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", da ? "data association" : "inter-robot observations",
                         kind == 0 ? "maximum weight" : "combination (eq. 14-15)", num(m.dx), num(m.dy), num(m.theta),
                         found_text(m), paper[row][0], paper[row][1], paper[row][2]);
    }
  }
  return out + "\nErrors are means over the runs of |estimate - truth| of each parameter; data association's over the runs where it found a transform.\n\n";
}

std::string table2(const LandmarkExperimentResult& r) {
  if (r.little.empty() || r.large.empty()) return "";
  const Summary lo = summarize(r.little, true, 1), hi = summarize(r.large, true, 1);
  std::string out = fmt::format(
      "## Table II: error of the coordinate transformation, % of the true parameter (little overlap: case {}, {:.1f} "
      "candidate matches, {:.1f} landmarks in both maps; large overlap: case {}, {:.1f} and {:.1f})\n\n",
      r.options.little_overlap, lo.overlap, lo.shared, r.options.large_overlap, hi.overlap, hi.shared);
  out += "| method | overlap | dx % | dy % | theta % | found | paper dx % | paper dy % | paper theta % |\n";
  out += "|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
  const char* paper[4][3] = {{"100", "100", "100"}, {"7.303", "0.76", "0"}, {"0.953", "4.492", "0.39"}, {"7.58", "3.3403", "1.84"}};
  int row = 0;
  for (bool da : {true, false}) {
    for (const auto* runs : {&r.little, &r.large}) {
      const Summary m = summarize(*runs, da, 1);
      out += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", da ? "data association" : "inter-robot observations",
                         runs == &r.little ? "very little" : "large", num(m.dx_pct, 2), num(m.dy_pct, 2), num(m.theta_pct, 2),
                         found_text(m), paper[row][0], paper[row][1], paper[row][2]);
      ++row;
    }
  }
  return out + "\nPer run |error| / |true parameter| x 100 on the combined maps, capped at 100; a run without a transform counts as 100% (the paper's \"100%\" for data association on little overlap).\n\n";
}

std::string table3(const LandmarkExperimentResult& r) {
  if (r.small_overlap.empty() || r.large_overlap.empty()) return "";
  const Summary a = summarize(r.small_overlap, true, 1), b = summarize(r.large_overlap, true, 1);
  std::string out = fmt::format(
      "## Table III: the two methods with more overlapping landmarks (case {}: {:.1f} landmarks in both maps, {:.1f} "
      "candidate matches; case {}: {:.1f} and {:.1f})\n\n",
      r.options.overlap_small, a.shared, a.overlap, r.options.overlap_large, b.shared, b.overlap);
  out += "| method | error (m) | smaller overlap | paper (overlap 22) | larger overlap | paper (overlap 33) |\n";
  out += "|---|---|---:|---:|---:|---:|\n";
  const char* paper[2][4][2] = {{{"0.5635", "0.0202"}, {"0.1698", "0.0497"}, {"0.36515", "0.0500"}, {"0.15465", "0.0662"}},
                                {{"8.0398", "8.2956"}, {"0.97155", "0.8102"}, {"2.83225", "2.81375"}, {"1.74885", "1.50365"}}};
  int m_index = 0;
  for (bool da : {true, false}) {
    const Summary x = summarize(r.small_overlap, da, 1), y = summarize(r.large_overlap, da, 1);
    const double xs[4] = {x.dx, x.dy, x.rms_x, x.rms_y}, ys[4] = {y.dx, y.dy, y.rms_x, y.rms_y};
    const char* names[4] = {"dx", "dy", "landmark x rms", "landmark y rms"};
    for (int k = 0; k < 4; ++k) {
      out += fmt::format("| {} | {} | {} | {} | {} | {} |\n", da ? "data association" : "inter-robot observations", names[k],
                         num(xs[k]), paper[m_index][k][0], num(ys[k]), paper[m_index][k][1]);
    }
    ++m_index;
  }
  return out + "\nLandmark rms: the fused map (eq. (10)-(13)) against the true landmarks, in the leader's frame.\n\n";
}

std::string fig2(const LandmarkExperimentResult& r) {
  if (r.noise.empty()) return "";
  std::string out = fmt::format(
      "## Fig. 2: transform error against the observation noise (case {}, {} runs per level, bearing noise {:g} deg "
      "kept)\n\n",
      r.options.noise_case, r.options.runs, r.options.sensor.bearing_noise_rad * 180.0 / 3.141592653589793);
  out += "| range noise (m) | data association: translation (m) | theta (rad) | found | inter-robot: translation (m) | theta (rad) | candidate matches |\n";
  out += "|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const auto& level : r.noise) {
    const Summary da = summarize(level.runs, true, 1), io = summarize(level.runs, false, 1);
    out += fmt::format("| {:g} | {} | {} | {} | {} | {} | {:.1f} |\n", level.range_noise, num(da.translation), num(da.theta),
                       found_text(da), num(io.translation), num(io.theta), da.overlap);
  }
  return out + "\n";
}

std::string merges(const LandmarkExperimentResult& r) {
  if (r.merges.empty()) return "";
  std::string out = fmt::format("## Leader/follower merges (§VI, Fig. 3: data association from {} overlapping landmarks)\n\n",
                                r.options.alignment.overlap_threshold);
  for (const auto& run : r.merges) {
    out += fmt::format("### case {}\n\n```\n", run.case_name);
    for (const auto& rep : run.reports) {
      out += fmt::format("step {}: leader {} receives {}'s map\n", rep.step, rep.leader, rep.follower);
      out += fmt::format("no_overlap = {} (landmarks truly in both maps: {}), warning: \"{}\"\n", rep.overlap, rep.shared,
                         rep.choice.message);
      if (rep.choice.transform) {
        const TransformError e = transform_error(*rep.choice.transform, rep.truth);
        out += "T =\n" + matrix_text(*rep.choice.transform, "  ");
        out += fmt::format("true T: dx {:.4f}, dy {:.4f}, theta {:.4f} rad; error dx {:.4f} m, dy {:.4f} m, theta {:.4f} rad\n",
                           rep.truth.translation().x(), rep.truth.translation().y(), rep.truth.rotation(), e.dx, e.dy, e.theta);
      }
      out += fmt::format("global map: {} landmarks\n\n", rep.global_landmarks);
    }
    out += "```\n\n";
  }
  out += "The paper's: 2 robots, first rendezvous no_overlap = 2, inter-robot observations, T = [1 0.0013 39.0889; -0.0013 1 "
         "-39.4249]; second no_overlap = 13, data association. 4 robots: robot 2 no_overlap = 14, data association, "
         "T = [1 -0 -39.7589; 0 1 39.7943]; robot 3 no_overlap = 5, inter-robot observations, T = [0.1097 0.9940 41.6536; "
         "0.9940 -0.1097 36.8141] (as printed, not a rotation); robot 4 no_overlap = 19, data association, "
         "T = [1 -0 40.7603; 0 1 -40.4778].\n\n";
  return out;
}

// The leader's global map at the end of a merge case: true landmarks as grey rings, the true paths,
// each robot's landmarks in its colour and fused duplicates in black.
cv::Mat global_map_picture(const LandmarkCaseRun& run) {
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  const auto grow = [&](const Eigen::Vector2d& p) { lo = lo.cwiseMin(p), hi = hi.cwiseMax(p); };
  for (const auto& p : run.truth_in_leader) grow(p);
  for (const auto& path : run.truth_paths)
    for (const auto& p : path) grow(p.position());
  const double size = 760.0, margin = 20.0;
  const double scale = (size - 2 * margin) / std::max({hi.x() - lo.x(), hi.y() - lo.y(), 1.0});
  const auto px = [&](const Eigen::Vector2d& p) {
    return cv::Point2d(margin + (p.x() - lo.x()) * scale, size - margin - (p.y() - lo.y()) * scale);
  };
  viz::Drawing d(static_cast<int>(size), static_cast<int>(size) + 30);
  for (const auto& p : run.truth_in_leader) d.circle(px(p), 4.0, {170, 170, 170}, false, 1.0);
  for (std::size_t i = 0; i < run.truth_paths.size(); ++i) {
    std::vector<cv::Point2d> line;
    for (const auto& p : run.truth_paths[i]) line.push_back(px(p.position()));
    d.polyline(line, viz::palette_color(int(i)), 1.5, false, 0.6);
  }
  for (std::size_t k = 0; k < run.global.landmarks.size(); ++k) {
    const int s = run.global_source[k];
    d.circle(px(run.global.landmarks[k].position), s < 0 ? 3.5 : 2.5, s < 0 ? viz::Color{0, 0, 0} : viz::palette_color(s));
  }
  d.text({margin, size + 18}, "grey rings: true landmarks; dots: each robot's landmarks (leader first colour); black: fused duplicates",
         0.4);
  return viz::rasterize(d);
}

cv::Mat fig2_picture(const LandmarkExperimentResult& r) {
  viz::LinePlot plot;
  plot.title = "Fig. 2: transform error vs observation noise";
  plot.x.label = "log10 range noise (m)";
  plot.y.label = "translation error (m)";
  for (bool da : {true, false}) {
    viz::PlotSeries s;
    s.label = da ? "data association" : "inter-robot observations";
    s.color = viz::palette_color(da ? 0 : 1);
    s.markers = true;
    for (const auto& level : r.noise) {
      const Summary m = summarize(level.runs, da, 1);
      s.x.push_back(std::log10(std::max(level.range_noise, 1e-6)));
      s.y.push_back(m.translation);
      s.y_low.push_back(std::isnan(m.translation_min) ? kNaN : m.translation_min);
      s.y_high.push_back(std::isnan(m.translation_max) ? kNaN : m.translation_max);
    }
    plot.series.push_back(std::move(s));
  }
  return viz::draw_line_plot(plot);
}

}  // namespace

std::string landmark_report_markdown(const LandmarkExperimentResult& r) {
  return table1(r) + table2(r) + table3(r) + fig2(r) + merges(r);
}

std::string landmark_reports_csv(const LandmarkExperimentResult& r) {
  std::string out =
      "part,case,run,range_noise,step,leader,follower,overlap,shared,chosen,true_dx,true_dy,true_theta,"
      "da_max_dx,da_max_dy,da_max_theta,da_comb_dx,da_comb_dy,da_comb_theta,da_comb_rms_x,da_comb_rms_y,"
      "io_max_dx,io_max_dy,io_max_theta,io_comb_dx,io_comb_dy,io_comb_theta,io_comb_rms_x,io_comb_rms_y,"
      "leader_position_error,leader_odometry_error\n";
  const auto rows = [&](const std::string& part, const std::vector<LandmarkCaseRun>& runs) {
    for (const auto& run : runs) {
      for (const auto& rep : run.reports) {
        const auto e = [](const MethodOutcome& m, double v) { return m.transform ? core::fixed(v, 5) : std::string(); };
        const auto& d0 = rep.data_association[0];
        const auto& d1 = rep.data_association[1];
        const auto& o0 = rep.observation[0];
        const auto& o1 = rep.observation[1];
        out += fmt::format("{},{},{},{:g},{},{},{},{},{},{},{:.5f},{:.5f},{:.5f},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:.5f},{:.5f}\n",
                           part, run.case_name, run.run, run.range_noise, rep.step, rep.leader, rep.follower, rep.overlap,
                           rep.shared, merging::to_string(rep.choice.method), rep.truth.translation().x(),
                           rep.truth.translation().y(), rep.truth.rotation(), e(d0, d0.error.dx), e(d0, d0.error.dy),
                           e(d0, d0.error.theta), e(d1, d1.error.dx), e(d1, d1.error.dy), e(d1, d1.error.theta),
                           e(d1, d1.landmark_rms_x), e(d1, d1.landmark_rms_y), e(o0, o0.error.dx), e(o0, o0.error.dy),
                           e(o0, o0.error.theta), e(o1, o1.error.dx), e(o1, o1.error.dy), e(o1, o1.error.theta),
                           e(o1, o1.landmark_rms_x), e(o1, o1.landmark_rms_y), run.final_position_error[0],
                           run.odometry_position_error[0]);
      }
    }
  };
  rows("table1", r.table1);
  rows("little_overlap", r.little);
  rows("large_overlap", r.large);
  rows("overlap_small", r.small_overlap);
  rows("overlap_large", r.large_overlap);
  for (const auto& level : r.noise) rows("noise", level.runs);
  rows("merge", r.merges);
  return out;
}

std::string landmark_noise_csv(const LandmarkExperimentResult& r) {
  std::string out = "range_noise,da_translation,da_theta,da_found,io_translation,io_theta,runs\n";
  for (const auto& level : r.noise) {
    const Summary da = summarize(level.runs, true, 1), io = summarize(level.runs, false, 1);
    out += fmt::format("{:g},{},{},{},{},{},{}\n", level.range_noise, num(da.translation, 5), num(da.theta, 5), da.found,
                       num(io.translation, 5), num(io.theta, 5), da.runs);
  }
  return out;
}

std::vector<std::string> landmark_output_files(const LandmarkExperimentOptions& o) {
  std::vector<std::string> names = {"alignment_tables.md", "rendezvous.csv"};
  if (!o.noise_case.empty()) names.insert(names.end(), {"fig2_noise.csv", "fig2_noise.png"});
  for (const auto& m : o.merges) names.push_back("global_map_" + m + ".png");
  return names;
}

std::vector<std::filesystem::path> write_landmark_outputs(const LandmarkExperimentResult& r, const std::filesystem::path& dir) {
  io::ensure_directory(dir);
  std::vector<std::filesystem::path> written;
  const auto text = [&](const std::string& name, const std::string& bytes) {
    io::write_file_atomic(dir / name, bytes);
    written.push_back(dir / name);
  };
  const auto image = [&](const std::string& name, const cv::Mat& picture) {
    io::write_image(dir / name, picture);
    written.push_back(dir / name);
  };
  text("alignment_tables.md", "# The map-alignment paper's experiments, measured\n\n" + landmark_report_markdown(r));
  text("rendezvous.csv", landmark_reports_csv(r));
  if (!r.noise.empty()) {
    text("fig2_noise.csv", landmark_noise_csv(r));
    image("fig2_noise.png", fig2_picture(r));
  }
  for (const auto& run : r.merges) image("global_map_" + run.case_name + ".png", global_map_picture(run));
  return written;
}

}  // namespace fleetmap::experiments
