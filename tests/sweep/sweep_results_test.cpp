#include "sweep/sweep_results.h"

#include <gtest/gtest.h>

#include <fstream>

#include "core/error.h"
#include "sweep/lower_bound.h"
#include "tests/sim/sim_test_maps.h"
#include "tests/test_support.h"

namespace fleetmap::sweep {
namespace {

using fleetmap::testing::expect_input_error;
using fleetmap::testing::TempDir;

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

RunRecord sample(const std::string& strategy, int robots, std::uint64_t seed) {
  RunRecord r;
  r.key = {"office", strategy, robots, seed, ""};
  r.localization = "ideal";
  r.comm_range_m = std::numeric_limits<double>::infinity();
  r.sensor_range_m = 4.0;
  r.step_limit = 500;
  r.settings = "0123456789abcdef";
  r.steps = 321;
  r.finished = true;
  r.coverage = 0.998765;
  r.steps_to_95 = 250;
  r.steps_to_99 = 300 + int(seed);
  r.distance_m = 123.456;
  r.redundancy = 0.25;
  r.bytes_sent = 1234567;
  r.meetings = 3;
  r.blocked_moves = 2;
  r.position_rmse_m = 0.0;
  r.lower_bound_steps = 90;
  r.lower_bound_travel_steps = 40;
  r.lower_bound_area_steps = 90;
  r.efficiency = 90.0 / r.steps_to_99.value();
  for (int k = 1; k <= kCoverageLevels; ++k) r.steps_to_percent.push_back(k < 100 ? std::optional<int>(3 * k) : std::nullopt);
  r.wall_time_s = 0.5;
  return r;
}

TEST(SweepResults, RowsRoundTrip) {
  RunRecord r = sample("market", 4, 2);
  const std::string line = format_record(r);
  EXPECT_EQ(line.find('\n'), std::string::npos);
  const RunRecord back = parse_record(line, "results.csv:2");
  EXPECT_EQ(format_record(back), line);
  EXPECT_EQ(back.key, r.key);
  EXPECT_TRUE(std::isinf(back.comm_range_m));
  EXPECT_FALSE(back.steps_to_percent.back().has_value());
  // A run that never reached 99% has empty cells for it and for its efficiency.
  r.steps_to_99.reset();
  r.efficiency.reset();
  const RunRecord unreached = parse_record(format_record(r), "results.csv:3");
  EXPECT_FALSE(unreached.steps_to_99.has_value());
  EXPECT_FALSE(unreached.efficiency.has_value());
  // Wall time is the only field left out of the comparison text.
  RunRecord slower = r;
  slower.wall_time_s = 9.0;
  EXPECT_EQ(record_without_wall_time(slower), record_without_wall_time(r));
  EXPECT_NE(format_record(slower), format_record(r));
  // Header and row have the same columns.
  const std::string header = results_header();
  EXPECT_EQ(std::count(header.begin(), header.end(), ','), std::count(line.begin(), line.end(), ','));
}

TEST(SweepResults, BadRowsNameTheLineAndColumn) {
  const std::string good = format_record(sample("market", 4, 2));
  expect_input_error([&] { parse_record(good + ",extra", "r.csv:5"); }, {"r.csv:5", "columns"});
  std::string bad = good;
  bad.replace(bad.find(",4,"), 3, ",x,");
  expect_input_error([&] { parse_record(bad, "r.csv:6"); }, {"r.csv:6", "column 'robots'", "'x'"});
  std::string levels = good.substr(0, good.rfind(',')) + ",1 2 3";
  expect_input_error([&] { parse_record(levels, "r.csv:7"); }, {"r.csv:7", "steps_to_percent"});
}

TEST(SweepResults, AppenderWritesWholeRowsAndReadsBack) {
  TempDir dir;
  const auto path = dir / "out" / "results.csv";
  {
    ResultsAppender a(path);
    a.append(sample("market", 1, 1));
    a.append(sample("market", 1, 2));
  }
  auto table = read_results(path);
  EXPECT_FALSE(table.partial_last_line);
  ASSERT_EQ(table.records.size(), 2u);
  EXPECT_EQ(table.records[1].key.seed, 2u);
  // A row cut short (as if the machine stopped mid-write) is not a row, and the next append drops it.
  { std::ofstream(path, std::ios::app) << format_record(sample("market", 1, 3)).substr(0, 40); }
  table = read_results(path);
  EXPECT_TRUE(table.partial_last_line);
  EXPECT_EQ(table.records.size(), 2u);
  {
    ResultsAppender a(path);
    a.append(sample("market", 1, 4));
  }
  table = read_results(path);
  EXPECT_FALSE(table.partial_last_line);
  ASSERT_EQ(table.records.size(), 3u);
  EXPECT_EQ(table.records[2].key.seed, 4u);
  const std::string text = slurp(path);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 4);
}

// What Python's csv module writes: CR LF line ends and True / False.
TEST(SweepResults, RowsWrittenAsPythonsCsvModuleWritesThemAreRead) {
  TempDir dir;
  const RunRecord r = sample("market", 4, 2), s = [] {
    RunRecord n = sample("market", 4, 3);
    n.finished = false;
    return n;
  }();
  std::string python = results_header() + "\r\n";
  for (const auto& record : {r, s}) {
    std::string line = format_record(record);
    for (const auto& [from, to] : {std::pair<std::string, std::string>{",true,", ",True,"}, {",false,", ",False,"}}) {
      if (const auto at = line.find(from); at != std::string::npos) line.replace(at, from.size(), to);
    }
    python += line + "\r\n";
  }
  const auto table = read_results(dir.write("python.csv", python));
  ASSERT_EQ(table.records.size(), 2u);
  EXPECT_EQ(format_record(table.records[0]), format_record(r));
  EXPECT_EQ(format_record(table.records[1]), format_record(s));
}

TEST(SweepResults, ForeignFilesAndConflictsAreRefused) {
  TempDir dir;
  const auto foreign = dir.write("foreign.csv", "a,b,c\n1,2,3\n");
  expect_input_error([&] { read_results(foreign); }, {"foreign.csv:1", "not a results table", "column 1 is 'a', expected 'map'"});
  EXPECT_THROW(ResultsAppender a(foreign), InputError);
  const std::string header = results_header() + "\n";
  RunRecord r = sample("market", 1, 1);
  const auto dup = dir.write("dup.csv", header + format_record(r) + "\n" + format_record(r) + "\n");
  EXPECT_EQ(read_results(dup).records.size(), 1u);  // the same run twice: kept once
  RunRecord other = r;
  other.steps += 1;
  const auto conflict = dir.write("conflict.csv", header + format_record(r) + "\n" + format_record(other) + "\n");
  expect_input_error([&] { read_results(conflict); }, {"conflict.csv:3", "line 2", "other results"});
  RunRecord foreign_settings = sample("market", 1, 5);
  foreign_settings.settings = "ffffffffffffffff";
  expect_input_error([&] { check_settings({r, foreign_settings}, r.settings, "x/results.csv"); },
                     {"x/results.csv", "seed 5", "other settings", "another output folder"});
}

TEST(SweepResults, SortsIntoTheSweepsOrderAndWritesAtomically) {
  Sweep sweep;
  sweep.maps = {"office"};
  sweep.strategies = {"market", "coordinated"};
  sweep.robots = {1};
  sweep.seeds = 2;
  std::vector<RunRecord> records = {sample("coordinated", 1, 2), sample("market", 1, 2), sample("stray", 3, 1),
                                    sample("coordinated", 1, 1), sample("market", 1, 1)};
  sort_records(records, sweep_runs(sweep));
  std::vector<std::string> order;
  for (const auto& r : records) order.push_back(r.key.strategy + std::to_string(r.key.seed));
  EXPECT_EQ(order, (std::vector<std::string>{"market1", "market2", "coordinated1", "coordinated2", "stray1"}));
  TempDir dir;
  write_results(dir / "results.csv", records);
  const auto back = read_results(dir / "results.csv");
  ASSERT_EQ(back.records.size(), records.size());
  for (std::size_t i = 0; i < records.size(); ++i) EXPECT_EQ(format_record(back.records[i]), format_record(records[i]));
}

TEST(SweepResults, RecordOfARealRun) {
  const auto truth = sim::testing::walled_room(200, 60);  // 20 x 6 m: more than the first scan sees
  sim::Scenario s;
  s.robot_count = 2;
  s.steps = 400;
  const sim::RunResult result = sim::Simulation(s, truth).run();
  const RunRecord r = make_record(result, sim::World(truth, {}), "room", settings_id(s), 0.25);
  EXPECT_EQ(r.key.map, "room");
  EXPECT_EQ(r.key.robots, 2);
  EXPECT_EQ(r.steps, result.steps);
  EXPECT_EQ(r.steps_to_95, result.steps_to_95);
  EXPECT_EQ(r.steps_to_99, result.steps_to_99);
  ASSERT_EQ(r.steps_to_percent.size(), std::size_t(kCoverageLevels));
  // The coverage curve levels agree with the simulator's own steps to 95% and 99%.
  EXPECT_EQ(r.steps_to_percent[94], result.steps_to_95);
  EXPECT_EQ(r.steps_to_percent[98], result.steps_to_99);
  for (std::size_t k = 1; k < r.steps_to_percent.size(); ++k) {
    if (r.steps_to_percent[k]) {
      EXPECT_LE(*r.steps_to_percent[k - 1], *r.steps_to_percent[k]);
    }
  }
  EXPECT_NEAR(coverage_at(r, 0), std::floor(result.coverage.front() * 100.0 + 1e-9) / 100.0, 1e-12);
  EXPECT_DOUBLE_EQ(coverage_at(r, r.steps + 5), result.coverage.back());
  ASSERT_TRUE(r.steps_to_99.has_value());
  EXPECT_GT(r.lower_bound_steps, 0);
  EXPECT_EQ(r.lower_bound_steps, std::max(r.lower_bound_travel_steps, r.lower_bound_area_steps));
  EXPECT_DOUBLE_EQ(*r.efficiency, double(r.lower_bound_steps) / *r.steps_to_99);
  EXPECT_DOUBLE_EQ(r.wall_time_s, 0.25);
}

}  // namespace
}  // namespace fleetmap::sweep
