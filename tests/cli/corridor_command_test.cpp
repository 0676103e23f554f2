// `fleetmap slam --scenario` on a corridor experiment scenario (cli/corridor_command.cpp).
#include <gtest/gtest.h>

#include <filesystem>

#include "tests/cli_run.h"

namespace fleetmap::testing {
namespace {

const char* kSmall =
    "experiment: leon_corridor\nseed: 2\nworld:\n  length: 9\n  height: 7\n  corridor_width: 1.6\n"
    "drive:\n  laps: [1]\nmethods:\n  list: [ideal, scan-matching]\nmerge_by_detection:\n  orientation_errors_deg: [0, 5]\n";

TEST(CorridorCommand, RunsTheExperimentAndWritesItsOutputs) {
  TempDir dir;
  dir.write("small.yaml", kSmall);
  const auto r = run_fleetmap("slam --scenario small.yaml --out res --quiet", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("| Length (m) | 9.0 |"), std::string::npos) << r.out;
  for (const char* name : {"corridor_table.md", "corridor_table.csv", "corridor.json", "corridor_scan-matching_1lap.png",
                           "merge_detection.csv", "merge_detection_5p0deg.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / "res" / name)) << name;
  }
}

TEST(CorridorCommand, BadInputIsOneLine) {
  TempDir dir;
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario missing.yaml --quiet", dir), "missing.yaml");
  dir.write("other.yaml", "experiment: leon_corridr\n");  // not the corridor: the seed-000 loader refuses it
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario other.yaml --quiet", dir), "other.yaml");
  dir.write("bad.yaml", "experiment: leon_corridor\ndrive:\n  speed: -1\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario bad.yaml --quiet", dir), "speed");
  dir.write("broken.yaml", "experiment: [\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario broken.yaml --quiet", dir), "broken.yaml");
}

}  // namespace
}  // namespace fleetmap::testing
