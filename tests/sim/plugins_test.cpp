// A program that links fleetmap adds its own coordination strategy, localizer, path planner and
// map by name, and a scenario reaches them exactly as it reaches the built-in ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "exploration/strategy.h"
#include "localization/localizer.h"
#include "maps/builtin_maps.h"
#include "planning/planner.h"
#include "sim/scenario.h"
#include "sim/simulation.h"
#include "tests/sim/sim_test_maps.h"

namespace fleetmap::sim {
namespace {

// Every robot drives to the target with the lowest cost that no other robot took yet.
class FirstComeStrategy final : public exploration::CoordinationStrategy {
 public:
  std::string name() const override { return "first-come"; }
  bool joint() const override { return true; }
  std::vector<int> assign(const exploration::AssignmentInput& input) const override {
    std::vector<int> out(input.robots.size(), -1);
    std::vector<char> taken(input.targets.size(), 0);
    for (std::size_t r = 0; r < input.robots.size(); ++r) {
      double best = std::numeric_limits<double>::infinity();
      for (std::size_t t = 0; t < input.targets.size(); ++t) {
        const double c = input.robots[r].cost_m[t];
        if (!taken[t] && std::isfinite(c) && c < best) best = c, out[r] = int(t);
      }
      if (out[r] >= 0) taken[std::size_t(out[r])] = 1;
    }
    ++calls_;
    return out;
  }
  static inline int calls_ = 0;
};

// Dead reckoning that counts its predictions.
class CountingLocalizer final : public localization::Localizer {
 public:
  explicit CountingLocalizer(const localization::LocalizerContext& c) : pose_(c.initial_pose) {}
  std::string name() const override { return "counting"; }
  void predict(const localization::Odometry& u) override {
    pose_ = localization::integrate_motion(pose_, u);
    ++predictions_;
  }
  core::Pose2 pose() const override { return pose_; }
  Eigen::Matrix3d covariance() const override { return Eigen::Matrix3d::Zero(); }
  std::vector<std::pair<std::string, double>> counters() const override { return {{"predictions", predictions_}}; }
  void change_frame(const core::Transform2& t) override { pose_ = core::Pose2::from_transform(t * pose_.as_transform()); }

 private:
  core::Pose2 pose_;
  int predictions_ = 0;
};

TEST(Plugins, ARegisteredStrategyLocalizerPlannerAndMapRunByName) {
  exploration::register_strategy("first-come", "each robot takes the cheapest target left (a test's own)",
                                 [](const exploration::StrategyOptions&) { return std::make_unique<FirstComeStrategy>(); });
  localization::register_localizer("counting", "dead reckoning that counts (a test's own)",
                                   [](const localization::LocalizerContext& c) { return std::make_unique<CountingLocalizer>(c); });
  planning::register_planner("grid-astar-again", "the grid A*, registered again under another name",
                             {[](const core::Params&) { return planning::make_planner("astar"); }});
  maps::register_map("test-room", "a walled 8 x 6 m room", [](const io::MapLoadOptions&) { return testing::walled_room(80, 60); });

  // Everything that lists names sees them; a second registration of a name is refused.
  for (const auto& [names, name] : {std::pair{exploration::strategy_names(), std::string("first-come")},
                                    std::pair{localization::localizer_names(), std::string("counting")},
                                    std::pair{planning::planner_names(), std::string("grid-astar-again")}}) {
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  }
  EXPECT_TRUE(maps::is_builtin_map("test-room"));
  EXPECT_THROW(exploration::register_strategy("first-come", "", {}), Error);
  EXPECT_THROW(maps::register_map("office", "", {}), Error);

  // A scenario file names them like the built-in ones.
  const Scenario s = parse_scenario(R"(map: test-room
robots: 2
steps: 60
localization: counting
exploration: {strategy: first-come, path_planner: grid-astar-again}
)",
                                    "plugins.yaml", "");
  Simulation simulation(s, maps::load_map_source(s.map));
  const RunResult r = simulation.run();
  EXPECT_GT(FirstComeStrategy::calls_, 0);
  EXPECT_GT(r.coverage.back(), 0.5);
  const auto& counters = r.robots.front().localizer_counters;
  ASSERT_FALSE(counters.empty());
  EXPECT_EQ(counters.front().first, "predictions");
  EXPECT_EQ(counters.front().second, r.steps);
}

// Records the poses every assignment round gets.
class PoseRecorder final : public exploration::CoordinationStrategy {
 public:
  std::string name() const override { return "pose-recorder"; }
  bool joint() const override { return true; }
  std::vector<int> assign(const exploration::AssignmentInput& input) const override {
    std::vector<int> out(input.robots.size(), -1);
    for (std::size_t r = 0; r < input.robots.size(); ++r) {
      const auto& robot = input.robots[r];
      seen_.push_back({robot.team_index, core::Pose2(robot.position_m.x(), robot.position_m.y(), robot.heading_rad)});
      for (std::size_t t = 0; t < input.targets.size(); ++t)
        if (std::isfinite(robot.cost_m[t]) && out[r] < 0) out[r] = int(t);
    }
    return out;
  }
  static inline std::vector<std::pair<int, core::Pose2>> seen_;
};

// A strategy sees each robot's pose with its heading: the start poses first, then poses the robots
// held during the run (ideal localization: the estimates are the truth).
TEST(Plugins, AStrategyGetsTheRobotsHeadings) {
  exploration::register_strategy("pose-recorder", "records the poses it gets (a test's own)",
                                 [](const exploration::StrategyOptions&) { return std::make_unique<PoseRecorder>(); });
  Scenario s;
  s.map = "room";
  s.robot_count = 2;
  s.steps = 30;
  s.placement = Placement::List;
  s.starts = {{2.0, 2.0, 0.7}, {6.0, 4.0, -2.0}};
  s.exploration.strategy = "pose-recorder";
  const RunResult r = Simulation(s, testing::walled_room(80, 60)).run();
  const auto& seen = PoseRecorder::seen_;
  ASSERT_GE(seen.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto& [robot, pose] = seen[k];
    ASSERT_TRUE(robot == 0 || robot == 1);
    EXPECT_NEAR(pose.theta, s.starts[std::size_t(robot)].theta, 1e-9) << "robot " << robot;
  }
  bool turned = false;
  for (const auto& [robot, pose] : seen) {
    const auto& track = r.robots[std::size_t(robot)].estimate;
    const bool held = std::any_of(track.begin(), track.end(), [&](const core::Pose2& p) {
      return (p.position() - pose.position()).norm() < 1e-9 && std::abs(p.theta - pose.theta) < 1e-9;
    });
    EXPECT_TRUE(held) << "robot " << robot << " never was at " << pose.x << ", " << pose.y << ", " << pose.theta;
    turned = turned || std::abs(pose.theta - s.starts[std::size_t(robot)].theta) > 0.1;
  }
  EXPECT_TRUE(turned);
}

}  // namespace
}  // namespace fleetmap::sim
