#include "sweep/sweep.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "core/error.h"
#include "tests/test_support.h"

namespace fleetmap::sweep {
namespace {

using fleetmap::testing::expect_input_error;
using fleetmap::testing::TempDir;

TEST(Sweep, DefaultIsTheIssuesSweepInAFixedOrder) {
  const Sweep sweep;
  const auto runs = sweep_runs(sweep);
  ASSERT_EQ(runs.size(), 4u * exploration::strategy_names().size() * 4u * 20u);
  EXPECT_EQ(runs.front().map, "empty");
  EXPECT_EQ(runs.front().strategy, exploration::strategy_names().front());
  EXPECT_EQ(runs.front().robots, 1);
  EXPECT_EQ(runs.front().seed, 1u);
  EXPECT_EQ(runs[1].seed, 2u);          // seeds vary fastest
  EXPECT_EQ(runs[20].robots, 2);        // then team sizes
  EXPECT_EQ(runs.back().map, "corridor");
  EXPECT_EQ(runs.back().robots, 9);
  EXPECT_EQ(runs.back().seed, 20u);
  std::set<std::tuple<std::string, std::string, int, std::uint64_t>> keys;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    EXPECT_EQ(runs[i].index, i);
    keys.insert({runs[i].map, runs[i].strategy, runs[i].robots, runs[i].seed});
  }
  EXPECT_EQ(keys.size(), runs.size());
  const sim::Scenario s = run_scenario(sweep, runs[123]);
  EXPECT_EQ(s.map, runs[123].map_source);
  EXPECT_EQ(s.exploration.strategy, runs[123].strategy);
  EXPECT_EQ(s.robot_count, runs[123].robots);
  EXPECT_EQ(s.seed, runs[123].seed);
}

TEST(Sweep, ShardsPartitionTheRuns) {
  Sweep sweep;
  sweep.maps = {"empty", "office"};
  sweep.robots = {1, 2, 3};
  sweep.seeds = 3;
  const auto runs = sweep_runs(sweep);
  for (int n = 1; n <= 7; ++n) {
    std::vector<std::size_t> seen;
    std::size_t smallest = runs.size(), largest = 0;
    for (int k = 1; k <= n; ++k) {
      const auto part = shard_runs(runs, {k, n});
      smallest = std::min(smallest, part.size());
      largest = std::max(largest, part.size());
      for (const auto& r : part) seen.push_back(r.index);
    }
    std::sort(seen.begin(), seen.end());
    ASSERT_EQ(seen.size(), runs.size()) << n << " shards";
    for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], i);
    EXPECT_LE(largest - smallest, 1u) << n << " shards";
  }
}

TEST(Sweep, ListsFromFlags) {
  EXPECT_EQ(parse_team_sizes("1,2,4,9", "--robots"), (std::vector<int>{1, 2, 4, 9}));
  EXPECT_EQ(parse_team_sizes("1-4", "--robots"), (std::vector<int>{1, 2, 3, 4}));
  EXPECT_EQ(parse_team_sizes(" 2, 5-6 ", "--robots"), (std::vector<int>{2, 5, 6}));
  for (const char* bad : {"0", "a", "65", "2.5", "-3"}) {
    expect_input_error([&] { parse_team_sizes(bad, "--robots"); }, {"--robots", std::string("team size '") + bad + "'"});
  }
  expect_input_error([] { parse_team_sizes("1,a", "--robots"); }, {"--robots", "team size 'a'"});
  expect_input_error([] { parse_team_sizes("4-2", "--robots"); }, {"--robots", "backwards"});
  expect_input_error([] { parse_team_sizes("1,,2", "--robots"); }, {"--robots", "empty item"});
  expect_input_error([] { parse_team_sizes("1,2,1", "--robots"); }, {"--robots", "twice"});
  EXPECT_EQ(parse_strategy_list("all", "--strategies"), exploration::strategy_names());
  EXPECT_EQ(parse_strategy_list("coordinated,uncoordinated", "--strategies"),
            (std::vector<std::string>{"coordinated", "uncoordinated"}));
  expect_input_error([] { parse_strategy_list("coordinated,greedy", "--strategies"); },
                     {"--strategies", "unknown strategy 'greedy'", "uncoordinated"});
  expect_input_error([] { parse_strategy_list("coordinated,uncordinated", "--strategies"); },
                     {"--strategies: unknown strategy 'uncordinated' (did you mean 'uncoordinated'?) (valid: "});
  expect_input_error([] { parse_strategy_list("all,tour", "--strategies"); }, {"--strategies: 'all' stands alone"});
  EXPECT_EQ(parse_map_list("office, maps/lab.png", "--maps"), (std::vector<std::string>{"office", "maps/lab.png"}));
  EXPECT_EQ(map_label("maps/lab.png"), "lab");
  EXPECT_EQ(map_label("office"), "office");
  EXPECT_TRUE(std::isinf(parse_comm_range("inf", "--comm-range")));
  EXPECT_DOUBLE_EQ(parse_comm_range("12.5", "--comm-range"), 12.5);
  expect_input_error([] { parse_comm_range("-1", "--comm-range"); }, {"--comm-range", "'-1'"});
}

TEST(Sweep, SweepFileWithEveryKey) {
  TempDir dir;
  dir.write("base.yaml", "steps: 700\nrobots: {starts: [[2, 2], [3, 2]]}\nsensors: {range: {max_range: 5}}\n");
  const auto path = dir.write("sweep.yaml",
                              "maps: [office, cave]\n"
                              "strategies: coordinated, market\n"
                              "robots: 1-3\n"
                              "seeds: 4\n"
                              "first_seed: 10\n"
                              "scenario: base.yaml\n"
                              "localization: odometry\n"
                              "merging: rendezvous\n"
                              "comm_range: 15\n");
  const Sweep s = load_sweep(path);
  EXPECT_EQ(s.maps, (std::vector<std::string>{"office", "cave"}));
  EXPECT_EQ(s.strategies, (std::vector<std::string>{"coordinated", "market"}));
  EXPECT_EQ(s.robots, (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(s.seeds, 4);
  EXPECT_EQ(s.first_seed, 10u);
  EXPECT_EQ(s.base.steps, 700);
  EXPECT_DOUBLE_EQ(s.base.range.max_range_m, 5.0);
  EXPECT_EQ(s.base.placement, sim::Placement::Cluster);  // listed starts become a cluster of each team size
  EXPECT_EQ(s.base.localization, "odometry");
  EXPECT_EQ(s.base.merging, "rendezvous");
  EXPECT_DOUBLE_EQ(s.base.communication.range_m, 15.0);
  const auto runs = sweep_runs(s);
  ASSERT_EQ(runs.size(), 2u * 2u * 3u * 4u);
  EXPECT_EQ(runs.front().seed, 10u);
}

TEST(Sweep, SweepFileErrorsNameTheFileLineAndKey) {
  TempDir dir;
  expect_input_error([&] { load_sweep(dir.write("a.yaml", "maps: [office]\nrobot: 4\n")); }, {"a.yaml", "robot"});
  expect_input_error([&] { load_sweep(dir.write("b.yaml", "maps: [office]\nstrategies: [fastest]\n")); },
                     {"b.yaml:2", "strategies", "unknown strategy 'fastest'"});
  expect_input_error([&] { load_sweep(dir.write("c.yaml", "robots: [1, 0]\n")); }, {"c.yaml:1", "robots", "team size '0'"});
  expect_input_error([&] { load_sweep(dir.write("d.yaml", "seeds: 0\n")); }, {"d.yaml:1", "seeds"});
  expect_input_error([&] { load_sweep(dir.write("e.yaml", "scenario: missing.yaml\n")); }, {"e.yaml:1", "missing.yaml"});
  expect_input_error([&] { load_sweep(dir.write("f.yaml", "maps: [office, office]\n")); }, {"f.yaml", "'office' is listed twice"});
  expect_input_error([&] { load_sweep(dir.write("g.yaml", "maps: [a/lab.png, b/lab.png]\n")); }, {"g.yaml", "two maps are named 'lab'"});
  expect_input_error([&] { load_sweep(dir.write("h.yaml", "maps: {office: 1}\n")); }, {"h.yaml:1", "maps", "expected a list"});
  expect_input_error([&] { load_sweep(dir.write("i.yaml", "localization: psychic\n")); }, {"i.yaml", "localization", "psychic"});
  expect_input_error([&] { load_sweep(dir.write("j.yaml", "merging: telepathy\n")); }, {"j.yaml:1", "merging", "telepathy"});
  // A mistyped strategy or setting gets the nearest name.
  expect_input_error([&] { load_sweep(dir.write("k.yaml", "strategies: [coordinated, uncordinated]\n")); },
                     {"k.yaml:1: key 'strategies': unknown strategy 'uncordinated' (did you mean 'uncoordinated'?)"});
  expect_input_error([&] { load_sweep(dir.write("l.yaml", "strategies: [all, tour]\n")); }, {"l.yaml:1", "'all' stands alone"});
  expect_input_error([&] { load_sweep(dir.write("m.yaml", "vary:\n  comm_rnage: [5, inf]\n")); },
                     {"m.yaml:2: key 'vary.comm_rnage': unknown setting 'comm_rnage' (did you mean 'comm_range'?)"});
}

TEST(Sweep, ReadySweepFiles) {
  const std::string dir = std::string(FLEETMAP_SOURCE_DIR) + "/scenarios/sweeps/";
  const Sweep wave_paper = load_sweep(dir + "wave_paper.yaml");
  EXPECT_EQ(wave_paper.maps, (std::vector<std::string>{"empty", "unstructured", "office", "corridor"}));
  EXPECT_EQ(wave_paper.strategies, exploration::strategy_names());
  EXPECT_EQ(wave_paper.robots, (std::vector<int>{9}));
  EXPECT_EQ(wave_paper.seeds, 20);
  EXPECT_EQ(wave_paper.base.steps, 2000);
  EXPECT_TRUE(std::isinf(wave_paper.base.communication.range_m));
  EXPECT_DOUBLE_EQ(wave_paper.base.range.max_range_m, 4.0);
  const Sweep burgard = load_sweep(dir + "burgard.yaml");
  EXPECT_EQ(burgard.strategies, (std::vector<std::string>{"coordinated", "uncoordinated"}));
  EXPECT_EQ(burgard.robots, (std::vector<int>{1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(sweep_runs(burgard).size(), burgard.maps.size() * 2u * 9u * std::size_t(burgard.seeds));
}

TEST(Sweep, SettingsIdIgnoresOnlyWhatTheSweepVaries) {
  const sim::Scenario base;
  sim::Scenario varied = base;
  varied.map = "cave";
  varied.exploration.strategy = "market";
  varied.robot_count = 7;
  varied.seed = 99;
  EXPECT_EQ(settings_id(base), settings_id(varied));
  EXPECT_EQ(settings_id(base).size(), 16u);
  sim::Scenario steps = base;
  steps.steps = 1999;
  EXPECT_NE(settings_id(base), settings_id(steps));
  sim::Scenario range = base;
  range.range.max_range_m = 3.0;
  EXPECT_NE(settings_id(base), settings_id(range));
  sim::Scenario comm = base;
  comm.communication.range_m = 10.0;
  EXPECT_NE(settings_id(base), settings_id(comm));
}

TEST(Sweep, WrittenSweepLoadsBackToTheSameRuns) {
  TempDir dir;
  Sweep s;
  s.maps = {"office", "maze"};
  s.strategies = {"market", "directional"};
  s.robots = {3, 5};
  s.seeds = 2;
  s.first_seed = 7;
  s.base.steps = 321;
  s.base.communication.range_m = 8.5;
  s.base.merging = "rendezvous";
  dir.write("scenario.yaml", sim::scenario_to_yaml(s.base));
  const Sweep back = load_sweep(dir.write("sweep.yaml", sweep_to_yaml(s, "scenario.yaml")));
  const auto a = sweep_runs(s), b = sweep_runs(back);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].map, b[i].map);
    EXPECT_EQ(a[i].strategy, b[i].strategy);
    EXPECT_EQ(a[i].robots, b[i].robots);
    EXPECT_EQ(a[i].seed, b[i].seed);
  }
  EXPECT_EQ(back.base.merging, "rendezvous");
  EXPECT_EQ(settings_id(s.base), settings_id(back.base));
}

TEST(Sweep, AMapNameTooLongForTheFileSystemIsJustAName) {
  // Found by fuzzing: asking the file system about a 5000-character name threw instead of answering.
  const std::string name = "maps/" + std::string(5000, 'x') + ".png";
  const Sweep s = parse_sweep("maps: [\"" + name + "\"]\n", "long.yaml", "/nonexistent");
  EXPECT_NE(sweep_to_yaml(s, "").find(std::string(5000, 'x')), std::string::npos);
}

}  // namespace
}  // namespace fleetmap::sweep

namespace fleetmap::sweep {
namespace {

using fleetmap::testing::expect_input_error;
using fleetmap::testing::TempDir;

TEST(SweepAxes, AnyScenarioSettingIsAnAxisInEveryCombination) {
  Sweep s;
  s.maps = {"office"};
  s.strategies = {"coordinated"};
  s.robots = {2};
  s.seeds = 2;
  s.axes = {parse_axis("beams=45,360", "--vary"), parse_axis("communication.range=5,inf", "--vary")};
  EXPECT_EQ(s.axes[0].scenario_key, "sensors.range.beams");
  validate_sweep(s);
  const auto runs = sweep_runs(s);
  ASSERT_EQ(runs.size(), 2u * 2u * 2u);
  // The first axis slowest, the seed fastest.
  EXPECT_EQ(runs[0].variant, "beams=45 communication.range=5");
  EXPECT_EQ(runs[1].variant, "beams=45 communication.range=5");
  EXPECT_EQ(runs[2].variant, "beams=45 communication.range=inf");
  EXPECT_EQ(runs[4].variant, "beams=360 communication.range=5");
  const sim::Scenario a = run_scenario(s, runs[0]);
  EXPECT_EQ(a.range.beams, 45);
  EXPECT_DOUBLE_EQ(a.communication.range_m, 5.0);
  EXPECT_EQ(a.exploration.strategy, "coordinated");
  EXPECT_EQ(a.robot_count, 2);
  const sim::Scenario b = run_scenario(s, runs[6]);
  EXPECT_EQ(b.range.beams, 360);
  EXPECT_TRUE(std::isinf(b.communication.range_m));
  // Everything else is the base's.
  EXPECT_EQ(b.steps, s.base.steps);
  EXPECT_EQ(b.localization, s.base.localization);
}

TEST(SweepAxes, BadAxesAreRefusedBeforeAnyRun) {
  Sweep s;
  s.maps = {"office"};
  expect_input_error([] { parse_axis("beams", "--vary beams"); }, {"--vary beams", "SETTING=VALUE"});
  expect_input_error([] { parse_axis("robots=2,4", "--vary"); }, {"'robots' is an axis of every sweep already"});
  expect_input_error([] { parse_axis("robots.count=2,4", "--vary"); }, {"already"});
  // The robots' size is a setting like any other: a sweep over it is valid.
  s.axes = {parse_axis("robots.radius=0.15,0.25", "--vary")};
  EXPECT_NO_THROW(validate_sweep(s));
  s.axes.clear();
  expect_input_error([] { parse_axis("strategy=market", "--vary"); }, {"already"});
  expect_input_error([] { parse_axis("beams=90,90", "--vary"); }, {"'90' is listed twice"});
  expect_input_error([] { parse_axis("beams=90,", "--vary"); }, {"empty item"});
  // A value the scenario refuses, or a key it does not know, names the axis and the key.
  s.axes = {parse_axis("beams=90,0", "--vary")};
  expect_input_error([&] { validate_sweep(s); }, {"axis beams=0", "sensors.range.beams", "1 to 100000"});
  // A setting no scenario has: the nearest short name or scenario key suggested, the short names listed.
  expect_input_error([] { parse_axis("sensors.range.beam=90", "--vary"); },
                     {"--vary: unknown setting 'sensors.range.beam' (did you mean 'sensors.range.beams'?)",
                      "(valid: beams, sensor_range, comm_range, localization, merging, path_planner, steps, noise_position, or "});
  expect_input_error([] { parse_axis("beam=45,360", "--vary"); }, {"unknown setting 'beam' (did you mean 'beams'?)"});
  expect_input_error([] { parse_axis("noise_positon=0.1", "--vary"); }, {"(did you mean 'noise_position'?)"});
  expect_input_error([] { parse_axis("sensors=1", "--vary"); }, {"unknown setting 'sensors'"});
  EXPECT_EQ(parse_axis("exploration.safety_margin=0.1,0.2", "--vary").scenario_key, "exploration.safety_margin");
  s.axes = {parse_axis("localization=odometry,magic", "--vary")};
  expect_input_error([&] { validate_sweep(s); }, {"axis localization=magic", "magic"});
  s.axes = {parse_axis("beams=90", "--vary"), parse_axis("sensors.range.beams=45", "--vary")};
  expect_input_error([&] { validate_sweep(s); }, {"vary", "listed twice"});
}

TEST(SweepAxes, SweepFileVaryAndItsWrittenCopy) {
  TempDir dir;
  const Sweep s = load_sweep(dir.write("s.yaml",
                                       "maps: [office]\nstrategies: [market]\nrobots: [3]\nseeds: 1\n"
                                       "vary:\n  merging: [known, rendezvous]\n  noise_position: '0.01,0.05'\n"));
  ASSERT_EQ(s.axes.size(), 2u);
  EXPECT_EQ(s.axes[0].values, (std::vector<std::string>{"known", "rendezvous"}));
  EXPECT_EQ(s.axes[1].scenario_key, "noise.position");
  const Sweep back = load_sweep(dir.write("back.yaml", sweep_to_yaml(s, "")));
  const auto a = sweep_runs(s), b = sweep_runs(back);
  ASSERT_EQ(a.size(), 4u);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].variant, b[i].variant);
  EXPECT_DOUBLE_EQ(run_scenario(s, a[3]).noise.position_m, 0.05);
  EXPECT_EQ(run_scenario(s, a[3]).merging, "rendezvous");
  expect_input_error([&] { load_sweep(dir.write("bad.yaml", "vary: [beams]\n")); }, {"bad.yaml:1", "vary"});
  expect_input_error([&] { load_sweep(dir.write("bad2.yaml", "vary:\n  beams: {a: 1}\n")); }, {"bad2.yaml:2", "vary.beams"});
}

TEST(SweepAxes, VariantLabels) {
  EXPECT_EQ(variant_value("beams=90 comm_range=inf", "comm_range"), "inf");
  EXPECT_EQ(variant_value("beams=90 comm_range=inf", "beam"), std::nullopt);
  EXPECT_EQ(variant_without("beams=90 comm_range=inf", "beams"), "comm_range=inf");
  EXPECT_EQ(variant_without("beams=90", "beams"), "");
}

}  // namespace
}  // namespace fleetmap::sweep
