// End-to-end: `fleetmap explore` as a user runs it.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "io/map_io.h"
#include "tests/cli_run.h"

namespace fleetmap::cli {
namespace {

using fleetmap::testing::run_fleetmap;
using fleetmap::testing::slurp;
using fleetmap::testing::TempDir;

nlohmann::json metrics(const std::filesystem::path& dir) { return nlohmann::json::parse(slurp(dir / "metrics.json")); }

TEST(ExploreCommand, WritesEveryOutputAndSaysWhere) {
  TempDir dir;
  const auto r = run_fleetmap("explore --map empty --robots 2 --steps 40 --out run", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"merged.png", "robot_1.png", "robot_2.png", "robot_1.yaml", "robot_1.pgm", "robot_2.yaml",
                        "robot_2.pgm", "metrics.json", "map.pgm", "map.yaml", "map.bt", "scenario.yaml"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / "run" / f)) << f;
  }
  EXPECT_NE(r.out.find("merged map: run/merged.png"), std::string::npos) << r.out;
  EXPECT_EQ(r.err, "");  // no progress bar when stderr is not a terminal, and no library chatter
  const cv::Mat merged = cv::imread((dir / "run" / "merged.png").string());
  EXPECT_GE(merged.cols, 800);
  const auto m = metrics(dir / "run");
  for (const char* key : {"map", "robots", "strategy", "seed", "steps", "coverage", "steps_to_95", "steps_to_99",
                          "distance_m", "redundancy", "bytes_sent", "timing"}) {
    EXPECT_TRUE(m.contains(key)) << key;
  }
  EXPECT_EQ(m["map"], "empty");
  EXPECT_EQ(m["robots"], 2);
  EXPECT_EQ(m["strategy"], "directional");
  EXPECT_EQ(m["steps"], 40);
  EXPECT_TRUE(m["steps_to_99"].is_null());  // 40 steps are not enough for 99%
  EXPECT_GT(m["coverage"].get<double>(), 0.1);
  // The map files are real maps: they load back.
  const auto back = run_fleetmap("maps show run/map.yaml --out back.png", dir);
  EXPECT_EQ(back.exit_code, 0) << back.err;
  // Each robot's map too, with a known cell for every cell its picture shows known.
  const auto robot = io::load_map(dir / "run" / "robot_1.yaml");
  EXPECT_GT(robot.known_count(), 0);
}

// The whole chain on files: explore, merge the robots' own maps, plan on the merged map.
TEST(ExploreCommand, TheRobotsMapsMergeAndThePlannerReadsTheResult) {
  TempDir dir;
  // 200 steps: enough for the two robots (who never talk) to map common walls worth a merge.
  ASSERT_EQ(run_fleetmap("explore --map office --robots 2 --comm-range 0 --steps 200 --out run", dir).exit_code, 0);
  const auto m = run_fleetmap("merge run/robot_1.yaml run/robot_2.yaml --out merged.yaml --json merge.json", dir);
  ASSERT_EQ(m.exit_code, 0) << m.err << m.out;
  // With known frames both maps are in the world frame: the transform is the identity (within a
  // cell of the robots' 0.1 m maps).
  const auto t = nlohmann::json::parse(slurp(dir / "merge.json"))["transforms"][0];
  EXPECT_LT(std::hypot(t["tx_m"].get<double>(), t["ty_m"].get<double>()), 0.1) << t.dump();
  EXPECT_LT(std::abs(t["theta_deg"].get<double>()), 0.5) << t.dump();
  const auto p = run_fleetmap("plan --map merged.yaml --from 3,15 --to 17,4 --planner astar", dir);
  EXPECT_EQ(p.exit_code, 0) << p.err << p.out;
}

TEST(ExploreCommand, RandomStartsSpreadTheTeamAndReplay) {
  TempDir dir;
  const auto r = run_fleetmap("explore --map office --robots 3 --starts random --min-separation 4 --steps 5 --out run", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto m = metrics(dir / "run");
  ASSERT_EQ(m["per_robot"].size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      const auto& a = m["per_robot"][i]["start"];
      const auto& b = m["per_robot"][j]["start"];
      EXPECT_GE(std::hypot(a[0].get<double>() - b[0].get<double>(), a[1].get<double>() - b[1].get<double>()), 4.0);
    }
  }
  EXPECT_NE(slurp(dir / "run" / "scenario.yaml").find("random: 3"), std::string::npos);
  const auto again = run_fleetmap("explore --scenario run/scenario.yaml --out again", dir);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(metrics(dir / "again")["per_robot"], m["per_robot"]);
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --starts everywhere --steps 1", dir), "everywhere");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --map office --robots 9 --starts random --min-separation 40 --steps 1", dir),
                        "fit");
}

TEST(ExploreCommand, SameCommandSameNumbers) {
  TempDir dir;
  const std::string args = " --map cave --robots 3 --strategy coordinated --steps 60";
  ASSERT_EQ(run_fleetmap("explore" + args + " --seed 5 --out a", dir).exit_code, 0);
  ASSERT_EQ(run_fleetmap("explore" + args + " --seed 5 --out b", dir).exit_code, 0);
  auto a = metrics(dir / "a"), b = metrics(dir / "b");
  a.erase("timing");
  b.erase("timing");
  EXPECT_EQ(a.dump(), b.dump());
  // Every output is byte for byte the same, apart from metrics.json's timing.
  for (const char* f : {"merged.png", "robot_1.png", "robot_2.png", "robot_3.png", "map.pgm", "map.yaml", "map.bt",
                        "scenario.yaml"}) {
    EXPECT_EQ(slurp(dir / "a" / f), slurp(dir / "b" / f)) << f;
  }
  ASSERT_EQ(run_fleetmap("explore" + args + " --seed 6 --out c", dir).exit_code, 0);
  auto c = metrics(dir / "c");
  c.erase("timing");
  EXPECT_NE(a.dump(), c.dump());
}

TEST(ExploreCommand, ScenarioFileAndFlagsThatOverrideIt) {
  TempDir dir;
  dir.write("s.yaml", "map: maze\nrobots: {count: 3}\nsteps: 25\nexploration: {strategy: market}\n");
  auto r = run_fleetmap("explore --scenario s.yaml --out s1", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto m = metrics(dir / "s1");
  EXPECT_EQ(m["map"], "maze");
  EXPECT_EQ(m["robots"], 3);
  EXPECT_EQ(m["strategy"], "market");
  r = run_fleetmap("explore --scenario s.yaml --strategy optimized --robots 2 --out s2", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  m = metrics(dir / "s2");
  EXPECT_EQ(m["strategy"], "optimized");
  EXPECT_EQ(m["robots"], 2);
  // The scenario written beside the outputs runs again to the same numbers.
  r = run_fleetmap("explore --scenario s2/scenario.yaml --out s3", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto a = metrics(dir / "s2"), b = metrics(dir / "s3");
  a.erase("timing");
  b.erase("timing");
  EXPECT_EQ(a.dump(), b.dump());
}

TEST(ExploreCommand, AnimateWritesAVideo) {
  TempDir dir;
  const auto r = run_fleetmap("explore --map empty --robots 2 --steps 12 --animate --out v", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  cv::VideoCapture video((dir / "v" / "run.mp4").string());
  ASSERT_TRUE(video.isOpened());
  int frames = 0;
  cv::Mat frame;
  while (video.read(frame)) ++frames;
  EXPECT_EQ(frames, 13);  // the start and each of the 12 steps
  EXPECT_FALSE(std::filesystem::exists(dir / "v" / "run.partial.mp4"));
}

// The fourcc the file's first video stream holds, e.g. "avc1" (H.264).
std::string stream_fourcc(const std::filesystem::path& p) {
  cv::VideoCapture v(p.string());
  const int c = int(v.get(cv::CAP_PROP_FOURCC));
  return {char(c & 255), char((c >> 8) & 255), char((c >> 16) & 255), char((c >> 24) & 255)};
}

TEST(ExploreCommand, VideosAreH264OrWebmWhereOpenCVCanWriteThem) {
  TempDir dir;
  const auto r = run_fleetmap("explore --map empty --robots 2 --steps 4 --video run.webm --out w", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  cv::VideoCapture webm((dir / "w" / "run.webm").string());
  ASSERT_TRUE(webm.isOpened());
  cv::Mat frame;
  ASSERT_TRUE(webm.read(frame));
  // The WebM muxer takes only VP8, VP9 or AV1, so a file that opens holds one of them; no fallback note.
  EXPECT_EQ(r.err.find("cannot write"), std::string::npos) << r.err;
  // --animate: H.264 in MP4 where OpenCV's FFmpeg has an encoder (Debian 12's does, libx264).
  const auto m = run_fleetmap("explore --map empty --robots 2 --steps 4 --animate --out m", dir);
  ASSERT_EQ(m.exit_code, 0) << m.err;
  const bool h264 = m.err.find("cannot write H.264") == std::string::npos;
  EXPECT_EQ(stream_fourcc(dir / "m" / "run.mp4"), h264 ? "avc1" : "mp4v") << m.err;
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --map empty --steps 2 --video run.avi --out x", dir), ".mp4 (H.264) or .webm");
  EXPECT_FALSE(std::filesystem::exists(dir / "x"));
}

TEST(ExploreCommand, BadInputGetsOneLineAndNonZeroExit) {
  TempDir dir;
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --map ofice", dir), "unknown map 'ofice'");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --map ofice", dir), "maze");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --strategy greedy --steps 1", dir), "greedy");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --strategy greedy --steps 1", dir), "coordinated");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --localization gps --steps 1", dir), "gps");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --robots 0", dir), "--robots");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --comm-range far", dir), "--comm-range");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --comm-range -3", dir), "--comm-range");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --scenario missing.yaml", dir), "missing.yaml");
  dir.write("wall.yaml", "map: empty\nrobots: {starts: [[0.05, 5.0, 0]]}\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --scenario wall.yaml", dir), "inside a wall");
  dir.write("outside.yaml", "map: empty\nrobots: {starts: [[50, 5.0, 0]]}\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --scenario outside.yaml", dir), "outside the map");
  dir.write("onrobot.yaml", "map: empty\nrobots: {starts: [[5, 5, 0], [5.1, 5.0, 0]]}\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --scenario onrobot.yaml", dir), "on robot 1");
  dir.write("zero.yaml", "map: empty\nrobots: {count: 0}\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --scenario zero.yaml", dir), "zero.yaml:2");
  dir.write("noise.yaml", "map: empty\nnoise: {position: -1}\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --scenario noise.yaml", dir), "noise.position");
  dir.write("range.yaml", "map: empty\nsensors: {range: {max_range: -4}}\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --scenario range.yaml", dir), "sensors.range.max_range");
  dir.write("key.yaml", "map: empty\nrobot: 3\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --scenario key.yaml", dir), "key.yaml:2: unknown key 'robot'");
  dir.write("badmap.yaml", "map: nowhere.png\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --scenario badmap.yaml", dir), "nowhere.png");
  // Nothing half-written by a failed run.
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(ExploreCommand, HelpListsStrategiesAndLocalizers) {
  TempDir dir;
  const auto r = run_fleetmap("explore --help", dir);
  EXPECT_EQ(r.exit_code, 0);
  for (const char* s : {"uncoordinated", "coordinated", "optimized", "directional", "market", "Burgard", "wave algorithm",
                        "ideal", "odometry", "ekf", "--comm-range", "--animate", "--scenario"}) {
    EXPECT_NE(r.out.find(s), std::string::npos) << s;
  }
}

}  // namespace
}  // namespace fleetmap::cli

namespace fleetmap::cli {
namespace {

TEST(ExploreCommand, PlansOnTheMergedMapAfterTheRun) {
  TempDir dir;
  auto r = run_fleetmap("explore --map empty --robots 2 --out p --plan-from 2,2 --plan-to 17,17 --planner astar", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto path = nlohmann::json::parse(slurp(dir / "p" / "path.json"));
  EXPECT_TRUE(path["success"].get<bool>());
  EXPECT_EQ(path["planner"], "astar");
  // Straight across the empty square: about sqrt(2) * 15 m.
  EXPECT_NEAR(path["length_m"].get<double>(), 15.0 * std::sqrt(2.0), 0.5);
  EXPECT_NE(r.out.find("planned on the merged map"), std::string::npos);
  // Endpoints are checked before the run; a failed plan still leaves the run's outputs.
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --plan-from 2,x --plan-to 3,3", dir), "--plan-from '2,x'");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --plan-from 2,2", dir), "go together");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --plan-from 2,2 --plan-to 3,3 --planner magic", dir), "magic");
  r = run_fleetmap("explore --map empty --robots 2 --steps 3 --out q --plan-from 10,10 --plan-to 0.05,0.05", dir);
  EXPECT_ONE_LINE_ERROR(r, "--plan-to 0.05,0.05");
  EXPECT_TRUE(std::filesystem::exists(dir / "q" / "merged.png"));
  EXPECT_FALSE(nlohmann::json::parse(slurp(dir / "q" / "path.json"))["success"].get<bool>());
}

TEST(ExploreCommand, RobotsCanFollowPlannerPaths) {
  TempDir dir;
  const auto r = run_fleetmap("explore --map office --robots 3 --steps 80 --path-planner astar --out a", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto m = metrics(dir / "a");
  EXPECT_EQ(m["exploration"]["path_planner"], "astar");
  EXPECT_GT(m["exploration"]["planner_paths"].get<int>(), 0);
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --path-planner teleport --steps 1", dir), "teleport");
}

TEST(ExploreCommand, RobotsInTheirOwnFramesMergeAtRendezvous) {
  TempDir dir;
  dir.write("own.yaml",
            "map: office\nrobots: {random: 3, min_separation: 4}\n"
            "communication: {range: 0}\nexploration: {strategy: coordinated}\nsteps: 300\n");
  const auto r = run_fleetmap("explore --scenario own.yaml --merging rendezvous --out m", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("merging (rendezvous): "), std::string::npos) << r.out;
  const auto m = metrics(dir / "m");
  EXPECT_EQ(m["merging"], "rendezvous");
  ASSERT_TRUE(m.contains("merges"));
  EXPECT_GT(m["merges_made"].get<int>(), 0);
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --merging magic --steps 1", dir), "magic");
  const auto help = run_fleetmap("explore --help", dir);
  EXPECT_NE(help.out.find("--merging"), std::string::npos);
  EXPECT_NE(help.out.find("overlap"), std::string::npos);
}

// Debugging a merge: --merge-attempts keeps the two maps of every attempt, and `fleetmap merge` on
// them gives the attempt's own answer again.
TEST(ExploreCommand, MergeAttemptsKeepsTheMapsThatReproduceEachAttempt) {
  TempDir dir;
  const auto r = run_fleetmap("explore --map office --robots 2 --merging overlap --steps 60 --seed 3 --out run "
                              "--merge-attempts att --quiet", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string csv = slurp(dir / "att" / "attempts.csv");
  std::vector<std::string> rows;
  for (std::size_t p = 0, q; (q = csv.find('\n', p)) != std::string::npos; p = q + 1) rows.push_back(csv.substr(p, q - p));
  ASSERT_GE(rows.size(), 2u) << csv;
  EXPECT_EQ(rows[0].rfind("step,receiver,sender,method,merged,confidence,", 0), 0u) << rows[0];
  // The last attempt: its maps, named in the row, merged again as a user would.
  std::vector<std::string> cells;
  for (std::size_t p = 0, q = 0; cells.size() < 10; p = q + 1) {
    q = rows.back().find(',', p);
    cells.push_back(rows.back().substr(p, q - p));
  }
  ASSERT_TRUE(std::filesystem::exists(dir / "att" / cells[8])) << cells[8];
  ASSERT_TRUE(std::filesystem::exists(dir / "att" / cells[9])) << cells[9];
  const auto again = run_fleetmap("merge att/" + cells[8] + " att/" + cells[9] + " --seed 3 --out m.png --json m.json", dir);
  ASSERT_NE(again.exit_code, 2) << again.err;
  const auto j = nlohmann::json::parse(slurp(dir / "m.json"));
  const auto& t = j["transforms"][0];
  EXPECT_EQ(t["merged"].get<bool>(), cells[4] == "1");
  if (t.contains("confidence")) {
    EXPECT_NEAR(t["confidence"].get<double>(), std::stod(cells[5]), 1e-3);
  }
  // The folder is the run's own: not --out itself.
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --map office --steps 1 --out run --merge-attempts run", dir), "--merge-attempts");
}

}  // namespace
}  // namespace fleetmap::cli

namespace fleetmap::cli {
namespace {

TEST(ExploreCommand, AFolderNamedLikeABuiltInMapDoesNotHideIt) {
  TempDir dir;
  std::filesystem::create_directories(dir / "maze");  // e.g. the outputs of an earlier run, out/maze
  const auto r = run_fleetmap("explore --map maze --robots 1 --steps 2 --out o", dir);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(metrics(dir / "o")["map"], "maze");
}

}  // namespace
}  // namespace fleetmap::cli
