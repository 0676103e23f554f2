// Same inputs, same numbers, release after release: a few runs covering every strategy, several
// localizers and the three merging modes must give exactly the metrics.json (timing apart) kept in
// tests/data/golden/. A change that moves code must leave them alone; a change that means to
// change behaviour regenerates them (FLEETMAP_UPDATE_GOLDEN=1 ctest -R GoldenRuns) and says so.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "io/file_io.h"
#include "tests/cli_run.h"

namespace fleetmap::cli {
namespace {

namespace fs = std::filesystem;
using fleetmap::testing::run_fleetmap;
using fleetmap::testing::slurp;
using fleetmap::testing::TempDir;

struct GoldenRun {
  std::string name;
  std::string args;  // after `fleetmap explore`
};

class GoldenRuns : public ::testing::TestWithParam<GoldenRun> {};

TEST_P(GoldenRuns, MetricsAreTheKeptOnes) {
  const GoldenRun& run = GetParam();
  TempDir dir;
  const std::string scenarios = std::string(FLEETMAP_SOURCE_DIR) + "/scenarios/";
  std::string args = run.args;
  for (std::size_t at; (at = args.find("SCENARIOS/")) != std::string::npos;) args.replace(at, 10, scenarios);
  const auto r = run_fleetmap("explore " + args + " --out run --quiet", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto metrics = nlohmann::json::parse(slurp(dir / "run" / "metrics.json"));
  metrics.erase("timing");
  const fs::path golden = fs::path(FLEETMAP_SOURCE_DIR) / "tests/data/golden" / (run.name + ".json");
  if (const char* update = std::getenv("FLEETMAP_UPDATE_GOLDEN"); update && std::string(update) == "1") {
    io::write_file_atomic(golden, metrics.dump(1) + "\n");
  }
  ASSERT_TRUE(fs::exists(golden)) << golden << " is missing: FLEETMAP_UPDATE_GOLDEN=1 writes it";
  const auto kept = nlohmann::json::parse(slurp(golden));
  EXPECT_EQ(metrics, kept) << "metrics of `fleetmap explore " << args << "` changed; compare " << golden;
}

const GoldenRun kGoldenRuns[] = {
    {"office_directional", "--map office --robots 4 --steps 150"},
    {"cave_coordinated_comm10", "--map cave --robots 3 --strategy coordinated --comm-range 10 --steps 150 --seed 2"},
    {"maze_market_odometry", "--map maze --robots 3 --strategy market --localization odometry --steps 120"},
    {"corridor_optimized", "--map corridor --robots 5 --strategy optimized --steps 100 --seed 4"},
    {"unstructured_uncoordinated", "--map unstructured --robots 2 --strategy uncoordinated --steps 120"},
    {"warehouse_ekf_landmarks", "--scenario SCENARIOS/warehouse_landmarks.yaml --steps 80"},
    {"office_rendezvous", "--scenario SCENARIOS/office_rendezvous.yaml --steps 80"},
    {"office_overlap", "--map office --robots 2 --merging overlap --steps 60 --seed 3"},
    {"office_scan_matching", "--map office --robots 2 --localization scan-matching --steps 40"},
    {"office_astar_paths", "--map office --robots 2 --path-planner astar --steps 80"},
};

INSTANTIATE_TEST_SUITE_P(KeptRuns, GoldenRuns, ::testing::ValuesIn(kGoldenRuns),
                         [](const ::testing::TestParamInfo<GoldenRun>& info) { return info.param.name; });

}  // namespace
}  // namespace fleetmap::cli
