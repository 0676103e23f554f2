#include "sim/simulation.h"

#include <gtest/gtest.h>

#include <set>

#include <opencv2/imgproc.hpp>

#include "core/angle.h"
#include "maps/builtin_maps.h"
#include "io/map_image.h"
#include "io/map_io.h"
#include "sim/run_output.h"
#include "tests/sim/sim_test_maps.h"
#include "tests/test_support.h"

namespace fleetmap::sim {
namespace {

using fleetmap::testing::expect_input_error;

Scenario small(const std::string& map, int robots, int steps) {
  Scenario s;
  s.map = map;
  s.robot_count = robots;
  s.steps = steps;
  s.noise = {0.01, 0.01};  // visible noise, so that seeds matter
  return s;
}

nlohmann::json without_timing(nlohmann::json j) {
  j.erase("timing");
  return j;
}

TEST(Simulation, SameSeedSameRunDifferentSeedDifferentRun) {
  const auto grid = maps::load_map_source("office");
  Scenario s = small("office", 3, 60);
  s.localization = "odometry";
  const RunResult a = Simulation(s, grid).run();
  const RunResult b = Simulation(s, grid).run();
  EXPECT_EQ(without_timing(metrics_json(a, "office")).dump(), without_timing(metrics_json(b, "office")).dump());
  ASSERT_EQ(a.robots[0].truth.size(), b.robots[0].truth.size());
  for (std::size_t k = 0; k < a.robots[0].truth.size(); ++k) {
    EXPECT_EQ(a.robots[1].truth[k], b.robots[1].truth[k]);
    EXPECT_EQ(a.robots[1].estimate[k], b.robots[1].estimate[k]);
  }
  EXPECT_EQ(a.merged.log_odds_data(), b.merged.log_odds_data());
  s.seed = 2;
  const RunResult c = Simulation(s, grid).run();
  EXPECT_NE(a.robots[1].truth.back(), c.robots[1].truth.back());
}

TEST(Simulation, ExploresASmallMapAndStopsWhenDone) {
  const RunResult r = Simulation(small("empty", 2, 2000), maps::load_map_source("empty")).run();
  EXPECT_TRUE(r.finished);
  EXPECT_LT(r.steps, 2000);
  EXPECT_GE(r.coverage.back(), 0.99);
  ASSERT_TRUE(r.steps_to_95.has_value());
  ASSERT_TRUE(r.steps_to_99.has_value());
  EXPECT_LE(*r.steps_to_95, *r.steps_to_99);
  for (std::size_t k = 1; k < r.coverage.size(); ++k) ASSERT_GE(r.coverage[k], r.coverage[k - 1]);
  EXPECT_EQ(int(r.coverage.size()), r.steps + 1);
  EXPECT_GT(r.bytes_sent, 0);
  EXPECT_GT(r.redundancy, 0.0);
  EXPECT_LT(r.redundancy, 1.0);
}

// Specks the scan misses (a room strewn with 5 cm posts, and a robot with 4 beams): a robot that
// touches one marks it on its map and never drives into it again; without that it pushes against
// the same post step after step. Every blocked move at a wall is a first touch.
TEST(Simulation, ARobotLearnsFromTouchingWhatItsScanMissed) {
  auto room = testing::walled_room(120, 120);  // 6 x 6 m
  core::Random rng(7);
  for (int k = 0; k < 80; ++k) room.set_state({rng.uniform_int(10, 110), rng.uniform_int(10, 110)}, mapping::CellState::Occupied);
  Scenario s;
  s.map = "room_with_posts";
  s.robot_count = 1;
  s.range.beams = 4;  // 90 degrees apart: most posts stay unseen until touched
  s.steps = 800;
  const RunResult r = Simulation(s, room).run();
  ASSERT_EQ(r.robots.size(), 1u);
  std::set<std::string> touched;
  int wall_blocks = 0;
  for (const auto& e : r.events) {
    if (e.kind != "blocked" || e.detail.find("wall at") == std::string::npos) continue;
    ++wall_blocks;
    EXPECT_TRUE(touched.insert(e.detail).second) << "step " << e.step << ": " << e.detail << " again";
  }
  EXPECT_GE(wall_blocks, 1) << "the robot should have touched some post";
  EXPECT_EQ(r.robots[0].contacts_marked, wall_blocks);
}

// Two robots that cannot talk, each in its own frame, start facing each other's way in the
// office's corner: a robot that bumps into the other plans its detour around where its bumper put
// it, as around the robots it knows of, after detour_after_steps steps without progress; without
// that both push against each other step after step (they did for 17 steps in a row, 327 of 600
// robot-steps blocked).
TEST(Simulation, RobotsThatCannotTalkDetourAroundARobotTheyBumpedInto) {
  Scenario s;
  s.map = "office";
  s.placement = Placement::List;
  s.starts = {core::Pose2(1.0, 1.0, 0.0), core::Pose2(3.0, 1.0, core::deg2rad(90.0))};
  s.robot_count = 2;
  s.merging = "none";
  s.steps = 300;
  const RunResult r = Simulation(s, maps::load_map_source("office")).run();
  // The longest run of consecutive steps in which a robot was stopped by the other.
  const int detour = s.exploration.detour_after_steps;
  for (int robot = 0; robot < 2; ++robot) {
    int streak = 0, longest = 0, last = -2;
    for (const auto& e : r.events) {
      if (e.kind != "blocked" || e.robot != robot || e.detail.find("robot") == std::string::npos) continue;
      streak = e.step == last + 1 ? streak + 1 : 1;
      last = e.step;
      longest = std::max(longest, streak);
    }
    // Blocked until the detour check, then at most once more while the other one moves too.
    EXPECT_LE(longest, detour + 1) << "robot " << robot + 1 << ": " << longest << " in a row";
  }
}

// A map finer than the planning resolution: the explorer decides on coarser cells, and the team
// still explores all of it and stops by itself.
TEST(Simulation, ExploresAFineMapDecidingOnCoarserCells) {
  const mapping::OccupancyGrid office = maps::load_map_source("office");
  cv::Mat image;
  cv::resize(io::grid_to_image(office), image, {}, 2, 2, cv::INTER_NEAREST);
  io::MapYaml meta;
  meta.resolution = office.resolution() / 2;
  const mapping::OccupancyGrid fine = io::grid_from_image(image, meta);
  Scenario s = small("office", 3, 2000);
  s.range.beams = 720;  // beams no farther apart than the cells near the robot
  s.exploration.planning_resolution_m = 0.1;
  const RunResult r = Simulation(s, fine).run();
  EXPECT_TRUE(r.finished);
  EXPECT_GE(r.coverage.back(), 0.99);
  EXPECT_GT(r.exploration.targets_reached, 0);
}

TEST(Simulation, RendezvousOnlyCommunicationSendsLessThanAlways) {
  Scenario s = small("office", 3, 150);
  const auto grid = maps::load_map_source("office");
  const RunResult always = Simulation(s, grid).run();
  s.communication.range_m = 0.0;
  const RunResult rendezvous = Simulation(s, grid).run();
  EXPECT_LT(rendezvous.bytes_sent, always.bytes_sent);
  EXPECT_GT(always.meetings, 0);
}

TEST(Simulation, PlacesRobotsApartInFreeSpace) {
  const auto grid = maps::load_map_source("cave");
  for (const Placement p : {Placement::Cluster, Placement::Random}) {
    Scenario s = small("cave", 9, 1);
    s.placement = p;
    s.min_separation_m = 1.0;
    const Simulation sim(s, grid);
    const auto& poses = sim.true_poses();
    ASSERT_EQ(poses.size(), 9u);
    for (std::size_t i = 0; i < poses.size(); ++i) {
      EXPECT_TRUE(sim.world().disc_free(poses[i].position(), s.robot.radius_m));
      for (std::size_t j = 0; j < i; ++j) EXPECT_GE((poses[i].position() - poses[j].position()).norm(), 1.0 - 1e-9);
    }
  }
}

TEST(SimulationBadInput, StartsAndCountsAreChecked) {
  const auto room = testing::walled_room(50, 40);
  Scenario s = small("room", 1, 10);
  s.placement = Placement::List;
  const auto with_starts = [&](std::vector<core::Pose2> starts) {
    Scenario t = s;
    t.starts = std::move(starts);
    t.robot_count = int(t.starts.size());
    return t;
  };
  expect_input_error([&] { Simulation(with_starts({{0.05, 2.0, 0}}), room); }, {"robot 1 starts at (0.05, 2.00)", "inside a wall"});
  expect_input_error([&] { Simulation(with_starts({{1.0, 1.0, 0}, {9.0, 1.0, 0}}), room); },
                     {"robot 2 starts at (9.00, 1.00)", "outside the map", "x from 0.00 to 5.00 m"});
  expect_input_error([&] { Simulation(with_starts({{1.0, 1.0, 0}, {1.2, 1.1, 0}}), room); }, {"robot 2", "on robot 1"});
  expect_input_error([&] { Simulation(with_starts({{0.2, 2.0, 0}}), room); }, {"robot 1", "too close to a wall"});
  Scenario none = small("room", 0, 10);
  expect_input_error([&] { Simulation(none, room); }, {"robots", "a whole number from 1 to 64"});
  Scenario crowd = small("room", 60, 10);
  crowd.min_separation_m = 2.0;
  expect_input_error([&] { Simulation(crowd, room); }, {"robots: only", "of 60 robots fit"});
  Scenario noisy = small("room", 1, 10);
  noisy.noise.position_m = -1.0;
  expect_input_error([&] { Simulation(noisy, room); }, {"noise.position", "expected a number >= 0"});
  Scenario range = small("room", 1, 10);
  range.communication.range_m = -5.0;
  expect_input_error([&] { Simulation(range, room); }, {"communication.range", "expected a number >= 0"});
  Scenario strategy = small("room", 1, 10);
  strategy.exploration.strategy = "greedy";
  expect_input_error([&] { Simulation(strategy, room); }, {"unknown", "greedy", "coordinated"});
  Scenario landmark = small("room", 1, 10);
  landmark.landmarks = {{0.05, 0.05}};
  expect_input_error([&] { Simulation(landmark, room); }, {"landmarks.points[0]", "inside a wall"});
  Scenario cluster = small("room", 1, 10);
  cluster.cluster_at = Eigen::Vector2d(0.05, 1.0);
  expect_input_error([&] { Simulation(cluster, room); }, {"robots.cluster_at", "inside a wall"});
}

}  // namespace
}  // namespace fleetmap::sim

namespace fleetmap::sim {
namespace {

TEST(Simulation, EkfAgainstLandmarksBeatsOdometryAndIsConsistent) {
  const auto grid = maps::load_map_source("warehouse");
  Scenario s;
  s.map = "warehouse";
  s.robot_count = 2;
  s.steps = 250;
  s.noise = {0.01, core::deg2rad(0.5)};
  s.landmarks_along_walls = 0.3;
  s.landmark_sensor.range_noise_m = 0.05;
  s.landmark_sensor.bearing_noise_rad = core::deg2rad(2.0);
  s.localization = "odometry";
  const auto odometry = metrics_json(Simulation(s, grid).run(), "warehouse");
  s.localization = "ekf";
  const auto ekf = metrics_json(Simulation(s, grid).run(), "warehouse");
  EXPECT_LT(ekf["position_rmse_m"].get<double>(), 0.5 * odometry["position_rmse_m"].get<double>());
  // A better pose makes a better map: fewer wrong cells and walls nearer the true ones.
  EXPECT_LT(ekf["map_quality"]["wrong_cell_share"].get<double>(), odometry["map_quality"]["wrong_cell_share"].get<double>());
  EXPECT_LT(ekf["map_quality"]["mean_wall_distance_m"].get<double>(),
            odometry["map_quality"]["mean_wall_distance_m"].get<double>());
  for (const auto& robot : ekf["per_robot"]) {
    EXPECT_GT(robot["localizer"]["landmark_updates"].get<double>(), 100.0);
    // The simulator's noise is the filter's model: the run-average NEES lies in its 95% band
    // (each robot's band is for ~250 steps of a 3-dof chi-square). With two robots, the chance that
    // a consistent filter misses is about 10%, so allow a 20% margin beyond the band.
    const double nees = robot["nees"].get<double>(), lo = robot["nees_band_95"][0], hi = robot["nees_band_95"][1];
    EXPECT_GT(nees, 0.8 * lo);
    EXPECT_LT(nees, 1.2 * hi);
  }
}

}  // namespace
}  // namespace fleetmap::sim
