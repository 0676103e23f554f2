// End-to-end: `fleetmap bench` as a user runs it: a tiny sweep, its files and numbers, the same rows
// whatever --jobs, resume after the process is killed, shards and --combine, --compare, bad input.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <boost/math/distributions/students_t.hpp>
#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <cmath>
#include <set>
#include <thread>

#include "exploration/strategy.h"
#include "tests/cli/bench_test_support.h"

namespace fleetmap::cli {
namespace {

using namespace fleetmap::testing;

// 2 maps x 2 strategies x 2 team sizes x `seeds` seeds of short runs.
std::string sweep_flags(int seeds) {
  return "--maps room.yaml,hall.yaml --strategies uncoordinated,coordinated --robots 1,2 --seeds " + std::to_string(seeds) +
         " --steps 300";
}
const std::string kSweep = sweep_flags(2);
constexpr int kSweepRuns = 16;

struct BenchDir {
  TempDir dir;
  BenchDir() { write_bench_maps(dir); }
  CliResult bench(const std::string& args) const { return run_fleetmap("bench " + args, dir); }
  std::filesystem::path operator/(const std::string& name) const { return dir / name; }
};

double number(const std::string& cell) { return std::stod(cell); }

int count_lines(const std::filesystem::path& p) { return int(lines_of(slurp(p)).size()); }

TEST(BenchCommand, TinySweepWritesEveryOutputAndItsSummaryMatchesItsRows) {
  BenchDir b;
  const auto r = b.bench(kSweep + " --jobs 2 --out out");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");  // no progress bar when stderr is not a terminal
  EXPECT_NE(r.out.find("ran 16 runs"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("results: out/results.csv"), std::string::npos) << r.out;
  for (const char* f : {"results.csv", "summary.csv", "summary.md", "sweep.yaml", "scenario.yaml", "coverage_room.png",
                        "coverage_hall.png", "time_room.png", "time_hall.png", "efficiency.png"}) {
    EXPECT_TRUE(std::filesystem::exists(b / "out" / f)) << f;
  }
  const CsvTable results = read_csv(b / "out" / "results.csv");
  ASSERT_EQ(int(results.rows.size()), kSweepRuns);
  std::set<std::string> keys;
  int reached = 0;
  for (const auto& row : results.rows) {
    EXPECT_EQ(row.size(), results.header.size());
    keys.insert(row.at("map") + "/" + row.at("strategy") + "/" + row.at("robots") + "/" + row.at("seed"));
    EXPECT_EQ(row.at("step_limit"), "300");
    EXPECT_EQ(row.at("merging"), "known");
    EXPECT_EQ(row.at("merges_made"), "0");  // one frame for all: nothing to merge
    EXPECT_GT(number(row.at("lower_bound_steps")), 0.0);  // the maps are larger than one scan
    // No run beats the lower bound; efficiency is defined where 99% was reached.
    if (row.at("steps_to_99").empty()) {
      EXPECT_EQ(row.at("efficiency"), "");
      continue;
    }
    ++reached;
    EXPECT_LE(number(row.at("lower_bound_steps")), number(row.at("steps_to_99")));
    EXPECT_NEAR(number(row.at("efficiency")), number(row.at("lower_bound_steps")) / number(row.at("steps_to_99")), 1e-6);
  }
  EXPECT_EQ(int(keys.size()), kSweepRuns);
  EXPECT_GE(reached, kSweepRuns / 2);

  // summary.csv, recomputed here from results.csv: mean, sample sd and the t interval over seeds.
  const CsvTable summary = read_csv(b / "out" / "summary.csv");
  ASSERT_EQ(summary.rows.size(), 8u);
  const double t1 = boost::math::quantile(boost::math::students_t(1.0), 0.975);  // 2 seeds: 1 degree of freedom
  int checked = 0;
  for (const auto& group : summary.rows) {
    for (const std::string metric : {"steps_to_95", "steps_to_99", "distance_m", "redundancy", "bytes_sent", "efficiency"}) {
      std::vector<double> v;
      for (const auto& row : results.rows) {
        if (row.at("map") == group.at("map") && row.at("strategy") == group.at("strategy") &&
            row.at("robots") == group.at("robots") && !row.at(metric).empty()) {
          v.push_back(number(row.at(metric)));
        }
      }
      const std::string where = group.at("map") + "/" + group.at("strategy") + "/" + group.at("robots") + " " + metric;
      EXPECT_EQ(group.at(metric + "_n"), std::to_string(v.size())) << where;
      if (v.size() < 2) {  // a level reached by one run or none: no deviation, no interval
        EXPECT_EQ(group.at(metric + "_sd"), "") << where;
        EXPECT_EQ(group.at(metric + "_ci95_low"), "") << where;
        if (v.size() == 1) {
          EXPECT_NEAR(number(group.at(metric + "_mean")), v[0], 1e-6 * std::max(1.0, v[0])) << where;
        }
        continue;
      }
      ++checked;
      const double mean = 0.5 * (v[0] + v[1]);
      const double sd = std::abs(v[0] - v[1]) / std::sqrt(2.0);
      const double tol = 1e-6 * std::max(1.0, std::abs(mean));
      EXPECT_NEAR(number(group.at(metric + "_mean")), mean, tol) << where;
      EXPECT_NEAR(number(group.at(metric + "_sd")), sd, tol) << where;
      EXPECT_NEAR(number(group.at(metric + "_ci95_low")), mean - t1 * sd / std::sqrt(2.0), 1e-5 * std::max(1.0, sd)) << where;
      EXPECT_NEAR(number(group.at(metric + "_ci95_high")), mean + t1 * sd / std::sqrt(2.0), 1e-5 * std::max(1.0, sd)) << where;
    }
  }
  EXPECT_GE(checked, 8 * 4);  // distance, redundancy, bytes and more always have both seeds
  const std::string md = slurp(b / "out" / "summary.md");
  EXPECT_NE(md.find("## room"), std::string::npos);
  EXPECT_NE(md.find("### 2 robots"), std::string::npos);
  EXPECT_NE(md.find("**"), std::string::npos);  // best values marked

  // The plots are real pictures with something drawn on them.
  for (const char* f : {"coverage_room.png", "coverage_hall.png", "time_room.png", "time_hall.png", "efficiency.png"}) {
    const cv::Mat img = cv::imread((b / "out" / f).string());
    ASSERT_FALSE(img.empty()) << f;
    EXPECT_GE(img.cols, 800) << f;
    cv::Mat grey, ink;
    cv::cvtColor(img, grey, cv::COLOR_BGR2GRAY);
    cv::threshold(grey, ink, 250, 255, cv::THRESH_BINARY_INV);
    EXPECT_GT(cv::countNonZero(ink), 5000) << f;
  }
}

TEST(BenchCommand, ReportPageLinksEachRunsReplay) {
  BenchDir b;
  const auto r = b.bench("--maps maze --strategies directional --robots 2 --seeds 2 --steps 10 --jobs 2 --html --out out");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string report = slurp(b / "out" / "report.html");
  EXPECT_NE(report.find("<h2>maze</h2>"), std::string::npos);
  EXPECT_NE(report.find("<svg"), std::string::npos);   // the plots, inline
  EXPECT_NE(report.find("<title>"), std::string::npos);  // with tooltips
  EXPECT_EQ(report.find("src="), std::string::npos);    // nothing to fetch
  for (const char* name : {"replay_maze_directional_2r_s1.html", "replay_maze_directional_2r_s2.html"}) {
    EXPECT_TRUE(std::filesystem::is_regular_file(b / "out" / name)) << name;
    EXPECT_NE(report.find(std::string("href=\"") + name + "\""), std::string::npos) << name;
    EXPECT_NE(slurp(b / "out" / "outputs.txt").find(name), std::string::npos) << name;
  }
  // Without --html: the report, no replays and no links.
  ASSERT_EQ(b.bench("--maps maze --strategies directional --robots 2 --seeds 1 --steps 10 --out plain").exit_code, 0);
  EXPECT_EQ(slurp(b / "plain" / "report.html").find("href="), std::string::npos);
}

TEST(BenchCommand, SameRowsWhateverTheNumberOfJobs) {
  BenchDir b;
  ASSERT_EQ(b.bench(kSweep + " --jobs 1 --out one").exit_code, 0);
  ASSERT_EQ(b.bench(kSweep + " --jobs 2 --out two").exit_code, 0);
  const auto one = rows_without_wall_time(b / "one" / "results.csv");
  EXPECT_EQ(one.size(), std::size_t(kSweepRuns + 1));
  EXPECT_EQ(one, rows_without_wall_time(b / "two" / "results.csv"));
  EXPECT_EQ(slurp(b / "one" / "summary.csv"), slurp(b / "two" / "summary.csv"));
  EXPECT_EQ(slurp(b / "one" / "summary.md"), slurp(b / "two" / "summary.md"));
  // Other seeds give other rows.
  ASSERT_EQ(b.bench(kSweep + " --first-seed 5 --jobs 2 --out other").exit_code, 0);
  EXPECT_NE(one, rows_without_wall_time(b / "other" / "results.csv"));
}

TEST(BenchCommand, ResumesAfterBeingKilledMidSweep) {
  BenchDir b;
  // 32 runs on one thread, so the process is killed well before the end.
  const std::string sweep = sweep_flags(4) + " --jobs 1";
  const auto results = b / "killed" / "results.csv";
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    if (::chdir(b.dir.path().c_str()) != 0) ::_exit(127);
    const std::string cmd = std::string("exec '") + FLEETMAP_BINARY + "' bench " + sweep + " --out killed >/dev/null 2>&1 </dev/null";
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int rows_at_kill = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(5);
  int status = 0;
  bool exited = false;
  while (std::chrono::steady_clock::now() < deadline) {
    if (std::filesystem::exists(results)) rows_at_kill = count_lines(results) - 1;
    if (rows_at_kill >= 3) break;
    if (::waitpid(pid, &status, WNOHANG) == pid) {
      exited = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_FALSE(exited) << "the sweep ended (status " << status << ") before it could be killed";
  ::kill(pid, SIGKILL);
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "status " << status;
  ASSERT_GE(rows_at_kill, 3) << "no rows within 5 minutes";

  // What the killed process left: whole rows only, fewer than the sweep's 32.
  const std::string left = slurp(results);
  ASSERT_FALSE(left.empty());
  EXPECT_EQ(left.back(), '\n');
  const auto left_lines = lines_of(left);
  const auto columns = split(left_lines[0]).size();
  for (const auto& line : left_lines) EXPECT_EQ(split(line).size(), columns) << line;
  const int kept = int(left_lines.size()) - 1;
  ASSERT_LT(kept, 32);

  // The rerun runs only the rest and keeps the finished rows as they were (wall times included).
  const auto again = b.bench(sweep + " --out killed");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NE(again.out.find("ran " + std::to_string(32 - kept) + " runs"), std::string::npos) << again.out;
  EXPECT_NE(again.out.find(std::to_string(kept) + (kept == 1 ? " run" : " runs") + " already in results.csv"), std::string::npos)
      << again.out;
  const std::string resumed = slurp(results);
  for (std::size_t i = 1; i < left_lines.size(); ++i) {
    EXPECT_NE(resumed.find(left_lines[i] + "\n"), std::string::npos) << "row redone: " << left_lines[i];
  }

  // The same as a sweep that was never interrupted.
  ASSERT_EQ(b.bench(sweep + " --out whole").exit_code, 0);
  EXPECT_EQ(rows_without_wall_time(results), rows_without_wall_time(b / "whole" / "results.csv"));
  EXPECT_EQ(slurp(b / "killed" / "summary.csv"), slurp(b / "whole" / "summary.csv"));
  // A third run has nothing left to do.
  const auto third = b.bench(sweep + " --out killed");
  EXPECT_NE(third.out.find("ran 0 runs"), std::string::npos) << third.out;
}

TEST(BenchCommand, ShardsCombineIntoTheFullRun) {
  BenchDir b;
  ASSERT_EQ(b.bench(kSweep + " --jobs 2 --out full").exit_code, 0);
  std::set<std::string> seen;
  int total = 0;
  for (int k = 1; k <= 3; ++k) {
    const std::string out = std::string("s").append(std::to_string(k));
    const auto r = b.bench(kSweep + " --jobs 2 --shard " + std::to_string(k) + "/3 --out " + out);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto rows = rows_without_wall_time(b / out / "results.csv");
    total += int(rows.size()) - 1;
    for (std::size_t i = 1; i < rows.size(); ++i) EXPECT_TRUE(seen.insert(rows[i]).second) << "in two shards: " << rows[i];
  }
  EXPECT_EQ(total, kSweepRuns);
  const auto c = b.bench("--combine s1 s2 s3 --out all");
  ASSERT_EQ(c.exit_code, 0) << c.err;
  EXPECT_NE(c.out.find("combined 16 runs from 3 folders"), std::string::npos) << c.out;
  EXPECT_EQ(rows_without_wall_time(b / "all" / "results.csv"), rows_without_wall_time(b / "full" / "results.csv"));
  for (const char* f : {"summary.csv", "summary.md"}) EXPECT_EQ(slurp(b / "all" / f), slurp(b / "full" / f)) << f;
  for (const char* f : {"coverage_room.png", "time_hall.png", "efficiency.png"}) {
    EXPECT_TRUE(std::filesystem::exists(b / "all" / f)) << f;
  }
  // Two of three shards: combined, with a note of what is missing.
  const auto part = b.bench("--combine s1 s3 --out part");
  ASSERT_EQ(part.exit_code, 0) << part.err;
  EXPECT_NE(part.out.find("are missing"), std::string::npos) << part.out;
}

TEST(BenchCommand, CombineRefusesFoldersOfDifferentSweeps) {
  BenchDir b;
  const std::string one = "--maps hall.yaml --strategies uncoordinated --robots 1,2 --seeds 2 --steps 20 -o ";
  ASSERT_EQ(b.bench(one + "s1 --shard 1/2").exit_code, 0);
  ASSERT_EQ(b.bench(one + "s2 --shard 2/2").exit_code, 0);
  // Another sweep with the same settings: other maps, team sizes and seeds.
  ASSERT_EQ(b.bench("--maps room.yaml --strategies uncoordinated --robots 1 --seeds 3 --steps 20 --out other").exit_code, 0);
  const auto r = b.bench("--combine s1 other --out c");
  EXPECT_ONE_LINE_ERROR(r, "--combine: s1 and other are results of different sweeps (their sweep.yaml has 'maps: [");
  EXPECT_EQ(r.out, "");
  EXPECT_FALSE(std::filesystem::exists(b / "c"));
  std::filesystem::remove(b / "other" / "sweep.yaml");
  EXPECT_ONE_LINE_ERROR(b.bench("--combine s1 other --out c"), "--combine: s1 has a sweep.yaml and other none");
  EXPECT_FALSE(std::filesystem::exists(b / "c"));

  // The shards of one sweep whose sweep.yaml does not load here (a strategy a Python program
  // registered): compared as text, combined with a note.
  for (const char* shard : {"s1", "s2"}) {
    std::string yaml = slurp(b / shard / "sweep.yaml");
    yaml.replace(yaml.find("strategies: [uncoordinated]"), 27, "strategies: [my_python_strategy]");
    b.dir.write(std::string(shard) + "/sweep.yaml", yaml);
  }
  const auto python = b.bench("--combine s1 s2 --out c");
  ASSERT_EQ(python.exit_code, 0) << python.err;
  EXPECT_NE(python.out.find("combined 4 runs from 2 folders"), std::string::npos) << python.out;
  EXPECT_NE(python.err.find("unknown strategy 'my_python_strategy'"), std::string::npos) << python.err;
  EXPECT_EQ(fleetmap::testing::line_count(python.err), 1) << python.err;
  std::string yaml = slurp(b / "s2" / "sweep.yaml");
  yaml.replace(yaml.find("seeds: 2"), 8, "seeds: 5");
  b.dir.write("s2/sweep.yaml", yaml);
  EXPECT_ONE_LINE_ERROR(b.bench("--combine s1 s2 --out c2"), "(their sweep.yaml has 'seeds: 2' against 'seeds: 5')");
}

TEST(BenchCommand, PairedComparisonOfTwoStrategies) {
  BenchDir b;
  ASSERT_EQ(b.bench(kSweep + " --jobs 2 --out out").exit_code, 0);
  const auto r = b.bench("--compare coordinated uncoordinated out");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The overall mean difference, recomputed from results.csv.
  const CsvTable t = read_csv(b / "out" / "results.csv");
  std::map<std::string, double> coordinated, uncoordinated;
  for (const auto& row : t.rows) {
    if (row.at("steps_to_99").empty()) continue;  // never reached 99%: no pair
    const std::string key = row.at("map") + "/" + row.at("robots") + "/" + row.at("seed");
    (row.at("strategy") == "coordinated" ? coordinated : uncoordinated)[key] = number(row.at("steps_to_99"));
  }
  double sum = 0.0;
  int pairs = 0;
  for (const auto& [key, v] : coordinated) {
    if (uncoordinated.count(key)) sum += v - uncoordinated.at(key), ++pairs;
  }
  ASSERT_GE(pairs, 2);
  const std::string expected = fmt::format("| all | all | {} | {:.2f} |", pairs, sum / pairs);
  EXPECT_NE(r.out.find(expected), std::string::npos) << expected << "\n" << r.out;
  EXPECT_NE(r.out.find("| room | 2 |"), std::string::npos) << r.out;
  const auto d = b.bench("--compare coordinated uncoordinated out --metric distance_m");
  ASSERT_EQ(d.exit_code, 0) << d.err;
  EXPECT_NE(d.out.find("Paired comparison of distance_m"), std::string::npos) << d.out;
}

TEST(BenchCommand, BadInputGetsOneLine) {
  BenchDir b;
  const std::string small = " --maps hall.yaml --strategies uncoordinated --robots 1 --seeds 1 --steps 20";
  EXPECT_ONE_LINE_ERROR(b.bench("--strategies uncoordinated,best --out x"), "unknown strategy 'best'");
  EXPECT_ONE_LINE_ERROR(b.bench("--strategies coordinated,uncordinated --out x"),
                        "--strategies: unknown strategy 'uncordinated' (did you mean 'uncoordinated'?) (valid: ");
  EXPECT_ONE_LINE_ERROR(b.bench("--strategies all,tour --out x"), "--strategies: 'all' stands alone");
  // --metric picks the metric of --compare: alone it is refused, not ignored.
  EXPECT_ONE_LINE_ERROR(b.bench(small + " --metric distance_m --out x"), "--metric goes with --compare");
  EXPECT_ONE_LINE_ERROR(b.bench(small + " --metric bogus --out x"), "--metric goes with --compare");
  EXPECT_ONE_LINE_ERROR(b.bench("--maps hall.yaml,atlantis --strategies uncoordinated --out x"), "atlantis");
  EXPECT_ONE_LINE_ERROR(b.bench(small + " --shard 5/4 --out x"), "--shard '5/4'");
  EXPECT_ONE_LINE_ERROR(b.bench(small + " --shard 0/3 --out x"), "--shard '0/3'");
  EXPECT_ONE_LINE_ERROR(b.bench("--robots 1,0 --out x"), "--robots: team size '0'");
  EXPECT_ONE_LINE_ERROR(b.bench("--robots 2,x --out x"), "--robots: team size 'x'");
  EXPECT_ONE_LINE_ERROR(b.bench("--seeds 0 --out x"), "--seeds");
  EXPECT_ONE_LINE_ERROR(b.bench("--jobs 0 --out x"), "--jobs");
  EXPECT_ONE_LINE_ERROR(b.bench("--sensor-range -1 --out x"), "--sensor-range");
  cv::Mat closet(20, 20, CV_8UC1, cv::Scalar(254));
  cv::rectangle(closet, cv::Rect(0, 0, 20, 20), cv::Scalar(0), 1);
  write_map(b.dir, "closet", closet);
  EXPECT_ONE_LINE_ERROR(b.bench("--maps hall.yaml,closet.yaml --robots 1,20 --strategies market --seeds 1 --out x"),
                        "map 'closet' with 20 robots");
  EXPECT_FALSE(std::filesystem::exists(b / "x" / "results.csv"));
  // --combine: needs --out, and folders with results.
  std::filesystem::create_directories(b / "empty_dir");
  EXPECT_ONE_LINE_ERROR(b.bench("--combine empty_dir"), "--combine needs --out");
  EXPECT_ONE_LINE_ERROR(b.bench("--combine nowhere --out c"), "'nowhere' is not a folder");
  EXPECT_ONE_LINE_ERROR(b.bench("--combine empty_dir --out c"), "holds no results.csv");
  EXPECT_ONE_LINE_ERROR(b.bench("--compare coordinated --out c"), "--compare");
  EXPECT_ONE_LINE_ERROR(b.bench("--compare coordinated market nowhere"), "--compare: 'nowhere' is not a folder");
  EXPECT_ONE_LINE_ERROR(b.bench(small + " --merging telepathy --out x"), "--merging: unknown mode 'telepathy'");
  EXPECT_ONE_LINE_ERROR(b.bench(small + " --localization psychic --out x"), "psychic");
  // results.csv of another sweep, or of something else.
  ASSERT_EQ(b.bench(small + " --out done").exit_code, 0);
  EXPECT_ONE_LINE_ERROR(b.bench(small + " --sensor-range 3 --out done"), "holds the results of another sweep");
  b.dir.write("foreign/results.csv", "name,score\nx,1\n");
  EXPECT_ONE_LINE_ERROR(b.bench(small + " --out foreign"), "holds a file that no earlier 'fleetmap bench' run wrote ('results.csv')");
  EXPECT_ONE_LINE_ERROR(b.bench("--combine done foreign --out c"), "not a results table");
  EXPECT_ONE_LINE_ERROR(b.bench("--compare coordinated market done"), "no runs of strategy 'coordinated' in the results (strategies");
  EXPECT_ONE_LINE_ERROR(b.bench("--compare uncordinated uncoordinated done"),
                        "no runs of strategy 'uncordinated' in the results (did you mean 'uncoordinated'?)");
  EXPECT_ONE_LINE_ERROR(b.bench("--compare coordinated uncoordinated done --metric steps_to99"),
                        "--metric: unknown metric 'steps_to99' (did you mean 'steps_to_99'?)");
  // A sweep file with a mistake.
  b.dir.write("bad.yaml", "maps: [hall.yaml]\nrobot: [1, 2]\n");
  EXPECT_ONE_LINE_ERROR(b.bench("--sweep bad.yaml --out x"), "bad.yaml:2: unknown key 'robot'");
}

TEST(BenchCommand, MergingModeReachesEveryRun) {
  // Robots that map in their own frames and merge when they meet: the rows say so and count merges.
  BenchDir b;
  const auto r = b.bench("--maps hall.yaml --strategies uncoordinated,market --robots 2 --seeds 2 --steps 40 "
                         "--merging rendezvous --jobs 2 --out m");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CsvTable t = read_csv(b / "m" / "results.csv");
  ASSERT_EQ(t.rows.size(), 4u);
  for (const auto& row : t.rows) {
    EXPECT_EQ(row.at("merging"), "rendezvous");
    EXPECT_GE(number(row.at("merges_made")), 1.0) << "two robots placed together see each other and merge";
  }
  EXPECT_NE(slurp(b / "m" / "summary.md").find("merging rendezvous"), std::string::npos);
}

// Any setting as a further axis: every combination runs, rows name their variant, the summary and
// --compare use it, and resume recognises the runs.
TEST(BenchCommand, VaryAnySettingAndCompareItsValues) {
  BenchDir b;
  const std::string sweep = "--maps hall.yaml --strategies uncoordinated --robots 1 --seeds 2 --steps 200 "
                            "--vary beams=8,360 --vary sensor_range=2,4";
  const auto r = b.bench(sweep + " --out v");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("8 runs of 1 map x 1 strategy x 1 team size x 4 variants x 2 seeds"), std::string::npos) << r.out;
  const CsvTable t = read_csv(b / "v" / "results.csv");
  ASSERT_EQ(t.rows.size(), 2u * 2u * 2u);
  std::set<std::string> variants;
  for (const auto& row : t.rows) variants.insert(row.at("variant"));
  EXPECT_EQ(variants, (std::set<std::string>{"beams=8 sensor_range=2", "beams=8 sensor_range=4", "beams=360 sensor_range=2",
                                             "beams=360 sensor_range=4"}));
  for (const auto& row : t.rows) {
    EXPECT_EQ(row.at("sensor_range_m"), row.at("variant").find("sensor_range=2") != std::string::npos ? "2.000" : "4.000");
  }
  EXPECT_NE(slurp(b / "v" / "summary.md").find("| uncoordinated beams=360 sensor_range=4 | 2 |"), std::string::npos);
  EXPECT_NE(slurp(b / "v" / "sweep.yaml").find("vary:\n  beams: [8, 360]\n  sensor_range: [2, 4]\n"), std::string::npos);
  // Resuming the very same sweep runs nothing again.
  const auto again = b.bench(sweep + " --out v");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(count_lines(b / "v" / "results.csv"), 1 + 8);
  const auto c = b.bench("--compare sensor_range=2 sensor_range=4 v --metric coverage");
  ASSERT_EQ(c.exit_code, 0) << c.err;
  EXPECT_NE(c.out.find("sensor_range=2 - sensor_range=4"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("| all | all | 4 |"), std::string::npos) << c.out;
  EXPECT_ONE_LINE_ERROR(b.bench("--compare beams=8 sensor_range=2 v"), "one setting");
  EXPECT_ONE_LINE_ERROR(b.bench("--compare beams=9 beams=8 v"), "no runs with beams=9");
  EXPECT_ONE_LINE_ERROR(b.bench("--maps hall.yaml --vary beams --out x"), "--vary beams: expected SETTING=VALUE");
  EXPECT_ONE_LINE_ERROR(b.bench("--maps hall.yaml --vary beams=0 --out x"), "axis beams=0");
  EXPECT_ONE_LINE_ERROR(b.bench("--maps hall.yaml --vary robots=1,2 --out x"), "already");
  // A mistyped setting: the short names listed, the nearest short name or key suggested.
  const auto beam = b.bench("--maps hall.yaml --vary beam=45,360 --out x");
  EXPECT_ONE_LINE_ERROR(beam, "--vary beam=45,360: unknown setting 'beam' (did you mean 'beams'?) (valid: beams, sensor_range, comm_range, ");
  EXPECT_ONE_LINE_ERROR(beam, "noise_position");
  EXPECT_ONE_LINE_ERROR(b.bench("--maps hall.yaml --vary noise_positon=0.1 --out x"), "(did you mean 'noise_position'?)");
  EXPECT_ONE_LINE_ERROR(b.bench("--maps hall.yaml --vary sensors.range.beam=8 --out x"), "(did you mean 'sensors.range.beams'?)");
  EXPECT_FALSE(std::filesystem::exists(b / "x"));
}

TEST(BenchCommand, ReadySweepFilesRun) {
  // The seed-003 sweep file, cut down by flags to one short run per strategy on one map.
  BenchDir b;
  const auto r = b.bench(std::string("--sweep '") + FLEETMAP_SOURCE_DIR +
                         "/scenarios/sweeps/wave_paper.yaml' --maps hall.yaml --seeds 1 --steps 15 --jobs 2 --out s");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CsvTable t = read_csv(b / "s" / "results.csv");
  ASSERT_EQ(t.rows.size(), exploration::strategy_names().size());  // every strategy
  for (const auto& row : t.rows) EXPECT_EQ(row.at("robots"), "9");
}


TEST(BenchCommand, AResultsFolderIsResumedOnlyByTheVerySameSweep) {
  BenchDir b;
  const std::string sweep = " --strategies uncoordinated --robots 1 --steps 20";
  // Two maps with the same file stem in different folders are different maps.
  std::filesystem::create_directories(b / "x");
  std::filesystem::create_directories(b / "y");
  std::filesystem::copy_file(b / "hall.png", b / "x" / "r.png");
  std::filesystem::copy_file(b / "room.png", b / "y" / "r.png");
  ASSERT_EQ(b.bench("--maps x/r.png --seeds 2" + sweep + " --out out").exit_code, 0);
  const std::string results = slurp(b / "out" / "results.csv");
  EXPECT_ONE_LINE_ERROR(b.bench("--maps y/r.png --seeds 2" + sweep + " --out out"),
                        "--out out: holds the results of another sweep (sweep.yaml there has 'maps: [");
  // Fewer seeds over a finished sweep: refused, not summarised with the old rows.
  EXPECT_ONE_LINE_ERROR(b.bench("--maps x/r.png --seeds 1" + sweep + " --out out"),
                        "(sweep.yaml there has 'seeds: 2', this sweep 'seeds: 1')");
  EXPECT_EQ(slurp(b / "out" / "results.csv"), results);
  // The same sweep resumes (nothing left to run).
  const auto same = b.bench("--maps x/r.png --seeds 2" + sweep + " --out out");
  ASSERT_EQ(same.exit_code, 0) << same.err;
  EXPECT_NE(same.out.find("ran 0 runs"), std::string::npos) << same.out;
  // A row from outside the sweep in results.csv is refused, not counted.
  auto lines = lines_of(results);
  std::string foreign = lines[1];
  foreign.replace(foreign.find(",1,1,"), 5, ",1,9,");  // seed 9 is not in the sweep
  b.dir.write("out/results.csv", results + foreign + "\n");
  EXPECT_ONE_LINE_ERROR(b.bench("--maps x/r.png --seeds 2" + sweep + " --out out"),
                        "holds a run that is not part of this sweep (r, uncoordinated, 1 robot, seed 9)");
  // A shard's folder is resumed by that shard only.
  ASSERT_EQ(b.bench("--maps x/r.png --seeds 2" + sweep + " --shard 1/2 --out s1").exit_code, 0);
  EXPECT_ONE_LINE_ERROR(b.bench("--maps x/r.png --seeds 2" + sweep + " --shard 2/2 --out s1"),
                        "holds a run that is not part of this sweep (shard)");
}

}  // namespace
}  // namespace fleetmap::cli
