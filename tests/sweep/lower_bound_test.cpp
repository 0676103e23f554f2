#include "sweep/lower_bound.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sim/simulation.h"
#include "tests/sim/sim_test_maps.h"

namespace fleetmap::sweep {
namespace {

using sim::testing::walled_room;
using sim::Simulation;
using sim::World;

Eigen::Vector2d centre_of(const mapping::OccupancyGrid& g, int x, int y) { return g.geometry().cell_center({x, y}); }

TEST(ExplorationLowerBound, TravelBoundAlongACorridor) {
  // Interior cells x 1..200, y 1..5; the robot at cell (1, 3). The farthest cells, (200, 1) and
  // (200, 5), are 197 straight and 2 diagonal steps away.
  const auto corridor = walled_room(202, 7);
  const sim::World world(corridor, {});
  LowerBoundOptions o;
  o.coverage = 1.0;
  const auto b = exploration_lower_bound(world, {centre_of(corridor, 1, 3)}, o);
  const double farthest = (197.0 + 2.0 * std::sqrt(2.0)) * 0.1 / kOctileStretch;
  EXPECT_NEAR(b.quantile_distance_m, farthest, 1e-4);
  EXPECT_EQ(b.travel_steps, int(std::ceil((farthest - 4.0 - std::sqrt(2.0) * 0.1) / 0.5)));
  EXPECT_NEAR(b.free_area_m2, 200 * 5 * 0.01, 1e-9);
  EXPECT_EQ(b.area_steps, 0);  // 10 m^2 fit in one sensor disc
  EXPECT_EQ(b.steps(), b.travel_steps);
  // 99%: the 1% farthest cells (10 of 1000, two columns) need not be seen.
  o.coverage = 0.99;
  const auto b99 = exploration_lower_bound(world, {centre_of(corridor, 1, 3)}, o);
  EXPECT_LT(b99.quantile_distance_m, farthest - 0.1);
  EXPECT_GT(b99.quantile_distance_m, farthest - 0.35);
  // A robot at each end halves the distance.
  const auto two = exploration_lower_bound(world, {centre_of(corridor, 1, 3), centre_of(corridor, 200, 3)}, o);
  EXPECT_LT(two.quantile_distance_m, 0.55 * farthest);
}

TEST(ExplorationLowerBound, AreaBoundInAnOpenRoom) {
  // 150 x 150 free cells: 225 m^2; one robot sweeps at most 2 R' s = 2 * 4.1414 * 0.5 m^2 per step
  // after a first scan of at most pi R'^2.
  const auto room = walled_room(152, 152);
  const sim::World world(room, {});
  LowerBoundOptions o;
  o.coverage = 1.0;
  const auto one = exploration_lower_bound(world, {centre_of(room, 76, 76)}, o);
  const double r = 4.0 + std::sqrt(2.0) * 0.1;
  EXPECT_EQ(one.area_steps, int(std::ceil((225.0 - M_PI * r * r) / (2.0 * r * 0.5))));
  const auto four = exploration_lower_bound(world, {centre_of(room, 70, 70), centre_of(room, 80, 70), centre_of(room, 70, 80),
                                                    centre_of(room, 80, 80)}, o);
  EXPECT_EQ(four.area_steps, int(std::ceil((225.0 / 4.0 - M_PI * r * r) / (2.0 * r * 0.5))));
  // A longer sensor range or a lower coverage never raises the bound.
  LowerBoundOptions wide = o;
  wide.sensor_range_m = 6.0;
  EXPECT_LE(exploration_lower_bound(world, {centre_of(room, 76, 76)}, wide).steps(), one.steps());
  LowerBoundOptions less = o;
  less.coverage = 0.95;
  EXPECT_LE(exploration_lower_bound(world, {centre_of(room, 76, 76)}, less).steps(), one.steps());
}

TEST(ExplorationLowerBound, OnlyTheStartsRegionCounts) {
  // A wall splits the room; the far half is unreachable and not part of the bound.
  auto room = walled_room(60, 30);
  for (int y = 0; y < 30; ++y) room.set_state({30, y}, mapping::CellState::Occupied);
  const sim::World world(room, {});
  const auto b = exploration_lower_bound(world, {centre_of(room, 10, 15)}, {});
  EXPECT_NEAR(b.free_area_m2, 29 * 28 * 0.01, 1e-9);
}

// Rooms the robots can reach every part of, each larger than one sensor disc.
std::vector<mapping::OccupancyGrid> reachable_rooms() {
  std::vector<mapping::OccupancyGrid> rooms = {walled_room(200, 40), walled_room(120, 80), walled_room(160, 60)};
  for (int y = 30; y < 50; ++y)
    for (int x = 20; x < 40; ++x) rooms[1].set_state({x, y}, mapping::CellState::Occupied);  // a pillar
  for (int y = 0; y < 60; ++y) {
    if (y < 10 || y > 25) rooms[2].set_state({53, y}, mapping::CellState::Occupied);  // walls with doors
    if (y < 35 || y > 50) rooms[2].set_state({106, y}, mapping::CellState::Occupied);
  }
  return rooms;
}

TEST(ExplorationLowerBound, NeverExceedsTheStepsOfARealRun) {
  // The property that makes it a lower bound: 0 < efficiency <= 1 for every run.
  int runs_checked = 0;
  const auto rooms = reachable_rooms();
  for (std::size_t map = 0; map < rooms.size(); ++map) {
    for (const char* strategy : {"uncoordinated", "coordinated"}) {
      for (int robots : {1, 3}) {
        sim::Scenario s;
        s.map = "room";
        s.robot_count = robots;
        s.exploration.strategy = strategy;
        s.steps = 1500;
        s.seed = std::uint64_t(map + 1);
        const sim::RunResult r = Simulation(s, rooms[map]).run();
        std::vector<Eigen::Vector2d> starts;
        for (const auto& t : r.robots) starts.push_back(t.truth.front().position());
        LowerBoundOptions o;
        o.sensor_range_m = s.range.max_range_m;
        o.step_length_m = s.robot.max_speed_mps * s.period_s;
        const auto b = exploration_lower_bound(World(rooms[map], {}), starts, o);
        const std::string run = "map " + std::to_string(map) + " " + strategy + " " + std::to_string(robots);
        ASSERT_TRUE(r.steps_to_99.has_value()) << run;
        EXPECT_GT(b.steps(), 0) << run;
        EXPECT_LE(b.steps(), *r.steps_to_99) << run;
        const auto e = exploration_efficiency(b.steps(), r.steps_to_99);
        ASSERT_TRUE(e.has_value());
        EXPECT_GT(*e, 0.0) << run;
        EXPECT_LE(*e, 1.0) << run;
        ++runs_checked;
      }
    }
  }
  EXPECT_EQ(runs_checked, 12);
}

TEST(ExplorationEfficiency, IsTheBoundOverTheSteps) {
  EXPECT_DOUBLE_EQ(*exploration_efficiency(50, 200), 0.25);
  EXPECT_DOUBLE_EQ(*exploration_efficiency(0, 0), 1.0);
  EXPECT_FALSE(exploration_efficiency(50, std::nullopt).has_value());
}

}  // namespace
}  // namespace fleetmap::sweep
