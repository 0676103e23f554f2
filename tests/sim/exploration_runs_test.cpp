// The exploration acceptance check: every strategy explores every built-in 200x200 map with 1, 2, 4 and
// 9 robots to at least 99% of the observable space, and the team notices it is done.
#include <gtest/gtest.h>

#include "exploration/strategy.h"
#include "maps/builtin_maps.h"
#include "sim/simulation.h"

namespace fleetmap::sim {
namespace {

using Param = std::tuple<std::string, std::string>;

class EveryStrategyEveryMap : public ::testing::TestWithParam<Param> {};

TEST_P(EveryStrategyEveryMap, ExploresAtLeast99Percent) {
  const auto& [strategy, map] = GetParam();
  const auto grid = maps::load_map_source(map);
  for (const int robots : {1, 2, 4, 9}) {
    Scenario s;
    s.map = map;
    s.robot_count = robots;
    s.exploration.strategy = strategy;
    const RunResult r = Simulation(s, grid).run();
    EXPECT_GE(r.coverage.back(), 0.99) << robots << " robots";
    EXPECT_TRUE(r.steps_to_99.has_value()) << robots << " robots";
    EXPECT_TRUE(r.finished) << robots << " robots ran to the step limit";
  }
}

INSTANTIATE_TEST_SUITE_P(All, EveryStrategyEveryMap,
                         ::testing::Combine(::testing::ValuesIn(exploration::strategy_names()),
                                            ::testing::Values("empty", "unstructured", "office", "corridor", "cave",
                                                              "maze")),
                         [](const ::testing::TestParamInfo<Param>& info) {
                           return std::get<0>(info.param) + "_" + std::get<1>(info.param);
                         });

}  // namespace
}  // namespace fleetmap::sim
