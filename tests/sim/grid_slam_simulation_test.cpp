// The grid-SLAM and MCL localizers inside the simulator (`fleetmap explore --localization ...`),
// and the scenario keys they bring.
#include <gtest/gtest.h>

#include "core/angle.h"
#include "maps/builtin_maps.h"
#include "sim/run_output.h"
#include "sim/scenario.h"
#include "sim/simulation.h"
#include "tests/test_support.h"

namespace fleetmap::sim {
namespace {

using fleetmap::testing::expect_input_error;

Scenario noisy(const std::string& localization, int robots, int steps) {
  Scenario s;
  s.map = "office";
  s.robot_count = robots;
  s.steps = steps;
  // Visible motion noise: 2 cm and 1 degree per step, which dead reckoning cannot undo.
  s.noise = {0.02, core::deg2rad(1.0)};
  s.localization = localization;
  if (localization == "rbpf") s.localization_settings = {{"particles", "12"}};
  return s;
}

// The position RMSE summed over seeds 1 to 3: one route can be a poor one for scan matching (a long
// featureless wall) or a lucky one for dead reckoning (errors that cancel).
double rmse(const std::string& localization, int steps) {
  const auto grid = maps::load_map_source("office");
  double sum = 0.0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    Scenario s = noisy(localization, 1, steps);
    s.seed = seed;
    sum += metrics_json(Simulation(s, grid).run(), "office")["position_rmse_m"].get<double>();
  }
  return sum;
}

// Scan matching on the robot's own grid, and the particle filter, undo most of the drift that
// dead reckoning accumulates over the same runs (same seeds, same noise).
TEST(GridSlamSimulation, ScanMatchingAndRbpfBeatDeadReckoningInExplore) {
  const double odometry = rmse("odometry", 120);
  const double scan = rmse("scan-matching", 120);
  const double rbpf = rmse("rbpf", 120);
  EXPECT_GT(odometry, 0.3);
  EXPECT_LT(scan, 0.5 * odometry);
  EXPECT_LT(rbpf, 0.5 * odometry);
}

// A lost robot (uniform belief) in the explore loop: alone it does not know where it starts; detected
// by a teammate that knows its start, it ends the run localized.
TEST(GridSlamSimulation, MclLostRobotIsLocalizedInExplore) {
  const auto grid = maps::load_map_source("office");
  Scenario s = noisy("mcl", 2, 60);
  s.noise = {0.005, core::deg2rad(0.3)};
  s.localization_settings = {{"particles", "1500"}};
  s.lost_robots = {2};
  const RunResult alone = Simulation(s, grid).run();
  EXPECT_GT((alone.robots[1].estimate.front().position() - alone.robots[1].truth.front().position()).norm(), 0.5);
  s.localization_options.use_robot_detections = true;
  const RunResult r = Simulation(s, grid).run();
  const auto& lost = r.robots[1];
  EXPECT_LT((lost.estimate.back().position() - lost.truth.back().position()).norm(), 0.3);
  double used = 0;
  for (const auto& [k, v] : lost.localizer_counters) if (k == "robot_detections_used") used = v;
  EXPECT_GT(used, 0);
}

TEST(GridSlamSimulation, MclNeedsTheKnownMapFrame) {
  const auto grid = maps::load_map_source("office");
  Scenario s = noisy("mcl", 2, 10);
  s.merging = "rendezvous";
  expect_input_error([&] { Simulation(s, grid); }, {"mcl", "merging: known"});
}

// The localizer's own parameters sit beside its name; the scenario written reads back the same.
TEST(GridSlamScenario, ReadsAndWritesTheLocalizersParameters) {
  const Scenario s = parse_scenario("localization:\n  name: mcl\n  particles: 500\n  lost_robots: [2]\nrobots:\n  count: 3\n",
                                    "t.yaml", ".");
  EXPECT_EQ(s.localization, "mcl");
  EXPECT_EQ(s.localization_settings, (core::Settings{{"particles", "500"}}));
  EXPECT_EQ(s.lost_robots, std::vector<int>{2});
  const Scenario back = parse_scenario(scenario_to_yaml(s), "back.yaml", ".");
  EXPECT_EQ(back.lost_robots, s.lost_robots);
  EXPECT_EQ(localization::localizer_options(back.localization, back.localization_settings).number("particles"), 500);
}

// Files written before the localizers declared their parameters still read: `method`, and each
// old particles key sets `particles` of the localizers it named and nothing else.
TEST(GridSlamScenario, OlderLocalizationKeysStillRead) {
  const std::string old_keys = "  mcl_particles: 500\n  rbpf_particles: 12\n  fastslam_particles: 70\n";
  const auto particles = [&](const std::string& method) {
    const Scenario s = parse_scenario("landmarks: {along_walls: 0.5}\nlocalization:\n  method: " + method + "\n" + old_keys,
                                      "t.yaml", ".");
    return localization::localizer_options(s.localization, s.localization_settings).number("particles");
  };
  EXPECT_EQ(particles("mcl"), 500);
  EXPECT_EQ(particles("rbpf"), 12);
  EXPECT_EQ(particles("fastslam-grid"), 12);
  EXPECT_EQ(particles("fastslam2"), 70);
  const Scenario ekf = parse_scenario("landmarks: {along_walls: 0.5}\nlocalization:\n  method: ekf\n" + old_keys, "t.yaml", ".");
  EXPECT_TRUE(ekf.localization_settings.empty());
}

TEST(GridSlamScenario, BadLocalizationKeysAreOneLineErrors) {
  const auto parse = [](const std::string& text) { validate_scenario(parse_scenario(text, "t.yaml", ".")); };
  expect_input_error([&] { parse("localization:\n  method: ekf\n  lost_robots: [1]\n"); }, {"lost_robots", "'ekf'"});
  expect_input_error([&] { parse("localization:\n  method: mcl\n  lost_robots: [5]\nrobots:\n  count: 2\n"); },
                     {"lost_robots", "robot 5"});
  expect_input_error([&] { parse("localization:\n  method: mcl\n  lost_robots: [1.5]\n"); }, {"lost_robots", "1.5"});
  expect_input_error([&] { parse("localization:\n  method: rbpf\n  rbpf_particles: 0\n"); }, {"rbpf_particles", "particles", "1"});
  expect_input_error([&] { parse("localization:\n  name: mcl\n  particles: -3\n"); }, {"localization.particles", "-3"});
  // A parameter of another localizer, a misspelt one, and the name given twice.
  expect_input_error([&] { parse("localization:\n  name: ekf\n  particles: 30\n"); }, {"localization 'ekf' has no parameter 'particles'"});
  expect_input_error([&] { parse("localization:\n  name: rbpf\n  particels: 30\n"); }, {"particels", "did you mean 'particles'"});
  expect_input_error([&] { parse("localization:\n  name: rbpf\n  method: rbpf\n"); }, {"'name' only once"});
  expect_input_error([&] { parse("localization:\n  name: rbpf\n  sample_motion: maybe\n"); }, {"sample_motion", "true or false"});
}

}  // namespace
}  // namespace fleetmap::sim
