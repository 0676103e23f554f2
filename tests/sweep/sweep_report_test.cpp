#include "sweep/sweep_report.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "core/error.h"
#include "tests/test_support.h"

namespace fleetmap::sweep {
namespace {

using fleetmap::testing::expect_input_error;

// A record whose steps to 99% and distance are given; the coverage curve rises linearly to 99%.
RunRecord record(const std::string& map, const std::string& strategy, int robots, std::uint64_t seed,
                 std::optional<int> steps_to_99, double distance_m) {
  RunRecord r;
  r.key = {map, strategy, robots, seed, ""};
  r.localization = "ideal";
  r.comm_range_m = std::numeric_limits<double>::infinity();
  r.sensor_range_m = 4.0;
  r.step_limit = 1000;
  r.settings = "0123456789abcdef";
  r.steps = steps_to_99 ? *steps_to_99 + 5 : 1000;
  r.finished = steps_to_99.has_value();
  r.coverage = steps_to_99 ? 0.995 : 0.9;
  r.steps_to_95 = steps_to_99 ? std::optional<int>(*steps_to_99 - 10) : std::optional<int>(900);
  r.steps_to_99 = steps_to_99;
  r.distance_m = distance_m;
  r.redundancy = 0.1 * robots;
  r.bytes_sent = 1000 * robots;
  r.lower_bound_steps = r.lower_bound_area_steps = 50;
  r.efficiency = steps_to_99 ? std::optional<double>(50.0 / *steps_to_99) : std::nullopt;
  const int end = steps_to_99.value_or(1000);
  for (int k = 1; k <= kCoverageLevels; ++k) {
    r.steps_to_percent.push_back(k <= 99 && (steps_to_99 || k <= 90) ? std::optional<int>(end * k / 99) : std::nullopt);
  }
  return r;
}

std::vector<RunRecord> sample_records() {
  std::vector<RunRecord> r;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    r.push_back(record("office", "fast", 2, seed, 100 + int(seed), 50.0 + double(seed)));
    r.push_back(record("office", "slow", 2, seed, 200 + 2 * int(seed), 40.0));
    r.push_back(record("cave", "fast", 2, seed, 300, 70.0));
    r.push_back(record("cave", "slow", 2, seed, seed == 3 ? std::nullopt : std::optional<int>(250), 60.0));
  }
  return r;
}

std::size_t metric(const std::string& name) {
  const auto& m = report_metrics();
  return std::size_t(std::find_if(m.begin(), m.end(), [&](const ReportMetric& x) { return x.name == name; }) - m.begin());
}

TEST(SweepReport, GroupsHoldMeansDeviationsAndIntervals) {
  const auto groups = summarize_groups(sample_records());
  ASSERT_EQ(groups.size(), 4u);
  EXPECT_EQ(groups[0].map, "office");  // in order of first appearance
  EXPECT_EQ(groups[0].strategy, "fast");
  EXPECT_EQ(groups[2].map, "cave");
  const auto& fast99 = groups[0].metrics[metric("steps_to_99")];
  EXPECT_EQ(fast99.n, 3);
  EXPECT_DOUBLE_EQ(fast99.mean, 102.0);
  EXPECT_DOUBLE_EQ(fast99.sd, 1.0);
  EXPECT_NEAR(fast99.ci_high - fast99.mean, 4.302653 / std::sqrt(3.0), 1e-5);  // t(0.975, 2)
  // A run that never reached 99% is left out of that metric, not of the others.
  const auto& cave_slow = groups[3];
  EXPECT_EQ(cave_slow.runs, 3);
  EXPECT_EQ(cave_slow.metrics[metric("steps_to_99")].n, 2);
  EXPECT_EQ(cave_slow.metrics[metric("efficiency")].n, 2);
  EXPECT_EQ(cave_slow.metrics[metric("distance_m")].n, 3);
}

TEST(SweepReport, SummaryCsvHasARowPerGroup) {
  const std::string csv = summary_csv(summarize_groups(sample_records()));
  std::istringstream in(csv);
  std::string header, row;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("map,strategy,variant,robots,runs,", 0), 0u);
  EXPECT_NE(header.find("steps_to_99_mean,steps_to_99_sd,steps_to_99_ci95_low,steps_to_99_ci95_high"), std::string::npos);
  std::getline(in, row);
  EXPECT_EQ(row.rfind("office,fast,,2,3,50,50,", 0), 0u) << row;
  EXPECT_NE(row.find(",3,102,1,"), std::string::npos) << row;  // steps_to_99: n, mean, sd
  int rows = 1;
  while (std::getline(in, row)) ++rows;
  EXPECT_EQ(rows, 4);
}

TEST(SweepReport, MarkdownMarksTheBestPerColumn) {
  const auto records = sample_records();
  const std::string md = summary_markdown(records, summarize_groups(records));
  EXPECT_NE(md.find("## office"), std::string::npos);
  EXPECT_NE(md.find("### 2 robots (lower bound 50 steps to 99%)"), std::string::npos);
  const auto line_of = [&](const std::string& map, const std::string& strategy) {
    const auto section = md.find("## " + map);
    const auto at = md.find("| " + strategy + " |", section);
    return md.substr(at, md.find('\n', at) - at);
  };
  // office: fast is quicker (bold steps), slow drives less (bold distance).
  EXPECT_NE(line_of("office", "fast").find("**102.0 ± 2.5**"), std::string::npos) << line_of("office", "fast");
  EXPECT_EQ(line_of("office", "slow").find("**204"), std::string::npos);
  EXPECT_NE(line_of("office", "slow").find("**40.0 ± 0.0**"), std::string::npos) << line_of("office", "slow");
  // cave: slow reached 99% in 2 of 3 runs, and is faster on those; efficiency is best when highest.
  EXPECT_NE(line_of("cave", "slow").find("(2/3)"), std::string::npos);
  EXPECT_NE(line_of("cave", "slow").find("**0.200"), std::string::npos) << line_of("cave", "slow");
  EXPECT_EQ(line_of("cave", "fast").find("**0.167"), std::string::npos) << line_of("cave", "fast");
}

TEST(SweepReport, BoldOnlyWhenTheIntervalsDoNotOverlap) {
  // "close" is faster on average but its interval overlaps "far"'s: no bold in steps to 99%.
  std::vector<RunRecord> records;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    records.push_back(record("office", "close", 2, seed, 100 + 20 * int(seed), 50.0));
    records.push_back(record("office", "far", 2, seed, 110 + 20 * int(seed), 50.0 + double(seed)));
  }
  const std::string md = summary_markdown(records, summarize_groups(records));
  const auto at = md.find("| close |");
  const std::string close = md.substr(at, md.find('\n', at) - at);
  EXPECT_EQ(close.find("**140.0"), std::string::npos) << close;
  EXPECT_NE(close.find("140.0 ± "), std::string::npos) << close;
  // A single seed gives no interval, so nothing is bold.
  std::vector<RunRecord> one = {record("office", "close", 2, 1, 100, 50.0), record("office", "far", 2, 1, 300, 60.0)};
  const std::string md_one = summary_markdown(one, summarize_groups(one));
  EXPECT_EQ(md_one.find("**", md_one.find("| strategy |")), std::string::npos) << md_one;
}

TEST(SweepReport, PairedComparisonOfTwoStrategies) {
  const auto records = sample_records();
  const StrategyComparison c = compare_strategies(records, "fast", "slow", "steps_to_99");
  // office: fast - slow = (101 - 202, 102 - 204, 103 - 206) = -101, -102, -103.
  const auto office = std::find_if(c.rows.begin(), c.rows.end(), [](const PairedRow& r) { return r.map == "office" && r.robots == 2; });
  ASSERT_NE(office, c.rows.end());
  EXPECT_EQ(office->comparison.difference.n, 3);
  EXPECT_DOUBLE_EQ(office->comparison.difference.mean, -102.0);
  EXPECT_EQ(office->comparison.a_lower, 3);
  // cave: seed 3 of slow never reached 99%, so that pair is out.
  EXPECT_EQ(c.unpaired, 2);
  EXPECT_EQ(c.rows.back().map, "all");
  EXPECT_EQ(c.rows.back().comparison.difference.n, 5);
  const std::string text = comparison_text(c);
  EXPECT_NE(text.find("| office | 2 | 3 | -102.00 |"), std::string::npos) << text;
  EXPECT_NE(text.find("2 runs had no partner"), std::string::npos);
  expect_input_error([&] { compare_strategies(records, "fast", "nowhere", "steps_to_99"); }, {"nowhere", "fast, slow"});
  expect_input_error([&] { compare_strategies(records, "fast", "fast", "steps_to_99"); }, {"two different"});
  expect_input_error([&] { compare_strategies(records, "fast", "slow", "speed"); }, {"metric: unknown metric", "'speed'", "steps_to_99"});
}

// Runs that differ in a setting of the sweep's further axes, or in team size, pair like strategies.
TEST(SweepReport, PairedComparisonOverAnyAxis) {
  std::vector<RunRecord> records;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    for (int robots : {2, 4}) {
      for (const char* strategy : {"fast", "slow"}) {
        for (int beams : {90, 360}) {
          RunRecord r = record("office", strategy, robots, seed, 400 / robots + (beams == 90 ? 30 : 0) + int(seed), 10.0);
          r.key.variant = "beams=" + std::to_string(beams) + " comm_range=inf";
          records.push_back(r);
        }
      }
    }
  }
  const StrategyComparison beams = compare_strategies(records, "beams=90", "beams=360", "steps_to_99");
  EXPECT_EQ(beams.axis, "beams");
  EXPECT_EQ(beams.rows.back().comparison.difference.n, 4 * 2 * 2);
  EXPECT_DOUBLE_EQ(beams.rows.back().comparison.difference.mean, 30.0);
  EXPECT_EQ(beams.unpaired, 0);
  const StrategyComparison teams = compare_strategies(records, "robots=2", "robots=4", "steps_to_99");
  EXPECT_DOUBLE_EQ(teams.rows.back().comparison.difference.mean, 100.0);
  for (const auto& row : teams.rows) EXPECT_EQ(row.robots, 0);  // no row per team size when teams are compared
  EXPECT_NE(comparison_text(teams).find("same map, strategy, seed and other settings"), std::string::npos);
  // Strategies still pair within one variant.
  EXPECT_EQ(compare_strategies(records, "fast", "slow", "steps_to_99").rows.back().comparison.difference.n, 16);
  expect_input_error([&] { compare_strategies(records, "beams=90", "robots=2", "steps_to_99"); }, {"one setting"});
  expect_input_error([&] { compare_strategies(records, "beams=45", "beams=360", "steps_to_99"); },
                     {"no runs with beams=45", "beams there: 90, 360"});
  // Summary rows and plot curves are per strategy and variant.
  const auto groups = summarize_groups(records);
  EXPECT_EQ(groups.size(), 2u * 2u * 2u);
  EXPECT_EQ(groups.front().series(), "fast beams=90 comm_range=inf");
  EXPECT_NE(summary_markdown(records, groups).find("| slow beams=360 comm_range=inf | 4 |"), std::string::npos);
  EXPECT_NE(summary_csv(groups).find("office,fast,beams=90 comm_range=inf,2,4,"), std::string::npos);
}

TEST(SweepReport, PlotsForEveryMapAndEfficiency) {
  const auto plots = sweep_plots(sample_records());
  std::vector<std::string> files;
  for (const auto& p : plots) {
    files.push_back(p.file);
    ASSERT_FALSE(p.image.empty()) << p.file;
    EXPECT_GE(p.image.cols, 600) << p.file;
    // Each plot shows the first strategy's colour (palette 0: BGR 180, 119, 31).
    cv::Mat mask;
    cv::inRange(p.image, cv::Scalar(180, 119, 31), cv::Scalar(180, 119, 31), mask);
    EXPECT_GT(cv::countNonZero(mask), 50) << p.file;
  }
  EXPECT_EQ(files, (std::vector<std::string>{"coverage_office.png", "time_office.png", "coverage_cave.png", "time_cave.png",
                                             "efficiency.png"}));
}

TEST(SweepReport, TheLowerBoundIsDrawnForASingleTeamSize) {
  // Every record has 2 robots: the bound is one point, drawn as a short dashed level line.
  const auto plots = sweep_plots(sample_records());
  const auto& time = plots[1];
  ASSERT_EQ(time.file, "time_office.png");
  int series = 0, dashed = 0;
  for (const auto& shape : time.drawing.shapes()) {
    if (shape.role != "series") continue;
    ++series;
    if (shape.dashed && shape.color == viz::Color{90, 90, 90}) {
      ++dashed;
      ASSERT_EQ(shape.points.size(), 2u);
      EXPECT_GT(shape.points[1].x - shape.points[0].x, 10.0);
    }
  }
  EXPECT_EQ(series, 3);  // fast, slow and the bound
  EXPECT_EQ(dashed, 1);
}

TEST(SweepReport, EveryPlotIsWrittenAsPngAndSvg) {
  fleetmap::testing::TempDir dir;
  const auto written = write_sweep_reports(dir.path(), sample_records());
  for (const char* stem : {"coverage_office", "time_office", "coverage_cave", "time_cave", "efficiency"}) {
    for (const char* ext : {".png", ".svg"}) {
      const auto p = dir.path() / (std::string(stem) + ext);
      EXPECT_TRUE(std::filesystem::exists(p)) << p;
      EXPECT_NE(std::find(written.begin(), written.end(), p), written.end()) << p;
    }
  }
  std::ifstream svg(dir.path() / "efficiency.svg");
  const std::string text((std::istreambuf_iterator<char>(svg)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("<svg"), std::string::npos);
}

}  // namespace
}  // namespace fleetmap::sweep
