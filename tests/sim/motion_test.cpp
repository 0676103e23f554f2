#include "sim/motion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "tests/sim/sim_test_maps.h"

namespace fleetmap::sim {
namespace {

TEST(Motion, FollowsTheArcWithoutNoise) {
  const World world(testing::walled_room(100, 100), {});
  core::Random rng(1);
  RobotOptions robot;
  MotionNoise none{0.0, 0.0};
  const MoveResult m = move_robot(world, 0, {core::Pose2(5.0, 5.0, 0.0)}, robot, {0.5, 0.0}, 1.0, none, rng);
  EXPECT_FALSE(m.blocked);
  EXPECT_NEAR(m.pose.x, 5.5, 1e-12);
  EXPECT_NEAR(m.distance_m, 0.5, 1e-12);
  const MoveResult turn = move_robot(world, 0, {core::Pose2(5.0, 5.0, 0.0)}, robot, {0.0, 1.0}, 1.0, none, rng);
  EXPECT_NEAR(turn.pose.theta, 1.0, 1e-12);
  EXPECT_NEAR(turn.pose.x, 5.0, 1e-12);
}

TEST(Motion, SpeedAndTurnLimitsHold) {
  const World world(testing::walled_room(100, 100), {});
  core::Random rng(1);
  RobotOptions robot;
  robot.max_speed_mps = 0.3;
  robot.max_turn_rate_rps = 0.5;
  const MoveResult m = move_robot(world, 0, {core::Pose2(5.0, 5.0, 0.0)}, robot, {2.0, 3.0}, 1.0, {0.0, 0.0}, rng);
  EXPECT_NEAR(m.odometry.v, 0.3, 1e-12);
  EXPECT_NEAR(m.odometry.omega, 0.5, 1e-12);
}

TEST(Motion, BlockedMovesStopBeforeTheWallAndAreCounted) {
  const World world(testing::walled_room(40, 40), {});
  core::Random rng(1);
  RobotOptions robot;
  // 0.3 m from the east wall's face (x = 3.9 m), driving east at 0.5 m/s.
  const MoveResult m = move_robot(world, 0, {core::Pose2(3.6, 2.0, 0.0)}, robot, {0.5, 0.0}, 1.0, {0.0, 0.0}, rng);
  EXPECT_TRUE(m.blocked);
  EXPECT_LE(m.pose.x, 3.9 - robot.radius_m + 1e-9);
  EXPECT_TRUE(world.disc_free(m.pose.position(), robot.radius_m));
}

// The safety property: over random maps and random commands (many aimed at walls and at each
// other), no robot ever ends a step inside a wall or overlapping another robot.
TEST(Motion, NoRobotEverPassesThroughAWallOrARobot) {
  core::Random rng(2024);
  int blocked = 0, steps = 0;
  for (int map = 0; map < 12; ++map) {
    const World world(testing::random_room(rng, 60, 50, 10), {});
    RobotOptions robot;
    std::vector<core::Pose2> robots;
    for (int tries = 0; robots.size() < 5 && tries < 5000; ++tries) {
      const Eigen::Vector2d p(rng.uniform(0.1, 5.9), rng.uniform(0.1, 4.9));
      if (world.disc_free(p, robot.radius_m) && clear_of_robots(-1, p, robots, robot.radius_m)) {
        robots.emplace_back(p.x(), p.y(), rng.uniform(-3.14, 3.14));
      }
    }
    ASSERT_GE(robots.size(), 2u);
    MotionNoise noise{0.01, 0.01};
    for (int k = 0; k < 300; ++k) {
      for (int i = 0; i < int(robots.size()); ++i) {
        const Command c{rng.uniform(-0.6, 0.8), rng.uniform(-2.0, 2.0)};
        const MoveResult m = move_robot(world, i, robots, robot, c, 1.0, noise, rng);
        robots[std::size_t(i)] = m.pose;
        blocked += m.blocked;
        ++steps;
        ASSERT_TRUE(world.disc_free(m.pose.position(), robot.radius_m)) << "robot " << i << " in a wall, map " << map;
        for (std::size_t j = 0; j < robots.size(); ++j) {
          if (int(j) != i) {
            ASSERT_GE((robots[j].position() - m.pose.position()).norm(), 2 * robot.radius_m) << "robots overlap";
          }
        }
      }
    }
  }
  EXPECT_GT(blocked, steps / 20) << "the random commands should run into walls and robots often";
}

// A robot does not drive into what its own map shows: a move toward a wall it knows is cut to what
// stays clear, down to turning in place; away from it, the move is whole.
TEST(Motion, CommandsKeepClearOfWhatTheRobotsMapShows) {
  auto map = testing::walled_room(40, 40);
  RobotOptions robot;
  // 0.3 m from the east wall's face (x = 3.9 m), facing it: 0.1 m is all there is.
  const Command toward = clear_on_map({0.5, 0.0}, core::Pose2(3.6, 2.0, 0.0), map, robot, 1.0);
  EXPECT_GT(toward.v, 0.0);
  EXPECT_LE(3.6 + toward.v, 3.9 - robot.radius_m);
  EXPECT_EQ(clear_on_map({0.5, 0.3}, core::Pose2(3.69, 2.0, 0.0), map, robot, 1.0).v, 0.0);  // turn in place
  EXPECT_EQ(clear_on_map({-0.3, 0.0}, core::Pose2(3.69, 2.0, 0.0), map, robot, 1.0).v, -0.3);  // backing away
  // A speck the robot found by touching it is avoided like any wall.
  auto open = testing::walled_room(40, 40);
  EXPECT_EQ(clear_on_map({0.5, 0.0}, core::Pose2(1.0, 2.0, 0.0), open, robot, 1.0).v, 0.5);
  open.set_state({15, 20}, mapping::CellState::Occupied);  // the square [1.5, 1.6] x [2.0, 2.1]
  EXPECT_LE(clear_on_map({0.5, 0.0}, core::Pose2(1.0, 2.0, 0.0), open, robot, 1.0).v, 0.3 + 1e-9);
  // A cell the robot already overlaps on its map (a short range reading's mark) does not pin it.
  open.set_state({10, 21}, mapping::CellState::Occupied);
  EXPECT_EQ(clear_on_map({-0.5, 0.0}, core::Pose2(1.05, 2.05, 0.0), open, robot, 1.0).v, -0.5);
}

// A bumper: a blocked move reports where the body touched the wall.
TEST(Motion, ABlockedMoveSaysWhereItTouchedTheWall) {
  const World world(testing::walled_room(40, 40), {});
  core::Random rng(1);
  const MoveResult m = move_robot(world, 0, {core::Pose2(3.6, 2.0, 0.0)}, RobotOptions{}, {0.5, 0.0}, 1.0, {0.0, 0.0}, rng);
  ASSERT_TRUE(m.blocked);
  ASSERT_TRUE(m.contact.has_value());
  EXPECT_NEAR(m.contact->x(), 3.9, 1e-9);  // the east wall's face
  EXPECT_NEAR(m.contact->y(), 2.0, 0.06);
  // Stopped by another robot: no wall was touched.
  const MoveResult r = move_robot(world, 0, {core::Pose2(2.0, 2.0, 0.0), core::Pose2(2.5, 2.0, 0.0)}, RobotOptions{},
                                  {0.5, 0.0}, 1.0, {0.0, 0.0}, rng);
  EXPECT_TRUE(r.blocked);
  EXPECT_FALSE(r.contact.has_value());
}

TEST(Motion, EscapeHeadsAwayFromTheWall) {
  auto map = testing::walled_room(40, 40);
  // Facing the east wall, 0.21 m from it: the escape drives backwards.
  const Command c = escape_command(core::Pose2(3.69, 2.0, 0.0), map, 1.0);
  EXPECT_LT(c.v, 0.0);
  EXPECT_EQ(c.omega, 0.0);
}

}  // namespace
}  // namespace fleetmap::sim
