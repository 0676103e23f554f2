// End-to-end: `fleetmap slam` as a user runs it.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <opencv2/imgcodecs.hpp>

#include "tests/cli_run.h"

namespace fleetmap::cli {
namespace {

using fleetmap::testing::run_fleetmap;
using fleetmap::testing::slurp;
using fleetmap::testing::TempDir;

std::string scenario() { return std::string("'") + FLEETMAP_SOURCE_DIR + "/scenarios/dalfonso_3robots.yaml'"; }

TEST(SlamCommand, WritesTable1AndTheFigures) {
  TempDir dir;
  const auto r = run_fleetmap("slam --scenario " + scenario() + " --runs 2 --jobs 2 --out out", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");  // no progress bar when stderr is not a terminal
  for (const char* f : {"table1.md", "table1.csv", "runs.csv", "rendezvous.csv", "map_r1.png", "map_r2.png", "map_r3.png",
                        "map_r3_alone.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / f)) << f;
  }
  EXPECT_NE(r.out.find("mean ± standard deviation over 2 runs"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("all outputs in out/"), std::string::npos) << r.out;
  const std::string runs = slurp(dir / "out" / "runs.csv");
  EXPECT_EQ(std::count(runs.begin(), runs.end(), '\n'), 1 + 2 * 3 + 2);  // header, 2 runs x 3 robots, 2 single-robot runs
  const cv::Mat figure = cv::imread((dir / "out" / "map_r3.png").string());
  EXPECT_GE(figure.cols, 800);
  // The same command gives the same numbers (everything but tau).
  const auto again = run_fleetmap("slam --scenario " + scenario() + " --runs 2 --jobs 1 --out again -q", dir);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(again.out, "again/table1.md\n");
  const auto without_tau = [](std::string csv) {
    std::string out;
    std::size_t start = 0;
    while (start < csv.size()) {
      const std::size_t end = csv.find('\n', start);
      const std::string line = csv.substr(start, end - start);
      if (line.rfind("tau_ms", 0) != 0) out += line + "\n";
      start = end == std::string::npos ? csv.size() : end + 1;
    }
    return out;
  };
  EXPECT_EQ(without_tau(slurp(dir / "out" / "table1.csv")), without_tau(slurp(dir / "again" / "table1.csv")));
}

TEST(SlamCommand, BadInputGetsOneLine) {
  TempDir dir;
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam", dir), "--scenario");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario missing.yaml", dir), "missing.yaml");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario " + scenario() + " --runs 0", dir), "--runs");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario " + scenario() + " --jobs x", dir), "--jobs");
  dir.write("bad_key.yaml", slurp(std::string(FLEETMAP_SOURCE_DIR) + "/scenarios/dalfonso_3robots.yaml") + "speed: 3\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario bad_key.yaml", dir), "unknown key 'speed'");
  dir.write("bad_value.yaml", "method: polynomial\nsteps: -3\nroom: {boundary: [[0, 0], [4, 0], [4, 3]]}\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario bad_value.yaml", dir), "steps");
  dir.write("bad_method.yaml", "method: magic\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario bad_method.yaml", dir), "magic");
  dir.write("wall.yaml", "room: {boundary: [[0, 0], [4, 0], [4, 3], [0, 3]]}\n"
                         "robots: {team: [{name: a, start: [1, 1, 0], path: [[9, 1]]}]}\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario wall.yaml", dir), "within its radius of a wall");
}

// --runs, --jobs, --sampled-start and --exact-start only where the scenario's experiment uses them.
TEST(SlamCommand, FlagsTheExperimentDoesNotUseAreRefused) {
  TempDir dir;
  const std::string src = std::string(FLEETMAP_SOURCE_DIR) + "/scenarios/";
  for (const std::string flag : {"--runs 5", "--jobs 2", "--sampled-start", "--exact-start"}) {
    const auto r = run_fleetmap("slam --scenario " + src + "leon_corridor.yaml " + flag + " --out out", dir);
    EXPECT_ONE_LINE_ERROR(r, flag.substr(0, flag.find(' ')) + " does not apply to the leon_corridor experiment of " + src +
                                 "leon_corridor.yaml");
  }
  for (const std::string flag : {"--sampled-start", "--exact-start"}) {
    const auto r = run_fleetmap("slam --scenario " + src + "landmark_alignment.yaml " + flag + " --out out", dir);
    EXPECT_ONE_LINE_ERROR(r, flag + " does not apply to the landmark_alignment experiment");
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
  // Where they apply they run, and -o names the output folder as --out does.
  const auto r = run_fleetmap("slam --scenario " + scenario() + " --runs 1 --jobs 1 --sampled-start -q -o short", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "short/table1.md\n");
}

// The scenario's method is built from its declared parameters; --set changes one for this run.
TEST(SlamCommand, SetsTheMethodsParameters) {
  TempDir dir;
  const auto base = run_fleetmap("slam --scenario " + scenario() + " --runs 1 -q -o base", dir);
  ASSERT_EQ(base.exit_code, 0) << base.err;
  // Straight lines only: the maps hold other polynomials, so the table differs.
  const auto lines = run_fleetmap("slam --scenario " + scenario() + " --runs 1 --set method.order=1 -q -o lines", dir);
  ASSERT_EQ(lines.exit_code, 0) << lines.err;
  EXPECT_NE(slurp(dir / "base" / "runs.csv"), slurp(dir / "lines" / "runs.csv"));
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario " + scenario() + " --set method.ordr=1 -o bad", dir),
                        "did you mean 'order'");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario " + scenario() + " --set method.order=12 -o bad", dir),
                        "a whole number from 1 to 9");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario " + scenario() + " --set method.rho_min=0.5 -o bad", dir),
                        "rho_max");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario " + scenario() + " --set localization.order=1 -o bad", dir),
                        "takes method.KEY=VALUE");
  EXPECT_FALSE(std::filesystem::exists(dir / "bad"));
  const std::string corridor = std::string(FLEETMAP_SOURCE_DIR) + "/scenarios/leon_corridor.yaml";
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario " + corridor + " --set method.order=1 -o bad", dir),
                        "--set does not apply to the leon_corridor experiment");
  // The explorer's `polynomial` localizer declares the same parameters.
  const auto listed = run_fleetmap("plugins --family slam-method", dir);
  EXPECT_NE(listed.out.find("order = 3"), std::string::npos) << listed.out;
  const auto r = run_fleetmap("explore --map office --robots 1 --localization polynomial --set localization.order=1 "
                              "--steps 20 --out ex",
                              dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(slurp(dir / "ex" / "scenario.yaml").find("order: 1"), std::string::npos);
}

TEST(SlamCommand, ExploreUsesThePolynomialLocalizer) {
  // The same filter as `explore --localization polynomial`: it learns polynomials from the scan
  // and keeps every robot within 3 sigma of P0 (0.05 m) of the truth over a short run.
  TempDir dir;
  const auto r = run_fleetmap(
      "explore --map office --robots 2 --localization polynomial --steps 80 --out out",
      dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto m = nlohmann::json::parse(slurp(dir / "out" / "metrics.json"));
  for (const auto& robot : m["per_robot"]) {
    EXPECT_LT(robot["position_rmse_m"].get<double>(), 3 * 0.05) << robot.dump();
    EXPECT_GE(robot["localizer"]["polynomials"].get<double>(), 4.0) << robot.dump();
    EXPECT_GT(robot["localizer"]["polynomial_updates"].get<double>(), 100.0) << robot.dump();
  }
}

}  // namespace
}  // namespace fleetmap::cli
