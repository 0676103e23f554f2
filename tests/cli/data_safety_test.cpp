// A user's data is never lost or mixed up: no output replaces an input, outputs land in folders
// the run owns (and an earlier run's stale files go), "-" is the standard output, a saved
// scenario finds its own map from anywhere, and runs with a sampling path planner repeat exactly.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "tests/cli_run.h"

namespace fleetmap::cli {
namespace {

namespace fs = std::filesystem;
using fleetmap::testing::run_fleetmap;
using fleetmap::testing::slurp;
using fleetmap::testing::TempDir;

// The fleetmap binary, quoted for the shell.
std::string binary() { return "'" + std::string(FLEETMAP_BINARY) + "'"; }
// run_fleetmap's arguments that run `shell` instead (after a harmless first call): for a command in
// another folder or under a resource limit. Its output is what is captured.
std::string then(const std::string& shell) { return "--version >/dev/null && " + shell; }

nlohmann::json metrics_without_timing(const fs::path& dir) {
  auto m = nlohmann::json::parse(slurp(dir / "metrics.json"));
  m.erase("timing");
  return m;
}

// A 6 x 4 m room with a dividing wall and a door, as map<ext> + map.yaml in `folder`.
void write_room_map(const TempDir& dir, const std::string& folder, const std::string& ext = ".pgm") {
  cv::Mat img(40, 60, CV_8UC1, cv::Scalar(254));
  cv::rectangle(img, cv::Rect(0, 0, 60, 40), cv::Scalar(0), 1);
  cv::line(img, cv::Point(30, 0), cv::Point(30, 39), cv::Scalar(0), 1);
  cv::line(img, cv::Point(30, 15), cv::Point(30, 24), cv::Scalar(254), 1);
  std::vector<unsigned char> bytes;
  cv::imencode(ext, img, bytes);
  dir.write(folder + "/map" + ext, std::string(bytes.begin(), bytes.end()));
  dir.write(folder + "/map.yaml", "image: map" + ext + "\nresolution: 0.1\n");
}

// A plan's JSON without its timings.
nlohmann::json untimed(nlohmann::json j) {
  j.erase("time_s");
  j.erase("first_solution_s");
  return j;
}

TEST(DataSafety, ExploreNeverWritesOverItsInputMap) {
  TempDir dir;
  write_room_map(dir, "D");
  const std::string before = slurp(dir / "D" / "map.pgm");
  const auto r = run_fleetmap("explore --map D/map.yaml --robots 2 --steps 20 --out D", dir);
  EXPECT_ONE_LINE_ERROR(r, "--out D: D/map.pgm: is the input D/map.pgm; fleetmap never overwrites an input");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(slurp(dir / "D" / "map.pgm"), before);
  EXPECT_FALSE(fs::exists(dir / "D" / "merged.png"));
  // maps show, merge and plan: the image a YAML names is an input too.
  write_room_map(dir, "P", ".png");
  const std::string picture = slurp(dir / "P" / "map.png");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("maps show P/map.yaml --out P/map.png", dir), "is the input P/map.png");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("plan --map P/map.yaml --from 1,1 --to 2,2 --out P/map.png", dir),
                        "is the input P/map.png");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("merge P/map.yaml D/map.yaml --out P/map.png", dir), "is the input P/map.png");
  EXPECT_EQ(slurp(dir / "P" / "map.png"), picture);
  // An earlier run's map file used as this run's map, with the same --out: refused before the run.
  ASSERT_EQ(run_fleetmap("explore --map D/map.yaml --robots 1 --steps 5 --out run", dir).exit_code, 0);
  const std::string earlier = slurp(dir / "run" / "map.pgm");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --map run/map.yaml --robots 1 --steps 5 --out run", dir),
                        "is the input run/map");
  EXPECT_EQ(slurp(dir / "run" / "map.pgm"), earlier);
}

TEST(DataSafety, ARunIntoAnEarlierRunsFolderReplacesItsFilesAndRemovesStaleOnes) {
  TempDir dir;
  write_room_map(dir, "maps");
  ASSERT_EQ(run_fleetmap("explore --map maps/map.yaml --robots 4 --steps 3 --animate --plan-from 1,1 --plan-to 2,2 "
                         "--out run",
                         dir)
                .exit_code,
            0);
  for (const char* f : {"robot_3.png", "robot_4.png", "run.mp4", "path.json"}) ASSERT_TRUE(fs::exists(dir / "run" / f)) << f;
  const auto r = run_fleetmap("explore --map maps/map.yaml --robots 2 --steps 3 --out run", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"robot_3.png", "robot_4.png", "run.mp4", "path.json"}) EXPECT_FALSE(fs::exists(dir / "run" / f)) << f;
  EXPECT_EQ(metrics_without_timing(dir / "run")["robots"], 2);
  // A folder with a file of the user's is not taken, and the file stays.
  dir.write("mine/notes.txt", "keep me");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --map maps/map.yaml --robots 1 --steps 3 --out mine", dir),
                        "holds a file that no earlier 'fleetmap explore' run wrote ('notes.txt')");
  EXPECT_EQ(slurp(dir / "mine" / "notes.txt"), "keep me");
}

TEST(DataSafety, ASavedScenarioRunsOnItsOwnMapFromAnyFolder) {
  TempDir dir;
  write_room_map(dir, "maps");
  // The run's own outputs include a map.yaml; the replay must not take it for the scenario's map.
  ASSERT_EQ(run_fleetmap("explore --map maps/map.yaml --robots 2 --steps 30 --out first", dir).exit_code, 0);
  EXPECT_NE(slurp(dir / "first" / "scenario.yaml").find("map: \"../maps/map.yaml\""), std::string::npos);
  dir.write("elsewhere/.keep", "");
  const auto replay = run_fleetmap(then("cd elsewhere && " + binary() + " explore --scenario ../first/scenario.yaml --out ../again"), dir);
  ASSERT_EQ(replay.exit_code, 0) << replay.err;
  EXPECT_EQ(metrics_without_timing(dir / "first").dump(), metrics_without_timing(dir / "again").dump());
}

TEST(DataSafety, DashAndDevStdoutAreTheStandardOutputAndLinksAreFollowed) {
  TempDir dir;
  write_room_map(dir, "maps");
  const auto json = run_fleetmap("plan --map maps/map.yaml --from 1,1 --to 2,2 --planner astar --json -", dir);
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const auto j = untimed(nlohmann::json::parse(json.out));  // nothing but the JSON on stdout
  EXPECT_EQ(j["success"], true);
  EXPECT_NE(json.err.find("astar:"), std::string::npos);  // the report moved to stderr
  const auto also = run_fleetmap("plan --map maps/map.yaml --from 1,1 --to 2,2 --planner astar --json /dev/stdout", dir);
  EXPECT_EQ(untimed(nlohmann::json::parse(also.out)), j);
  EXPECT_TRUE(fs::is_symlink("/dev/stdout") || fs::is_character_file("/dev/stdout"));
  const auto png = run_fleetmap("maps show maps/map.yaml --out -", dir);
  ASSERT_EQ(png.exit_code, 0) << png.err;
  const std::vector<unsigned char> bytes(png.out.begin(), png.out.end());
  EXPECT_FALSE(cv::imdecode(bytes, cv::IMREAD_UNCHANGED).empty());
  fs::create_symlink("real.json", dir / "link.json");
  ASSERT_EQ(run_fleetmap("plan --map maps/map.yaml --from 1,1 --to 2,2 --planner astar --json link.json", dir).exit_code, 0);
  EXPECT_TRUE(fs::is_symlink(dir / "link.json"));
  EXPECT_EQ(untimed(nlohmann::json::parse(slurp(dir / "real.json"))), j);
}

TEST(DataSafety, ASamplingPathPlannerGivesTheSameRunTwice) {
  TempDir dir;
  for (const char* planner : {"rrtstar", "bitstar"}) {
    const std::string args = std::string("explore --map office --robots 2 --steps 40 --path-planner ") + planner;
    ASSERT_EQ(run_fleetmap(args + " --out a", dir).exit_code, 0);
    ASSERT_EQ(run_fleetmap(args + " --out b", dir).exit_code, 0);
    EXPECT_EQ(metrics_without_timing(dir / "a").dump(), metrics_without_timing(dir / "b").dump()) << planner;
  }
}

TEST(DataSafety, NamesWithControlCharactersCannotBreakTheOneLineMessage) {
  TempDir dir;
  const auto r = run_fleetmap("explore --map \"$(printf 'of\\001fi\\nce')\"", dir);
  EXPECT_ONE_LINE_ERROR(r, "unknown map 'of\\x01fi\\x0Ace'");
  EXPECT_EQ(r.exit_code, 2);
}

TEST(DataSafety, MessagesNameNumbersAsTyped) {
  TempDir dir;
  write_room_map(dir, "a");
  dir.write("b/map.yaml", "image: ../a/map.pgm\nresolution: 0.05\n");
  const auto r = run_fleetmap("merge a/map.yaml b/map.yaml --out m.png", dir);
  EXPECT_NE(r.out.find("maps of different resolutions: each pair aligned through the coarser one's cells, fused in a/map.yaml's 0.1 m cells"), std::string::npos) << r.out;
}

// A map of much coarser cells than the first would be resampled to more cells than a map may have.
TEST(DataSafety, AResampledMapOverTheCellLimitIsRefused) {
  TempDir dir;
  write_room_map(dir, "a");
  dir.write("b/map.yaml", "image: ../a/map.pgm\nresolution: 1000\n");
  const auto r = run_fleetmap("merge a/map.yaml b/map.yaml --out m.png", dir);
  EXPECT_ONE_LINE_ERROR(r, "b/map.yaml: its 1000 m cells seen through a/map.yaml's 0.1 m cells would make");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(dir / "m.png"));
}

#if !FLEETMAP_SANITIZED  // AddressSanitizer reserves more address space than the limit below
// A grey PNG whose header declares `width` x `height` pixels (its pixel data is a 1 x 1 image's).
std::string png_declaring(std::uint32_t width, std::uint32_t height) {
  std::vector<unsigned char> png;
  cv::imencode(".png", cv::Mat(1, 1, CV_8UC1, cv::Scalar(254)), png);
  const auto put32 = [&](std::size_t at, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) png[at + std::size_t(k)] = static_cast<unsigned char>(v >> (24 - 8 * k));
  };
  put32(16, width);
  put32(20, height);
  std::uint32_t crc = 0xFFFFFFFFu;  // the IHDR chunk's CRC-32, over its type and data (bytes 12..28)
  for (std::size_t i = 12; i < 29; ++i) {
    crc ^= png[i];
    for (int b = 0; b < 8; ++b) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  put32(29, crc ^ 0xFFFFFFFFu);
  return std::string(png.begin(), png.end());
}

TEST(DataSafety, OutOfMemoryIsOneClearLine) {
  TempDir dir;
  // 100000 x 100000 pixels, let through by --max-cells: decoding needs 10 GB, more than this run may have.
  dir.write("huge.png", png_declaring(100000, 100000));
  const auto r = run_fleetmap(then("ulimit -v 1000000 && " + binary() + " maps show huge.png --max-cells 100000000000"), dir);
  EXPECT_ONE_LINE_ERROR(r, "fleetmap: out of memory");
  EXPECT_EQ(r.exit_code, 1);
}
#endif

}  // namespace
}  // namespace fleetmap::cli
