// experiments/corridor_experiment.cpp and experiments/corridor_output.cpp: León et al.'s corridor comparison and
// merging by detection, on a small loop so that the test takes seconds.
#include "experiments/corridor_experiment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "core/format.h"
#include "experiments/corridor_output.h"
#include "tests/test_support.h"

namespace fleetmap::experiments {
namespace {

using fleetmap::testing::expect_input_error;

CorridorOptions small_loop() {
  CorridorOptions o;
  o.length_m = 9.0;
  o.height_m = 7.0;
  o.corridor_width_m = 1.6;
  o.laps = {1, 2};
  o.localizer_settings = {{"particles", "4"}};
  o.detection_errors_deg = {0.0, 5.0};
  return o;
}

TEST(CorridorWorld, HasTheLoopsDimensions) {
  const auto o = small_loop();
  const auto world = corridor_world(o);
  // On the truth the outermost occupied cells are the outer wall's outer layer (the wall is 0.3 m
  // thick): the measure gives the loop plus both walls less one cell on each side.
  const MapDimensions d = measure_loop(world);
  ASSERT_TRUE(d.found);
  EXPECT_NEAR(d.length_m, o.length_m + 0.6 - 2 * o.resolution_m, 0.5 * o.resolution_m);
  EXPECT_NEAR(d.height_m, o.height_m + 0.6 - 2 * o.resolution_m, 0.5 * o.resolution_m);
  EXPECT_EQ(world.state(*world.geometry().world_to_cell({0.8, 0.8})), mapping::CellState::Free);
  EXPECT_EQ(world.state(*world.geometry().world_to_cell({4.5, 3.5})), mapping::CellState::Occupied);  // the inner block
  expect_input_error(
      [&] {
        auto bad = o;
        bad.corridor_width_m = 3.4;
        corridor_world(bad);
      },
      {"corridor_width"});
}

TEST(CorridorExperiment, MeasuresEveryMethodAndShowsWhatADetectionErrorDoes) {
  const CorridorResult r = run_corridor_experiment(small_loop());
  ASSERT_EQ(r.runs.size(), 10u);  // 5 methods x 2 lap counts
  for (const auto& run : r.runs) {
    ASSERT_TRUE(run.dimensions.found) << run.method;
    if (run.method == "ideal") {
      // A map built at the true poses: its walls' faces are the loop's, to a cell.
      EXPECT_LT(std::abs(run.dimensions.length_m - 9.0), 0.1 + 1e-9) << run.laps;
      EXPECT_LT(std::abs(run.dimensions.height_m - 7.0), 0.1 + 1e-9) << run.laps;
      EXPECT_LT(run.final_position_error_m, 1e-9);
    }
  }
  const auto find = [&](const std::string& m, int laps) -> const CorridorRun& {
    for (const auto& run : r.runs)
      if (run.method == m && run.laps == laps) return run;
    throw std::runtime_error("missing run");
  };
  // The odometry (2% short, 0.1 deg/m turn bias) drifts; scan matching ends nearer the truth.
  EXPECT_GT(find("odometry", 2).final_position_error_m, 0.2);
  EXPECT_LT(find("scan-matching", 2).final_position_error_m, find("odometry", 2).final_position_error_m);

  ASSERT_EQ(r.merges.size(), 2u);
  const auto& exact = r.merges[0];
  const auto& off = r.merges[1];
  // Without an added error the merge is right to the detection noise (1 degree bearing noise);
  // 5 degrees turn the other's map about the meeting point: its start, about 8 m away, moves by
  // about 8 m x 5 deg = 0.7 m, and its walls leave the true ones.
  EXPECT_LT(exact.rotation_error_deg, 3.0);
  EXPECT_NEAR(off.rotation_error_deg, 5.0, 3.0);
  EXPECT_GT(off.far_end_error_m, exact.far_end_error_m + 0.3);
  EXPECT_GT(off.mean_wall_distance_m, exact.mean_wall_distance_m);
  EXPECT_GT(off.misplaced_wall_share, exact.misplaced_wall_share);
  // The merged map holds the other's corridors: the two maps overlap only at the meeting corner.
  EXPECT_GT(exact.merged.known_count(), r.master_map.known_count() + r.other_map.known_count() / 2);
}

TEST(CorridorExperiment, WritesTablesFiguresAndJson) {
  auto o = small_loop();
  o.laps = {1};
  o.methods = {"ideal", "odometry"};
  o.detection_errors_deg = {2.0};
  const CorridorResult r = run_corridor_experiment(o);
  fleetmap::testing::TempDir dir;
  const auto written = write_corridor_outputs(r, dir.path() / "out");
  for (const char* name : {"corridor_table.md", "corridor_table.csv", "corridor.json", "corridor_ideal_1lap.png",
                           "corridor_odometry_1lap.png", "merge_detection.csv", "merge_detection.md",
                           "merge_detection_2p0deg.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "out" / name)) << name;
  }
  EXPECT_EQ(written.size(), 8u);
  const std::string csv = corridor_table_csv(r);
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "method,seed,laps,real_length_m,real_height_m,length_m,height_m,length_error_pct,height_error_pct,"
            "final_position_error_m,seconds");
  EXPECT_NE(corridor_table_markdown(r).find("| Length (m) | 9.0 |"), std::string::npos);
}

TEST(CorridorExperiment, OverSeveralSeedsTableIGivesTheMeanAndTheSpread) {
  auto o = small_loop();
  o.laps = {1};
  o.methods = {"odometry"};
  o.merge_study = false;
  o.seed = 2;
  o.seeds = 3;
  const CorridorResult r = run_corridor_experiment(o);
  ASSERT_EQ(r.runs.size(), 3u);
  std::vector<double> errors;
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(r.runs[k].seed, 2u + k);
    errors.push_back(r.runs[k].final_position_error_m);
  }
  // Each seed its own drive: its own odometry noise, its own drift.
  EXPECT_NE(errors[0], errors[1]);
  EXPECT_NE(errors[1], errors[2]);
  const double mean = (errors[0] + errors[1] + errors[2]) / 3.0;
  double var = 0.0;
  for (double e : errors) var += (e - mean) * (e - mean) / 2.0;
  const std::string md = corridor_table_markdown(r);
  EXPECT_NE(md.find("(seeds 2-4: mean ± standard deviation)"), std::string::npos) << md;
  EXPECT_NE(md.find("| Final position error (m) | | " + core::fixed(mean, 2) + " ± " + core::fixed(std::sqrt(var), 2) + " |"),
            std::string::npos)
      << md;
  // The first seed's run is the run of that seed alone.
  o.seeds = 1;
  EXPECT_EQ(run_corridor_experiment(o).runs[0].final_position_error_m, errors[0]);
}

TEST(CorridorOptionsParsing, ReadsTheScenarioAndRejectsBadKeys) {
  const std::string good =
      "experiment: leon_corridor\nseed: 4\nseeds: 10\nworld:\n  length: 12\ndrive:\n  laps: [3, 1]\nmethods:\n  list: [odometry]\n";
  EXPECT_TRUE(is_corridor_scenario(good, "c.yaml"));
  EXPECT_FALSE(is_corridor_scenario("map: office\n", "s.yaml"));
  const CorridorOptions o = parse_corridor_options(good, "c.yaml");
  EXPECT_EQ(o.seed, 4u);
  EXPECT_EQ(o.seeds, 10);
  EXPECT_EQ(o.length_m, 12.0);
  EXPECT_EQ(o.laps, (std::vector<int>{1, 3}));
  EXPECT_EQ(o.methods, std::vector<std::string>{"odometry"});
  expect_input_error([] { parse_corridor_options("experiment: leon_corridor\nwrld: {}\n", "c.yaml"); }, {"c.yaml", "wrld"});
  expect_input_error([] { parse_corridor_options("experiment: leon_corridor\ndrive:\n  laps: [0]\n", "c.yaml"); },
                     {"laps", "0"});
  expect_input_error([] { parse_corridor_options("experiment: leon_corridor\nworld:\n  length: -1\n", "c.yaml"); },
                     {"length"});
  expect_input_error([] { parse_corridor_options("experiment: other\n", "c.yaml"); }, {"experiment", "other"});
  expect_input_error([] { parse_corridor_options("experiment: leon_corridor\nseeds: 0\n", "c.yaml"); }, {"seeds", "0"});
  auto bad = small_loop();
  bad.methods = {"mcl"};
  expect_input_error([&] { run_corridor_experiment(bad); }, {"methods.list", "'mcl'"});
}

TEST(CorridorOptionsParsing, AMethodListOfListsIsOneLineNotACrash) {
  // Found by fuzzing: a list inside the methods list reached yaml-cpp's conversion, which threw.
  expect_input_error([] { parse_corridor_options("experiment: leon_corridor\nmethods:\n  list: [ideal, [odometry]]\n", "c.yaml"); },
                     {"c.yaml:3: key 'methods.list': expected a list of localizer names, got an item a list"});
}

}  // namespace
}  // namespace fleetmap::experiments
