// End-to-end: `fleetmap slam` on a map-alignment scenario (experiment: landmark_alignment).
#include <gtest/gtest.h>

#include <filesystem>

#include "tests/cli_run.h"

namespace fleetmap::cli {
namespace {

using fleetmap::testing::run_fleetmap;
using fleetmap::testing::slurp;
using fleetmap::testing::TempDir;

// Two robots crossing a strip of landmarks; one run per part, two noise levels.
constexpr const char* kScenario = R"(experiment: landmark_alignment
runs: 1
particles: 10
sensors: {camera: {max_range: 40}}
landmarks:
  fields:
    - {area: [-25, -12, 25, 12], count: 60}
cases:
  - name: strip
    steps: 80
    robots:
      - {name: a, start: [-20, 0, 0], path: [[15, 0]]}
      - {name: b, start: [20, 3, 30], path: [[-15, 3]]}
parts:
  table1: strip
  noise: {case: strip, range_noise: [0.1, 1]}
  merges: [strip]
)";

TEST(LandmarkCommand, WritesTheTablesFigureTwoAndTheGlobalMap) {
  TempDir dir;
  dir.write("strip.yaml", kScenario);
  const auto r = run_fleetmap("slam --scenario strip.yaml --out out", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"alignment_tables.md", "rendezvous.csv", "fig2_noise.csv", "fig2_noise.png", "global_map_strip.png"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / f)) << f;
  }
  EXPECT_NE(r.out.find("Table I"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("warning: \"Map alignment using data association\""), std::string::npos) << r.out;
  const std::string fig2 = slurp(dir / "out" / "fig2_noise.csv");
  EXPECT_EQ(std::count(fig2.begin(), fig2.end(), '\n'), 3);  // header and two noise levels
}

TEST(LandmarkCommand, BadInputIsOneLine) {
  TempDir dir;
  dir.write("bad_key.yaml", std::string(kScenario) + "speed_limit: 3\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario bad_key.yaml", dir), "unknown key 'speed_limit'");
  std::string far = kScenario;
  far.replace(far.find("max_range: 40"), 13, "max_range: 2");
  dir.write("far.yaml", far);
  EXPECT_ONE_LINE_ERROR(run_fleetmap("slam --scenario far.yaml --out far", dir), "apart at the rendezvous");
  EXPECT_FALSE(std::filesystem::exists(dir / "far"));  // nothing written
}

}  // namespace
}  // namespace fleetmap::cli
