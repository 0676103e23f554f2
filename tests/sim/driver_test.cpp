// sim/driver.h and the simulator's set-up for experiments: robots driven by a script or by
// waypoints instead of the explorer, odometry that misreports the motion, a meeting handler.
#include "sim/driver.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sim/simulation.h"
#include "tests/sim/sim_test_maps.h"

namespace fleetmap::sim {
namespace {

// One robot (or more) at given starts in a 10 x 8 m walled room, no noise anywhere.
Scenario room_scenario(std::vector<core::Pose2> starts, int steps) {
  Scenario s;
  s.map = "room";
  s.placement = Placement::List;
  s.robot_count = int(starts.size());
  s.starts = std::move(starts);
  s.steps = steps;
  s.noise = {0.0, 0.0};
  s.range.noise_m = 0.0;
  s.range.beams = 36;
  s.detector.range_noise_m = 0.0;
  s.detector.bearing_noise_rad = 0.0;
  return s;
}

TEST(Drivers, ACommandScriptDrivesItsCommandsAndThenTheRunEnds) {
  const Scenario s = room_scenario({core::Pose2(2.0, 4.0, 0.0)}, 500);
  SimulationSetup how;
  how.robots.resize(1);
  how.robots[0].driver = std::make_shared<CommandScript>(std::vector<Command>(20, Command{0.2, 0.0}));
  Simulation sim(s, testing::walled_room(100, 80), std::move(how));
  const RunResult r = sim.run();
  // 20 steps of 0.2 m/s for 1 s, straight along x, and the run ends with the script, not at 500.
  EXPECT_EQ(r.steps, 20);
  EXPECT_TRUE(r.finished);
  EXPECT_NEAR(r.robots[0].truth.back().x, 6.0, 1e-9);
  EXPECT_NEAR(r.robots[0].truth.back().y, 4.0, 1e-9);
  EXPECT_NEAR(r.robots[0].distance_m, 4.0, 1e-9);
  bool finished_event = false;
  for (const auto& e : r.events) finished_event = finished_event || (e.kind == "finished" && e.step == 20);
  EXPECT_TRUE(finished_event);
}

TEST(Drivers, AWaypointDriverDrivesClosedLapsOnTheTruePose) {
  WaypointDrive way;
  way.waypoints = {{2.0, 2.0}, {8.0, 2.0}, {8.0, 6.0}, {2.0, 6.0}};
  way.closed = true;
  way.laps = 2;
  way.speed_mps = 0.5;
  Scenario s = room_scenario({core::Pose2(2.0, 2.0, 0.0)}, 2000);
  s.period_s = 0.5;
  s.localization = "odometry";
  SimulationSetup how;
  how.measure_coverage = false;
  how.robots.resize(1);
  auto driver = std::make_shared<WaypointDriver>(way, s.period_s);
  how.robots[0].driver = driver;
  // The encoders report a heading drift of 0.01 rad per metre that the robot never turned: the
  // truth closes its laps, dead reckoning does not.
  how.robots[0].odometry_error = OdometryError{0.0, 0.01, 0.0, 0.0};
  Simulation sim(s, testing::walled_room(100, 80), std::move(how));
  int steps_seen = 0;
  sim.run_to_end({}, [&](const Simulation&) { ++steps_seen; });
  ASSERT_EQ(driver->lap_ends().size(), 2u);
  EXPECT_EQ(driver->lap_ends().back(), sim.step_count());
  EXPECT_EQ(steps_seen, sim.step_count() + 1);  // the start, then every step
  // A lap of the 20 m loop at 0.25 m per step takes at least 80 steps; both took about as long.
  EXPECT_GT(driver->lap_ends()[0], 80);
  EXPECT_NEAR(driver->lap_ends()[1], 2 * driver->lap_ends()[0], 10);
  EXPECT_LT((sim.true_poses()[0].position() - way.waypoints[0]).norm(), way.reached_m);
  // Two laps of the 20 m loop, less what passing each corner within reached_m cuts off.
  EXPECT_GT(sim.track(0).distance_m, 2 * (20.0 - 4 * 2 * way.reached_m));
  EXPECT_LT(sim.track(0).distance_m, 2 * 20.0 + 0.5);
  // The robot drove its laps on the true pose, whatever it believed: its dead reckoning, turned by
  // 0.4 rad over 40 m, ends far from it.
  EXPECT_GT((sim.estimated_poses()[0].position() - sim.true_poses()[0].position()).norm(), 0.5);
  EXPECT_TRUE(sim.result().coverage.empty());  // not measured
}

TEST(Drivers, AMeetingHandlerReplacesTheGridExchangeWhenTwoRobotsFirstSeeEachOther) {
  // Two robots drive toward each other along y = 4; cameras reach 2.1 m.
  Scenario s = room_scenario({core::Pose2(1.0, 4.0, 0.0), core::Pose2(9.0, 4.0, 3.141592653589793)}, 100);
  s.communication.range_m = 0.0;  // they talk when they see each other
  s.detector.max_range_m = 2.1;
  s.merging = "rendezvous";
  SimulationSetup how;
  how.robots.resize(2);
  for (auto& r : how.robots) r.driver = std::make_shared<CommandScript>(std::vector<Command>(16, Command{0.2, 0.0}));
  std::vector<std::pair<int, int>> met;
  std::vector<int> at;
  how.on_meeting = [&](Simulation& sim, int a, int b) {
    met.emplace_back(a, b);
    at.push_back(sim.step_count());
    EXPECT_FALSE(sim.detections(a).empty());
  };
  const RunResult r = Simulation(s, testing::walled_room(100, 80), std::move(how)).run();
  // They are 8 m apart and close in at 0.4 m per step: 2 m apart after step 15, first in reach then.
  ASSERT_EQ(met.size(), 1u);
  EXPECT_EQ(met[0], std::make_pair(0, 1));
  EXPECT_EQ(at[0], 15);
  EXPECT_EQ(r.meetings, 1);
  EXPECT_EQ(r.bytes_sent, 0);  // no grid tiles sent: the handler exchanged instead
  EXPECT_TRUE(r.merges.empty());
  EXPECT_EQ(r.robot_frames[1].rotation(), s.starts[1].theta);  // and nobody changed frames
}

}  // namespace
}  // namespace fleetmap::sim
