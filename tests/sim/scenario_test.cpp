#include "sim/scenario.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "io/file_io.h"
#include "tests/test_support.h"

namespace fleetmap::sim {
namespace {

using fleetmap::testing::expect_input_error;

Scenario parse(const std::string& text) { return parse_scenario(text, "test.yaml", ""); }

TEST(Scenario, DefaultsWithoutKeys) {
  const Scenario s = parse("map: maze\n");
  EXPECT_EQ(s.map, "maze");
  EXPECT_EQ(s.robot_count, 4);
  EXPECT_EQ(s.placement, Placement::Cluster);
  EXPECT_EQ(s.exploration.strategy, "directional");
  EXPECT_TRUE(std::isinf(s.communication.range_m));
}

TEST(Scenario, ReadsEverySection) {
  const Scenario s = parse(R"(map: office
seed: 7
steps: 300
period: 0.5
robots:
  starts: [[1.0, 2.0, 90], [3, 4]]
  radius: 0.15
  max_speed: 0.4
noise: {position: 0.002, heading_deg: 0.5}
sensors:
  range: {angles_deg: [-90, -45, 0, 45, 90], max_range: 3, noise: 0.02}
  landmarks: {max_range: 4, report_ids: false}
  robots: {fov_deg: 120}
landmarks:
  points: [[1, 1], [2, 2]]
  along_walls: 0.2
localization: {method: odometry, robot_detections: true}
communication: {range: 0, line_of_sight: true}
exploration: {strategy: {name: optimized, beta: 2}, eight_connected: false}
merging: known
)");
  EXPECT_EQ(s.seed, 7u);
  EXPECT_EQ(s.steps, 300);
  EXPECT_DOUBLE_EQ(s.period_s, 0.5);
  ASSERT_EQ(s.placement, Placement::List);
  ASSERT_EQ(s.starts.size(), 2u);
  EXPECT_EQ(s.robot_count, 2);
  EXPECT_NEAR(s.starts[0].theta, M_PI / 2, 1e-12);
  EXPECT_DOUBLE_EQ(s.robot.radius_m, 0.15);
  EXPECT_NEAR(s.noise.heading_rad, 0.5 * M_PI / 180, 1e-15);
  EXPECT_EQ(s.range.angles_rad.size(), 5u);
  EXPECT_FALSE(s.landmark_sensor.report_ids);
  EXPECT_NEAR(s.detector.fov_rad, 2 * M_PI / 3, 1e-12);
  EXPECT_EQ(s.landmarks.size(), 2u);
  EXPECT_EQ(s.localization, "odometry");
  EXPECT_TRUE(s.localization_options.use_robot_detections);
  EXPECT_EQ(s.communication.range_m, 0.0);
  EXPECT_EQ(s.exploration.strategy, "optimized");
  EXPECT_EQ(s.exploration.strategy_settings, (exploration::StrategySettings{{"beta", "2"}}));
  EXPECT_FALSE(s.exploration.wave.eight_connected);
  EXPECT_EQ(parse("robots: {random: 6, min_separation: 1.5}\n").placement, Placement::Random);
  EXPECT_EQ(parse("robots: 9\n").robot_count, 9);
  EXPECT_EQ(parse("localization: ekf\nlandmarks: {along_walls: 0.5}\n").localization, "ekf");
}

TEST(Scenario, RoundTripsThroughYaml) {
  fleetmap::testing::TempDir dir;
  const Scenario a = parse(R"(map: cave
robots: {starts: [[1.5, 2.5, 30], [2.5, 2.5, -60]]}
sensors: {range: {angles_deg: [0, 90]}}
landmarks: {points: [[1, 2]], along_walls: 0.3}
communication: {range: 12.5}
exploration: {strategy: market}
)");
  // A strategy's settings survive a round trip.
  const Scenario c = parse("exploration: {strategy: {name: directional, weight: 0.25}}\n");
  EXPECT_EQ(parse(scenario_to_yaml(c)).exploration.strategy_settings, c.exploration.strategy_settings);
  const std::string text = scenario_to_yaml(a);
  io::write_file_atomic(dir / "s.yaml", text);
  const Scenario b = load_scenario(dir / "s.yaml");
  EXPECT_EQ(scenario_to_yaml(b), text);
  EXPECT_EQ(b.starts.size(), 2u);
  EXPECT_NEAR(b.starts[1].theta, a.starts[1].theta, 1e-12);
  EXPECT_EQ(b.exploration.strategy, "market");
  EXPECT_DOUBLE_EQ(b.communication.range_m, 12.5);
  // Unlimited range survives as "inf".
  EXPECT_TRUE(std::isinf(parse(scenario_to_yaml(parse("map: maze\n"))).communication.range_m));
}

// Found by fuzz_scenario: a map name with a line break came back with a space instead (YAML folds
// line breaks in quoted scalars), so a saved scenario named another map.
TEST(Scenario, MapNamesWithControlCharactersAndQuotesRoundTrip) {
  Scenario a;
  a.map = "two\nlines\tand \"quotes\" \\ \x01";
  const Scenario b = parse(scenario_to_yaml(a));
  EXPECT_EQ(b.map, a.map);
  EXPECT_EQ(scenario_to_yaml(b), scenario_to_yaml(a));
}

TEST(ScenarioBadInput, ErrorsNameTheKeyAndTheLine) {
  expect_input_error([] { parse("map: office\nrobtos: 3\n"); }, {"test.yaml:2", "unknown key 'robtos'", "robots"});
  expect_input_error([] { parse("robots:\n  count: 0\n"); }, {"test.yaml:2", "'robots.count'", "got '0'"});
  expect_input_error([] { parse("robots: {count: 3, random: 2}\n"); }, {"only one of"});
  expect_input_error([] { parse("noise: {position: -0.1}\n"); }, {"'noise.position'", ">= 0", "-0.1"});
  expect_input_error([] { parse("sensors:\n  range:\n    max_range: -2\n"); }, {"test.yaml:3", "'sensors.range.max_range'"});
  expect_input_error([] { parse("communication: {range: far}\n"); }, {"'communication.range'", "far", "inf"});
  expect_input_error([] { parse("communication: {range: -1}\n"); }, {"'communication.range'", "-1"});
  expect_input_error([] { parse("exploration: {strategy: greedy}\n"); },
                     {"'exploration.strategy'", "greedy", "uncoordinated", "market"});
  // A strategy's own parameters are checked against its declaration.
  expect_input_error([] { parse("exploration:\n  strategy: {name: coordinated, bta: 2}\n"); },
                     {"test.yaml:2", "'exploration.strategy.bta'", "strategy 'coordinated' has no parameter 'bta'",
                      "did you mean 'beta'"});
  expect_input_error([] { parse("exploration: {strategy: {name: coordinated, beta: -1}}\n"); },
                     {"'exploration.strategy.beta'", ">= 0", "got '-1'"});
  expect_input_error([] { parse("exploration: {strategy: {name: market, beta: 1}}\n"); }, {"'market' has no parameter 'beta'", "it has none"});
  // The keys of before each strategy declared its own say where they went.
  expect_input_error([] { parse("exploration: {strategy: optimized, beta: 2}\n"); },
                     {"'exploration.beta'", "strategy: {name: optimized, beta: 2}"});
  expect_input_error([] { parse("exploration: {directional_weight: 0.3}\n"); },
                     {"'exploration.directional_weight'", "strategy: {name: directional, weight: 0.3}"});
  expect_input_error([] { parse("localization: gps\n"); }, {"localization", "gps", "ideal", "odometry"});
  expect_input_error([] { parse("robots: {starts: [[1, 2], [3]]}\n"); }, {"'robots.starts'", "[x, y]"});
  expect_input_error([] { parse("steps: many\n"); }, {"'steps'", "many"});
  expect_input_error([] { parse("exploration: [1, 2]\n"); }, {"'exploration'", "mapping"});
  expect_input_error([] { parse("map: [unclosed\n"); }, {"test.yaml", "not valid YAML"});
  expect_input_error([] { parse(""); }, {"test.yaml", "empty"});
  fleetmap::testing::TempDir dir;
  expect_input_error([&] { load_scenario(dir / "nope.yaml"); }, {"nope.yaml", "no such file"});
}

}  // namespace
}  // namespace fleetmap::sim

namespace fleetmap::sim {
namespace {

// The README documents every scenario key with its default: that block must parse, and give the
// defaults.
TEST(Scenario, TheReadmeExampleParsesToTheDefaults) {
  const std::string readme = io::read_file(std::filesystem::path(FLEETMAP_SOURCE_DIR) / "README.md");
  const auto section = readme.find("### Scenario files");
  ASSERT_NE(section, std::string::npos);
  const auto begin = readme.find("```yaml\n", section);
  ASSERT_NE(begin, std::string::npos);
  const auto end = readme.find("```", begin + 8);
  const Scenario s = parse_scenario(readme.substr(begin + 8, end - begin - 8), "README.md", "");
  EXPECT_EQ(scenario_to_yaml(s), scenario_to_yaml(parse_scenario("map: office\n", "defaults", "")));
}

}  // namespace
}  // namespace fleetmap::sim
