// Same seeds, same experiment outputs, release after release: D'Alfonso et al.'s polynomial SLAM
// (a shortened run of scenarios/dalfonso_3robots.yaml, with and without the exchange, and r3 alone),
// León et al.'s corridor comparison (a small loop) and the map-alignment paper's landmark maps
// (FastSLAM 2.0, Montemerlo et al. 2003; small cases) must give exactly the numbers kept in
// tests/data/golden/experiments/ (every number at full precision, grids by a checksum of their
// log-odds; timings apart). A change that moves code must leave them alone; a change that means to
// change behaviour regenerates them (FLEETMAP_UPDATE_GOLDEN=1 ctest -R KeptOutputs) and says so.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

#include <fmt/format.h>

#include "experiments/corridor_experiment.h"
#include "experiments/landmark_experiment.h"
#include "experiments/slam_experiment.h"
#include "io/file_io.h"
#include "tests/cli_run.h"

namespace fleetmap::experiments {
namespace {

namespace fs = std::filesystem;

std::string number(double v) { return fmt::format("{:.17g}", v); }

std::string pose_text(const core::Pose2& p) { return number(p.x) + " " + number(p.y) + " " + number(p.theta); }

// FNV-1a over the cells' log-odds bits, and the cells in each state.
std::string grid_text(const mapping::OccupancyGrid& g) {
  std::uint64_t h = 1469598103934665603ull;
  int occupied = 0, free = 0;
  for (int i = 0; i < g.geometry().cell_count(); ++i) {
    const float l = g.log_odds_at(i);
    std::uint32_t bits = 0;
    std::memcpy(&bits, &l, sizeof bits);
    for (int b = 0; b < 4; ++b) h = (h ^ ((bits >> (8 * b)) & 0xffu)) * 1099511628211ull;
    occupied += g.state_at(i) == mapping::CellState::Occupied;
    free += g.state_at(i) == mapping::CellState::Free;
  }
  return fmt::format("{}x{} occupied {} free {} fnv {:016x}", g.width(), g.height(), occupied, free, h);
}

// A path by its length, its ends and its sums: a change of any pose changes the sums.
std::string path_text(const std::vector<core::Pose2>& path) {
  core::Pose2 sum(0.0, 0.0, 0.0);
  for (const auto& p : path) sum = core::Pose2(sum.x + p.x, sum.y + p.y, sum.theta + p.theta);
  if (path.empty()) return "no poses\n";
  return fmt::format("{} poses, first {}, last {}, sums {}\n", path.size(), pose_text(path.front()),
                     pose_text(path.back()), pose_text(sum));
}

std::string slam_text(const SlamRunResult& r) {
  std::string out = fmt::format("run {} exchange {}\n", r.run, r.exchange);
  for (const auto& rb : r.robots) {
    const auto& l = rb.localization;
    out += fmt::format("robot {}\ntruth {}estimate {}", rb.name, path_text(rb.truth), path_text(rb.estimate));
    out += fmt::format("localization steps {} rmse {} {} nees {} over {} mu {}\n", l.steps, number(l.position_rmse),
                       number(l.heading_rmse), l.average_nees ? number(*l.average_nees) : "none", l.nees_steps,
                       number(l.dalfonso_mu));
    out += fmt::format("mapping nu {} mean {} max {} samples {} polynomials {}\n", number(rb.mapping.nu),
                       number(rb.mapping.mean_distance), number(rb.mapping.max_distance), rb.mapping.samples,
                       rb.mapping.polynomials);
    out += fmt::format("boundary coverage {} polynomials {}\n", number(rb.boundary_coverage), rb.polynomials);
    for (const auto& curve : rb.map_curves) {
      Eigen::Vector2d sum = Eigen::Vector2d::Zero();
      for (const auto& p : curve) sum += p;
      out += fmt::format("curve of {} points, sums {} {}\n", curve.size(), number(sum.x()), number(sum.y()));
    }
    for (const auto& [name, value] : rb.counters) out += fmt::format("counter {} {}\n", name, number(value));
  }
  for (const auto& m : r.rendezvous) {
    out += fmt::format("rendezvous step {} {} -> {} polynomials {} bytes {} grid {}\n", m.step, m.sender, m.receiver,
                       m.polynomials, m.bytes, m.grid_bytes);
  }
  return out;
}

std::string corridor_text(const CorridorResult& r) {
  std::string out = "truth " + grid_text(r.truth) + "\n";
  for (const auto& run : r.runs) {
    out += fmt::format("run {} laps {} found {} length {} height {} errors {} {} final {}\n", run.method, run.laps,
                       run.dimensions.found, number(run.dimensions.length_m), number(run.dimensions.height_m),
                       number(run.length_error), number(run.height_error), number(run.final_position_error_m));
    out += "map " + grid_text(run.map) + "\n";
    out += "truth " + path_text(run.truth) + "estimate " + path_text(run.estimate);
  }
  out += "master map " + grid_text(r.master_map) + "\nother map " + grid_text(r.other_map) + "\n";
  out += "master " + path_text(r.master_path) + "other " + path_text(r.other_path);
  out += "meeting " + pose_text(r.meeting_master) + " / " + pose_text(r.meeting_other) + "\n";
  for (const auto& m : r.merges) {
    out += fmt::format("merge error {} rotation {} far end {} wall distance {} misplaced {}\n",
                       number(m.orientation_error_deg), number(m.rotation_error_deg), number(m.far_end_error_m),
                       number(m.mean_wall_distance_m), number(m.misplaced_wall_share));
    out += "merged " + grid_text(m.merged) + "\n";
  }
  return out;
}

std::string transform_text(const core::Transform2& t) {
  return number(t.translation().x()) + " " + number(t.translation().y()) + " " + number(t.rotation());
}

std::string outcome_text(const MethodOutcome& m) {
  if (!m.transform) return "none\n";
  return fmt::format("{} error {} {} {} rms {} {}\n", transform_text(*m.transform), number(m.error.dx),
                     number(m.error.dy), number(m.error.theta), number(m.landmark_rms_x), number(m.landmark_rms_y));
}

std::string landmark_text(const LandmarkCaseRun& r) {
  std::string out = fmt::format("case {} run {} range noise {}\n", r.case_name, r.run, number(r.range_noise));
  for (const auto& rep : r.reports) {
    out += fmt::format("report step {} {} <- {} truth {} overlap {} shared {} global {}\n", rep.step, rep.leader,
                       rep.follower, transform_text(rep.truth), rep.overlap, rep.shared, rep.global_landmarks);
    for (int kind = 0; kind < 2; ++kind) {
      out += fmt::format("data association [{}] ", kind) + outcome_text(rep.data_association[kind]);
      out += fmt::format("observation [{}] ", kind) + outcome_text(rep.observation[kind]);
    }
    out += fmt::format("choice {} '{}' overlapping {} transform {}\n", int(rep.choice.method), rep.choice.message,
                       rep.choice.overlapping_landmarks,
                       rep.choice.transform ? transform_text(*rep.choice.transform) : "none");
  }
  for (std::size_t i = 0; i < r.final_position_error.size(); ++i) {
    out += fmt::format("robot {} final error {} dead reckoning {}\n", i, number(r.final_position_error[i]),
                       number(r.odometry_position_error[i]));
    out += "truth " + path_text(r.truth_paths[i]);
  }
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double covariance = 0.0, signature = 0.0;
  for (const auto& l : r.global.landmarks) {
    position += l.position;
    covariance += l.covariance.sum();
    signature += l.signature.sum();
  }
  std::uint64_t sources = 0;  // the robot of each landmark, in order
  for (int s : r.global_source) sources = 31 * sources + std::uint64_t(s + 2);
  out += fmt::format("global {} landmarks, sums {} {} covariance {} signature {} sources {}\n", r.global.landmarks.size(),
                     number(position.x()), number(position.y()), number(covariance), number(signature), sources);
  Eigen::Vector2d truth = Eigen::Vector2d::Zero();
  for (const auto& p : r.truth_in_leader) truth += p;
  out += fmt::format("truth {} landmarks, sums {} {}\n", r.truth_in_leader.size(), number(truth.x()), number(truth.y()));
  return out;
}

void expect_kept(const std::string& name, const std::string& text) {
  const fs::path golden = fs::path(FLEETMAP_SOURCE_DIR) / "tests/data/golden/experiments" / (name + ".txt");
  if (const char* update = std::getenv("FLEETMAP_UPDATE_GOLDEN"); update && std::string(update) == "1") {
    io::write_file_atomic(golden, text);
  }
  ASSERT_TRUE(fs::exists(golden)) << golden << " is missing: FLEETMAP_UPDATE_GOLDEN=1 writes it";
  const std::string kept = fleetmap::testing::slurp(golden);
  // The first line that differs, rather than two texts of thousands of lines.
  std::size_t at = 0;
  while (at < kept.size() && at < text.size() && kept[at] == text[at]) ++at;
  const std::size_t line_start = kept.rfind('\n', at == 0 ? 0 : at - 1);
  const std::size_t from = line_start == std::string::npos ? 0 : line_start + 1;
  EXPECT_EQ(text, kept) << name << " changed; first difference in the line: kept '"
                        << kept.substr(from, kept.find('\n', from) - from) << "', now '"
                        << text.substr(from, text.find('\n', from) - from) << "'";
}

TEST(KeptOutputs, PolynomialSlamOfDAlfonsoEtAl) {
  SlamScenario s = load_slam_scenario(std::string(FLEETMAP_SOURCE_DIR) + "/scenarios/dalfonso_3robots.yaml");
  s.steps = 110;  // r2 and r3 meet at about step 85
  const SlamSetup setup = prepare_slam(s);
  int r3 = 0;
  while (s.robots[std::size_t(r3)].name != "r3") ++r3;
  const std::string text =
      slam_text(run_slam(setup, 2, true)) + slam_text(run_slam(setup, 2, false)) + slam_text(run_slam(setup, 2, false, r3));
  expect_kept("dalfonso_polynomial_slam", text);
}

TEST(KeptOutputs, CorridorOfLeonEtAl) {
  CorridorOptions o;
  o.length_m = 9.0;
  o.height_m = 7.0;
  o.corridor_width_m = 1.6;
  o.laps = {1, 2};
  o.localizer_settings = {{"particles", "4"}};
  o.detection_errors_deg = {0.0, 5.0};
  o.seed = 3;
  o.methods = {"ideal", "odometry", "scan-matching", "rbpf"};
  expect_kept("leon_corridor", corridor_text(run_corridor_experiment(o)));
}

// Two robots in a shared strip, a trio meeting twice, and a case whose sparse landmarks leave the
// robots blind for most steps (FastSLAM 2.0's predictions accumulate), one of them with the range
// noise of Fig. 2 replaced: few particles keep it short.
TEST(KeptOutputs, LandmarkAlignmentOfTheMapAlignmentPaper) {
  constexpr const char* kCases = R"(
experiment: landmark_alignment
seed: 5
runs: 1
particles: 8
sensors:
  landmarks: {max_range: 10, range_noise: 0.05, bearing_noise_deg: 0.5}
  camera: {max_range: 40, range_noise: 0.05, bearing_noise_deg: 0.5}
landmarks:
  fields:
    - {area: [-25, -12, 25, 12], count: 60}
cases:
  - name: shared
    steps: 70
    robots:
      - {name: a, start: [-20, 0, 0], path: [[10, 0]]}
      - {name: b, start: [20, 3, 30], path: [[-10, 3]]}
  - name: trio
    steps: 80
    rendezvous: [40, 80]
    robots:
      - {name: a, start: [-20, 0, 0], path: [[15, 0]]}
      - {name: b, start: [20, 3, 30], path: [[-15, 3]]}
      - {name: c, start: [0, -20, 90], path: [[0, 10]]}
  - name: sparse
    steps: 60
    landmarks:
      fields:
        - {area: [-25, -12, -12, 12], count: 4}
        - {area: [12, -12, 25, 12], count: 4}
    robots:
      - {name: a, start: [-20, 0, 0], path: [[5, 0]]}
      - {name: b, start: [20, 3, 180], path: [[-5, 3]]}
parts:
  table1: shared
)";
  const LandmarkExperimentOptions o = parse_landmark_options(kCases, "kept.yaml");
  std::string text;
  for (const auto& c : o.cases) text += landmark_text(run_landmark_case(o, c, 0));
  text += landmark_text(run_landmark_case(o, o.cases.front(), 1, 0.3));
  expect_kept("landmark_alignment", text);
}

}  // namespace
}  // namespace fleetmap::experiments
