// `fleetmap slam --log`: a log written from the simulator, mapped, the outputs read back.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <sstream>

#include "io/map_io.h"
#include "tests/cli_run.h"
#include "tests/sim_laser_log.h"
#include "tests/test_support.h"

namespace fleetmap::testing {
namespace {

struct LogFiles {
  SimLaserLog log = sim_laser_log({.laps = 1});
  explicit LogFiles(TempDir& dir) {
    dir.write("sim.log", log.text);
    dir.write("sim.relations", relations_text(log));
  }
};

TEST(SlamLogCommand, WritesTheMapTrajectoryAndMetrics) {
  TempDir dir;
  LogFiles files(dir);
  const auto r = run_fleetmap("slam --log sim.log --relations sim.relations --out o", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("relations:"), std::string::npos) << r.out;
  const auto map = io::load_map(dir / "o" / "map.yaml");
  EXPECT_GT(map.width(), 0);
  EXPECT_TRUE(std::filesystem::exists(dir / "o" / "map.png"));
  // One line per scan: the log's timestamp as written, then x y theta.
  std::istringstream lines(slurp(dir / "o" / "trajectory.txt"));
  std::string line;
  std::size_t n = 0;
  while (std::getline(lines, line)) {
    ASSERT_LT(n, files.log.timestamps.size());
    std::istringstream words(line);
    std::string stamp;
    double x = 0, y = 0, theta = 0;
    ASSERT_TRUE(words >> stamp >> x >> y >> theta) << line;
    EXPECT_EQ(stamp, files.log.timestamps[n]);
    ++n;
  }
  EXPECT_EQ(n, files.log.timestamps.size());
  const auto m = nlohmann::json::parse(slurp(dir / "o" / "metrics.json"));
  EXPECT_EQ(m["scans"], files.log.timestamps.size());
  EXPECT_EQ(m["method"], "graph-slam");
  EXPECT_EQ(m["relations"]["matched"], m["relations"]["given"]);
  EXPECT_LT(m["relations"]["translation_mean_m"].get<double>(), 0.05);
  EXPECT_GT(m["log_duration_s"].get<double>(), 0.0);
  EXPECT_GT(m["distance_m"].get<double>(), 10.0);
  EXPECT_TRUE(m.contains("real_time_factor"));
  EXPECT_EQ(m["parameters"]["scans_per_submap"], "30");
}

// The method's declared parameters reach it: submaps of 5 scans make another graph, and say so.
TEST(SlamLogCommand, SetGivesTheMethodItsParameters) {
  TempDir dir;
  LogFiles files(dir);
  const auto a = run_fleetmap("slam --log sim.log --out a -q", dir);
  const auto b = run_fleetmap("slam --log sim.log --set localization.scans_per_submap=5 --out b -q", dir);
  ASSERT_EQ(a.exit_code, 0) << a.err;
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(dir / "b" / "metrics.json"))["parameters"]["scans_per_submap"], "5");
  EXPECT_NE(slurp(dir / "a" / "trajectory.txt"), slurp(dir / "b" / "trajectory.txt"));
}

TEST(SlamLogCommand, SameLogAndSeedGiveTheSameBytes) {
  TempDir dir;
  LogFiles files(dir);
  for (const std::string method : {"graph-slam", "scan-matching"}) {
    const auto a = run_fleetmap("slam --log sim.log --method " + method + " --seed 3 --out a_" + method + " -q", dir);
    const auto b = run_fleetmap("slam --log sim.log --method " + method + " --seed 3 --out b_" + method + " -q", dir);
    ASSERT_EQ(a.exit_code, 0) << a.err;
    ASSERT_EQ(b.exit_code, 0) << b.err;
    for (const char* name : {"map.yaml", "map.pgm", "map.png", "trajectory.txt"}) {
      EXPECT_EQ(slurp(dir / ("a_" + method) / name), slurp(dir / ("b_" + method) / name)) << method << " " << name;
    }
    auto ma = nlohmann::json::parse(slurp(dir / ("a_" + method) / "metrics.json"));
    auto mb = nlohmann::json::parse(slurp(dir / ("b_" + method) / "metrics.json"));
    for (const char* timing : {"wall_time_s", "cpu_time_s", "real_time_factor", "peak_memory_mb"}) {
      ma.erase(timing);
      mb.erase(timing);
    }
    EXPECT_EQ(ma, mb) << method;
  }
}

// Real logs' times can go back (the Intel lab's do): relations across such a scan still match.
TEST(SlamLogCommand, RelationsMatchScansWhoseTimesGoBack) {
  TempDir dir;
  SimLaserLog log = sim_laser_log({.laps = 1});
  // Scan 20 written half a second before scan 19.
  const std::string early = fmt::format("{:.6f}", log.times[19] - 0.5);
  const auto at = log.text.find(" " + log.timestamps[20] + " sim " + log.timestamps[20]);
  ASSERT_NE(at, std::string::npos);
  log.text.replace(at, 2 * log.timestamps[20].size() + 6, " " + early + " sim " + early);
  log.timestamps[20] = early;
  log.times[20] = std::stod(early);
  dir.write("back.log", log.text);
  dir.write("back.relations", relations_text(log));
  const auto r = run_fleetmap("slam --log back.log --relations back.relations --out o -q", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto m = nlohmann::json::parse(slurp(dir / "o" / "metrics.json"));
  EXPECT_EQ(m["relations"]["matched"], m["relations"]["given"]);
  EXPECT_LT(m["relations"]["translation_mean_m"].get<double>(), 0.05);
}

TEST(SlamLogCommand, BadInputGetsOneLineAndWritesNothing) {
  TempDir dir;
  LogFiles files(dir);
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --log missing.log --out o", dir), "missing.log");
  // A word where the third scan's tenth range belongs.
  std::string text = files.log.text;
  std::size_t line_start = 0;
  for (int i = 0; i < 2; ++i) line_start = text.find('\n', line_start) + 1;
  std::size_t word = line_start;
  for (int i = 0; i < 11; ++i) word = text.find(' ', word) + 1;
  text.replace(word, text.find(' ', word) - word, "wall");
  dir.write("bad.log", text);
  const auto bad = run_fleetmap("slam --log bad.log --out o", dir);
  EXPECT_ONE_LINE_ERROR(bad, "bad.log:3");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(dir / "o"));
  // A relation whose time is no scan's.
  dir.write("far.relations", "5.5 1000.2 0.1 0 0 0 0 0\n");
  const auto far = run_fleetmap("slam --log sim.log --relations far.relations --out o", dir);
  EXPECT_ONE_LINE_ERROR(far, "far.relations:1");
  EXPECT_EQ(far.exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(dir / "o"));
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --log sim.log --method magic --out o", dir), "magic");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --log sim.log --runs 3 --out o", dir), "--runs");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --method rbpf --out o", dir), "--log");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --log sim.log --set localization.scans_per_submp=5 --out o", dir),
                        "did you mean 'scans_per_submap'");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --log sim.log --method rbpf --set localization.huber_scale=5 --out o", dir),
                        "localization 'rbpf' has no parameter 'huber_scale'");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --log sim.log --set strategy.beta=1 --out o", dir), "localization.KEY=VALUE");
  EXPECT_FALSE(std::filesystem::exists(dir / "o"));
}

}  // namespace
}  // namespace fleetmap::testing
