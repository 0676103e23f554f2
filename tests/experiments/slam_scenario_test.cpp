#include "experiments/slam_scenario.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/angle.h"
#include "experiments/slam_experiment.h"
#include "localization/polynomial_slam.h"
#include "tests/test_support.h"

namespace fleetmap::experiments {
namespace {

using fleetmap::testing::expect_input_error;

constexpr const char* kMinimal = R"(
room:
  boundary: [[0, 0], [4, 0], [4, 3], [0, 3]]
robots:
  team:
    - {name: a, start: [1, 1, 0], path: [[3, 1]]}
)";

TEST(SlamScenario, TheDalfonsoScenarioHasThePapersParameters) {
  const SlamScenario s = load_slam_scenario(std::string(FLEETMAP_SOURCE_DIR) + "/scenarios/dalfonso_3robots.yaml");
  EXPECT_EQ(s.method, "polynomial");
  EXPECT_EQ(s.runs, 100);
  EXPECT_EQ(s.steps, 200);
  EXPECT_DOUBLE_EQ(s.period_s, 1.0);
  ASSERT_EQ(s.robots.size(), 3u);
  EXPECT_EQ(s.robots[2].name, "r3");
  EXPECT_EQ(s.single_robot, "r3");
  EXPECT_EQ(s.range.angles_rad.size(), 5u);  // five distance sensors
  EXPECT_DOUBLE_EQ(s.range.noise_m, 0.02);
  EXPECT_DOUBLE_EQ(s.noise.position_m, 0.001);
  EXPECT_NEAR(s.noise.heading_rad, core::deg2rad(0.01), 1e-15);
  EXPECT_DOUBLE_EQ(s.initial_sigma_xy, 0.05);
  EXPECT_DOUBLE_EQ(s.initial_sigma_heading, 0.0175);
  const auto p = localization::polynomial_slam_options(slam_method_options(s.method, s.method_settings), s.range.noise_m);
  EXPECT_EQ(p.order, 3);
  EXPECT_DOUBLE_EQ(p.rho_min, 0.08);
  EXPECT_DOUBLE_EQ(p.rho_max, 0.24);
  EXPECT_DOUBLE_EQ(p.sigma_min, 0.1);
  EXPECT_DOUBLE_EQ(p.sigma_max, 0.3);
  EXPECT_EQ(p.epsilon_m, 5);
  EXPECT_EQ(p.epsilon_z, 10);
  EXPECT_DOUBLE_EQ(p.k, 150.0);
  EXPECT_DOUBLE_EQ(p.cluster_radius, 0.35);
  EXPECT_DOUBLE_EQ(p.gamma_m, 0.35);
  EXPECT_DOUBLE_EQ(p.range_noise, 0.02);
  EXPECT_GE(room_walls(s.room).size(), 24u);
}

TEST(SlamScenario, DefaultsFillAMinimalScenario) {
  const SlamScenario s = parse_slam_scenario(kMinimal, "min.yaml");
  EXPECT_EQ(s.method, "polynomial");
  EXPECT_EQ(s.runs, 100);
  EXPECT_EQ(s.robots[0].path.size(), 1u);
  EXPECT_EQ(s.range.angles_rad.size(), 5u);
  EXPECT_EQ(room_walls(s.room).size(), 4u);
  // D'Alfonso et al.'s filter unless asked: c_0 only, the estimate starting at the truth.
  const auto options = [](const SlamScenario& scenario) {
    return localization::polynomial_slam_options(slam_method_options(scenario.method, scenario.method_settings), 0.02);
  };
  EXPECT_TRUE(s.method_settings.empty());
  EXPECT_FALSE(options(s).shape_in_state);
  EXPECT_FALSE(options(s).first_estimate_jacobians);
  EXPECT_FALSE(s.sampled_start);
  const SlamScenario t = parse_slam_scenario(
      std::string(kMinimal) + "initial_sigma: {sampled: true}\npolynomial: {shape_in_state: true, first_estimate_jacobians: true, min_merge_length: 0.2, feature_noise: 1.0e-6}\n",
      "min.yaml");
  EXPECT_TRUE(t.sampled_start);
  EXPECT_TRUE(options(t).shape_in_state);
  EXPECT_TRUE(options(t).first_estimate_jacobians);
  EXPECT_DOUBLE_EQ(options(t).min_merge_length, 0.2);
  EXPECT_DOUBLE_EQ(options(t).feature_noise, 1e-6);
}

TEST(SlamScenario, ThePolynomialMethodsParametersAreItsDeclaredOnes) {
  // Every declared default is PolynomialSlamOptions' own, so a scenario without them runs as before.
  const localization::PolynomialSlamOptions d;
  const auto p = localization::polynomial_slam_options(slam_method_options("polynomial"), d.range_noise);
  EXPECT_EQ(p.order, d.order);
  EXPECT_EQ(p.rho_min, d.rho_min);
  EXPECT_EQ(p.sigma_max, d.sigma_max);
  EXPECT_EQ(p.epsilon_z, d.epsilon_z);
  EXPECT_EQ(p.merge_max_angle, d.merge_max_angle);
  EXPECT_EQ(p.cluster_tolerance, d.cluster_tolerance);
  EXPECT_EQ(p.shape_noise, d.shape_noise);
  EXPECT_EQ(p.lowest_order, d.lowest_order);
  // The same values three ways: the method's mapping, its own block, and the older pair form.
  const auto read = [](const std::string& extra) {
    const SlamScenario s = parse_slam_scenario(std::string(kMinimal) + extra, "min.yaml");
    return localization::polynomial_slam_options(slam_method_options(s.method, s.method_settings), 0.02);
  };
  for (const auto& extra : {std::string("method: {name: polynomial, order: 2, rho_min: 0.1, rho_max: 0.2}\n"),
                            std::string("polynomial: {order: 2, rho_min: 0.1, rho_max: 0.2}\n"),
                            std::string("polynomial: {order: 2, rho: [0.1, 0.2]}\n")}) {
    const auto o = read(extra);
    EXPECT_EQ(o.order, 2) << extra;
    EXPECT_DOUBLE_EQ(o.rho_min, 0.1) << extra;
    EXPECT_DOUBLE_EQ(o.rho_max, 0.2) << extra;
  }
  // Values each within range but not together: named with the file.
  expect_input_error([&] { parse_slam_scenario(std::string(kMinimal) + "polynomial: {rho_min: 0.3, rho_max: 0.2}\n", "s.yaml"); },
                     {"s.yaml", "rho_max"});
  expect_input_error([&] { parse_slam_scenario(std::string(kMinimal) + "polynomial: {ordre: 2}\n", "s.yaml"); },
                     {"s.yaml", "ordre", "order"});
}

TEST(SlamScenario, BadInputNamesTheFileAndKey) {
  const auto with = [](const std::string& extra) { return std::string(kMinimal) + extra; };
  expect_input_error([&] { parse_slam_scenario(with("method: grid\n"), "s.yaml"); }, {"s.yaml", "method", "grid", "polynomial"});
  expect_input_error([&] { parse_slam_scenario(with("colour: red\n"), "s.yaml"); }, {"s.yaml", "colour"});
  expect_input_error([&] { parse_slam_scenario(with("steps: 0\n"), "s.yaml"); }, {"steps"});
  expect_input_error([&] { parse_slam_scenario(with("polynomial: {rho: [0.3, 0.1]}\n"), "s.yaml"); }, {"polynomial.rho"});
  expect_input_error([&] { parse_slam_scenario(with("polynomial: {epsilon_z: 0}\n"), "s.yaml"); }, {"epsilon_z"});
  expect_input_error([&] { parse_slam_scenario(with("polynomial: {feature_noise: -1}\n"), "s.yaml"); }, {"feature_noise"});
  expect_input_error([&] { parse_slam_scenario(with("single_robot: zz\n"), "s.yaml"); }, {"single_robot", "zz"});
  expect_input_error([&] { parse_slam_scenario("room: {boundary: [[0, 0], [1, 0]]}\nrobots: {team: []}\n", "s.yaml"); },
                     {"room.boundary"});
  expect_input_error([&] { parse_slam_scenario("room: {boundary: [[0, 0], [4, 0], [4, 3]]}\n", "s.yaml"); }, {"robots.team"});
  expect_input_error(
      [&] {
        parse_slam_scenario(
            "room: {boundary: [[0, 0], [4, 0], [4, 3]]}\nrobots: {team: [{name: a, start: [1, 1, 0], path: [[2, 1]]}, "
            "{name: a, start: [2, 1, 0], path: [[3, 1]]}]}\n",
            "s.yaml");
      },
      {"named 'a'"});
  expect_input_error([&] { parse_slam_scenario("room: {boundary: [[0, 0], [4, x], [4, 3]]}\n", "s.yaml"); }, {"room.boundary"});
}

}  // namespace
}  // namespace fleetmap::experiments
