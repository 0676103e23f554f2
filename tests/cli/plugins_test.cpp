// End-to-end: the declared parameters of strategies and localizers as a user meets them:
// `fleetmap plugins`, `--set FAMILY.KEY=VALUE` on explore and bench, `bench --vary FAMILY.KEY=...`,
// and the messages for a mistyped key, a value out of range, and a member without that parameter.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <set>

#include "tests/cli/bench_test_support.h"

namespace fleetmap::cli {
namespace {

using namespace fleetmap::testing;

TEST(PluginsCommand, ListsEveryFamilyWithTheDeclaredParameters) {
  TempDir dir;
  const auto all = run_fleetmap("plugins", dir);
  ASSERT_EQ(all.exit_code, 0) << all.err;
  for (const char* family : {"strategy (", "localization (", "merging (", "merge-method (", "planner (", "map ("}) {
    EXPECT_NE(all.out.find(family), std::string::npos) << family << " not in:\n" << all.out;
  }
  EXPECT_NE(all.out.find("  coordinated: "), std::string::npos);
  EXPECT_NE(all.out.find("      beta = 1  (a number >= 0 and <= 1000000): weight of travel cost"), std::string::npos) << all.out;
  EXPECT_NE(all.out.find("      weight = 0.5"), std::string::npos);
  const auto one = run_fleetmap("plugins --family strategy", dir);
  ASSERT_EQ(one.exit_code, 0) << one.err;
  EXPECT_EQ(one.out.find("planner ("), std::string::npos);
  EXPECT_ONE_LINE_ERROR(run_fleetmap("plugins --family strategies", dir), "did you mean 'strategy'");
  // explore --help lists the strategies' parameters from the same declarations.
  EXPECT_NE(run_fleetmap("explore --help", dir).out.find("      beta = 1"), std::string::npos);
}

TEST(PluginsCommand, ExploreSetsAStrategysParameter) {
  TempDir dir;
  write_bench_maps(dir);
  const auto r = run_fleetmap("explore --map hall.yaml --robots 2 --steps 20 --strategy coordinated "
                              "--set strategy.beta=0.25 --out run", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(slurp(dir / "run" / "scenario.yaml").find("strategy: {name: coordinated, beta: 0.25}"), std::string::npos)
      << slurp(dir / "run" / "scenario.yaml");
  // The saved scenario runs again as it was.
  const auto again = run_fleetmap("explore --scenario run/scenario.yaml --out again", dir);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(slurp(dir / "again" / "scenario.yaml"), slurp(dir / "run" / "scenario.yaml"));
}

TEST(PluginsCommand, BadSettingsAreOneLineNamingTheSetting) {
  TempDir dir;
  write_bench_maps(dir);
  const std::string run = "explore --map hall.yaml --robots 1 --steps 5 --out out ";
  EXPECT_ONE_LINE_ERROR(run_fleetmap(run + "--strategy coordinated --set strategy.bta=1", dir), "did you mean 'beta'");
  EXPECT_ONE_LINE_ERROR(run_fleetmap(run + "--strategy coordinated --set strategy.beta=-1", dir), "a number >= 0");
  EXPECT_ONE_LINE_ERROR(run_fleetmap(run + "--strategy market --set strategy.beta=1", dir),
                        "strategy 'market' has no parameter 'beta' (it has none)");
  EXPECT_ONE_LINE_ERROR(run_fleetmap(run + "--set beta=1", dir), "--set beta=1: expected FAMILY.KEY=VALUE");
  EXPECT_ONE_LINE_ERROR(run_fleetmap(run + "--set strategi.beta=1", dir), "did you mean 'strategy'");
  EXPECT_FALSE(std::filesystem::exists(dir / "out")) << "nothing written for bad input";
  const std::string bench = "bench --maps hall.yaml --robots 1 --seeds 1 --steps 5 --out b ";
  EXPECT_ONE_LINE_ERROR(run_fleetmap(bench + "--strategies coordinated,market --set strategy.weight=1", dir),
                        "no strategy of this sweep (coordinated, market) has a parameter 'weight'");
  EXPECT_ONE_LINE_ERROR(run_fleetmap(bench + "--strategies coordinated --vary strategy.bta=1,2", dir),
                        "no strategy has a parameter 'bta' (did you mean 'beta'?)");
  EXPECT_ONE_LINE_ERROR(run_fleetmap(bench + "--strategies coordinated --vary strategy.beta=1,-2", dir), "-2");
  EXPECT_FALSE(std::filesystem::exists(dir / "b"));
}

TEST(PluginsCommand, BenchVariesAParameterOfTheStrategiesThatDeclareIt) {
  TempDir dir;
  write_bench_maps(dir);
  const auto r = run_fleetmap("bench --maps hall.yaml --strategies coordinated,market --robots 2 --seeds 1 --steps 60 "
                              "--vary strategy.beta=0,5 --out b", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CsvTable results = read_csv(dir / "b" / "results.csv");
  ASSERT_EQ(results.rows.size(), 4u);
  std::map<std::string, std::string> coverage;
  for (const auto& row : results.rows) coverage[row.at("strategy") + " " + row.at("variant")] = row.at("coverage");
  ASSERT_EQ(coverage.size(), 4u);
  // market declares no beta: its two runs are the same run.
  EXPECT_EQ(coverage.at("market strategy.beta=0"), coverage.at("market strategy.beta=5"));
}

TEST(PluginsCommand, ExploreSetsALocalizersParameter) {
  TempDir dir;
  write_bench_maps(dir);
  const auto r = run_fleetmap("explore --map hall.yaml --robots 1 --steps 10 --localization rbpf "
                              "--set localization.particles=3 --out run", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string scenario = slurp(dir / "run" / "scenario.yaml");
  EXPECT_NE(scenario.find("  method: rbpf\n"), std::string::npos) << scenario;
  EXPECT_NE(scenario.find("  particles: 3\n"), std::string::npos) << scenario;
  const auto again = run_fleetmap("explore --scenario run/scenario.yaml --out again", dir);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(slurp(dir / "again" / "scenario.yaml"), scenario);
  EXPECT_NE(run_fleetmap("plugins --family localization", dir).out.find("      particles = 30  (a whole number"),
            std::string::npos);
}

TEST(PluginsCommand, BadLocalizerSettingsAreOneLineNamingTheSetting) {
  TempDir dir;
  write_bench_maps(dir);
  const std::string run = "explore --map hall.yaml --robots 1 --steps 5 --out out ";
  EXPECT_ONE_LINE_ERROR(run_fleetmap(run + "--localization scan-matching --set localization.particles=3", dir),
                        "localization 'scan-matching' has no parameter 'particles' (it has none)");
  EXPECT_ONE_LINE_ERROR(run_fleetmap(run + "--localization rbpf --set localization.particels=3", dir),
                        "did you mean 'particles'");
  EXPECT_ONE_LINE_ERROR(run_fleetmap(run + "--localization mcl --set localization.particles=0.5", dir), "a whole number");
  EXPECT_FALSE(std::filesystem::exists(dir / "out")) << "nothing written for bad input";
  const std::string bench = "bench --maps hall.yaml --strategies coordinated --robots 1 --seeds 1 --steps 5 --out b ";
  EXPECT_ONE_LINE_ERROR(run_fleetmap(bench + "--localization scan-matching --set localization.particles=3", dir),
                        "no localization of this sweep (scan-matching) has a parameter 'particles'");
  EXPECT_ONE_LINE_ERROR(run_fleetmap(bench + "--vary localization.particls=1,2", dir),
                        "no localization has a parameter 'particls' (did you mean 'particles'?)");
  EXPECT_FALSE(std::filesystem::exists(dir / "b"));
}

// A localizer parameter swept beside a localizer axis: the localizers that declare it run once per
// value, the others once per value unchanged.
TEST(PluginsCommand, BenchVariesAParameterOfTheLocalizersThatDeclareIt) {
  TempDir dir;
  write_bench_maps(dir);
  const auto r = run_fleetmap("bench --maps hall.yaml --strategies coordinated --robots 1 --seeds 1 --steps 30 "
                              "--vary localization=odometry,fastslam-grid --vary localization.particles=1,8 --vary noise_position=0.02 "
                              "--out b", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CsvTable results = read_csv(dir / "b" / "results.csv");
  ASSERT_EQ(results.rows.size(), 4u);
  std::map<std::string, std::string> error;
  const std::string noise = " noise_position=0.02";
  for (const auto& row : results.rows) error[row.at("variant").substr(0, row.at("variant").size() - noise.size())] = row.at("position_rmse_m");
  ASSERT_EQ(error.size(), 4u) << r.out;
  EXPECT_EQ(error.at("localization=odometry localization.particles=1"), error.at("localization=odometry localization.particles=8"));
  EXPECT_NE(error.at("localization=fastslam-grid localization.particles=1"),
            error.at("localization=fastslam-grid localization.particles=8"));
}

// The overlap aligner's method and threshold, as parameters like any other member's.
TEST(PluginsCommand, TheAlignersParametersAreSetAndCheckedLikeTheOthers) {
  TempDir dir;
  write_bench_maps(dir);
  const std::string run = "explore --map hall.yaml --robots 2 --steps 5 --merging overlap ";
  const auto r = run_fleetmap(run + "--set merging.method=features --set merging.min_confidence=0.7 --out run", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string scenario = slurp(dir / "run" / "scenario.yaml");
  EXPECT_NE(scenario.find("  mode: overlap\n  attempt_every: 20\n  method: features\n  min_confidence: 0.7\n"), std::string::npos)
      << scenario;
  EXPECT_ONE_LINE_ERROR(run_fleetmap(run + "--set merging.method=overlap --out bad", dir), "'overlap' is now called 'grid'");
  EXPECT_ONE_LINE_ERROR(run_fleetmap(run + "--set merging.min_confidence=2 --out bad", dir), "min_confidence");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --map hall.yaml --robots 2 --steps 5 --merging rendezvous "
                                     "--set merging.method=grid --out bad", dir),
                        "merging 'rendezvous' has no parameter 'method' (it has none)");
  EXPECT_FALSE(std::filesystem::exists(dir / "bad"));
  // A file written before the aligners declared their parameters still reads.
  dir.write("old.yaml", "map: hall.yaml\nsteps: 5\nmerging: {mode: known, method: auto, min_confidence: 0.5, attempt_every: 20}\n");
  const auto old = run_fleetmap("explore --scenario old.yaml --out old", dir);
  EXPECT_EQ(old.exit_code, 0) << old.err;
  dir.write("wrong.yaml", "map: hall.yaml\nsteps: 5\nmerging: {mode: rendezvous, min_confidence: 0.9}\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --scenario wrong.yaml --out wrong", dir),
                        "merging 'rendezvous' has no parameter 'min_confidence'");
}

// The merge methods the overlap aligner runs have their own parameters, nested under merging.
TEST(PluginsCommand, TheMergeMethodsParametersAreSetUnderMerging) {
  TempDir dir;
  const std::string run = "explore --map office --robots 2 --starts random --min-separation 4 --steps 150 --merging overlap "
                          "--set merging.method=features ";
  // More inliers than any ORB model can have: no candidate; a loose ratio test and few inliers: some.
  const auto strict = run_fleetmap(run + "--set merging.features.min_inliers=10000 --out strict", dir);
  ASSERT_EQ(strict.exit_code, 0) << strict.err;
  const auto loose = run_fleetmap(run + "--set merging.features.ratio=1 --set merging.features.min_inliers=3 --out loose", dir);
  ASSERT_EQ(loose.exit_code, 0) << loose.err;
  const std::string scenario = slurp(dir / "loose" / "scenario.yaml");
  EXPECT_NE(scenario.find("  method: features\n  features: {ratio: 1, min_inliers: 3}\n"), std::string::npos) << scenario;
  const auto reasons = [&](const char* out) {
    const auto metrics = nlohmann::json::parse(slurp(dir / out / "metrics.json"));
    std::set<std::string> r;
    for (const auto& m : metrics["merges"]) r.insert(m.value("reason", ""));
    return r;
  };
  EXPECT_EQ(reasons("strict"), std::set<std::string>{"no reliable overlap: no candidate transform"});
  EXPECT_FALSE(reasons("loose").contains("no reliable overlap: no candidate transform"));
  const auto again = run_fleetmap("explore --scenario loose/scenario.yaml --out again", dir);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(slurp(dir / "again" / "scenario.yaml"), scenario);
  EXPECT_ONE_LINE_ERROR(run_fleetmap(run + "--set merging.features.ratoi=1 --out bad", dir), "did you mean 'ratio'");
  EXPECT_ONE_LINE_ERROR(run_fleetmap(run + "--set merging.features.ratio=2 --out bad", dir), "<= 1");
  EXPECT_ONE_LINE_ERROR(run_fleetmap(run + "--set merging.method=grid --set merging.features.ratio=0.5 --out bad", dir),
                        "merge method 'grid' does not run 'features'");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --map office --robots 2 --steps 5 --merging rendezvous "
                                     "--set merging.features.ratio=0.5 --out bad", dir),
                        "runs no merge method");
  EXPECT_FALSE(std::filesystem::exists(dir / "bad"));
  // A sweep axis like any other parameter.
  const auto b = run_fleetmap("bench --maps office --strategies coordinated --robots 2 --seeds 1 --steps 20 --merging overlap "
                              "--vary merging.features.ratio=0.7,0.9 --out b", dir);
  ASSERT_EQ(b.exit_code, 0) << b.err;
  const CsvTable results = read_csv(dir / "b" / "results.csv");
  ASSERT_EQ(results.rows.size(), 2u);
  EXPECT_EQ(results.rows[0].at("variant"), "merging.features.ratio=0.7");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("bench --maps office --strategies coordinated --robots 2 --seeds 1 --steps 20 "
                                     "--merging overlap --vary merging.features.ratoi=0.7 --out b2", dir),
                        "did you mean 'ratio'");
}

// The planners' parameters: plan --set, and a path planner's in explore's scenario.
TEST(PluginsCommand, APlannersParametersAreSetFromPlanAndExplore) {
  TempDir dir;
  write_bench_maps(dir);
  const std::string plan = "plan --map hall.yaml --from 1,1 --to 5,3 --planner reactive ";
  const auto narrow = run_fleetmap(plan + "--json a.json", dir);
  const auto wide = run_fleetmap(plan + "--set planner.look_ahead=0.01 --json b.json", dir);
  ASSERT_EQ(narrow.exit_code, 0) << narrow.err;
  ASSERT_EQ(wide.exit_code, 0) << wide.err;
  EXPECT_ONE_LINE_ERROR(run_fleetmap(plan + "--set planner.turn_angle_deg=200 --json c.json", dir), "turn_angle_deg");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("plan --map hall.yaml --from 1,1 --to 5,3 --planner astar --set planner.step=1", dir),
                        "planner 'astar' has no parameter 'step' (it has none)");
  EXPECT_ONE_LINE_ERROR(run_fleetmap(plan + "--set strategy.beta=1", dir), "plan takes planner.KEY=VALUE");
  EXPECT_FALSE(std::filesystem::exists(dir / "c.json"));
  const auto r = run_fleetmap("explore --map hall.yaml --robots 1 --steps 5 --path-planner reactive "
                              "--set planner.turn_angle_deg=20 --out run", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(slurp(dir / "run" / "scenario.yaml").find("path_planner: {name: reactive, turn_angle_deg: 20}"), std::string::npos)
      << slurp(dir / "run" / "scenario.yaml");
}

}  // namespace
}  // namespace fleetmap::cli
