// End-to-end: `fleetmap plan` as a user runs it.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>

#include "io/map_io.h"
#include "tests/cli_run.h"

namespace fleetmap::cli {
namespace {

using fleetmap::testing::run_fleetmap;
using fleetmap::testing::slurp;
using fleetmap::testing::TempDir;

// A 4 x 2 m room (0.1 m cells) split by a wall with a door, and a closed cupboard on the right.
std::filesystem::path write_room(const TempDir& dir) {
  cv::Mat img(20, 40, CV_8UC1, cv::Scalar(254));
  img.row(0).setTo(0), img.row(19).setTo(0), img.col(0).setTo(0), img.col(39).setTo(0);
  img(cv::Rect(20, 0, 1, 20)).setTo(0);
  img(cv::Rect(20, 7, 1, 7)).setTo(254);  // the door, 0.7 m wide
  img(cv::Rect(30, 2, 8, 6)).setTo(0);    // the cupboard's walls ...
  img(cv::Rect(31, 3, 6, 4)).setTo(254);  // ... around free space nobody can enter
  const auto path = dir / "room.png";
  cv::imwrite(path.string(), img);
  return path;
}

TEST(PlanCommand, WritesThePathAsJsonAndPng) {
  TempDir dir;
  const auto room = write_room(dir).string();
  const auto r = run_fleetmap("plan --map " + room +
                                  " --resolution 0.1 --from 0.5,0.5 --to 3.5,0.5 --planner astar --out out/path.png "
                                  "--json out/path.json",
                              dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("astar"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("wrote out/path.png"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(slurp(dir / "out" / "path.json"));
  EXPECT_EQ(j["planner"], "astar");
  EXPECT_EQ(j["success"], true);
  EXPECT_GE(j["time_s"].get<double>(), 0.0);
  const auto& w = j["waypoints"];
  ASSERT_GE(w.size(), 3u);  // around the wall, through the door
  EXPECT_NEAR(w.front()[0].get<double>(), 0.5, 1e-12);
  EXPECT_NEAR(w.back()[0].get<double>(), 3.5, 1e-12);
  double length = 0;
  for (std::size_t i = 0; i + 1 < w.size(); ++i)
    length += std::hypot(w[i + 1][0].get<double>() - w[i][0].get<double>(), w[i + 1][1].get<double>() - w[i][1].get<double>());
  EXPECT_NEAR(j["length_m"].get<double>(), length, 1e-9);
  EXPECT_GT(length, 3.0);
  const cv::Mat img = cv::imread((dir / "out" / "path.png").string());
  ASSERT_FALSE(img.empty());
  EXPECT_GT(img.cols, 40 * 4);  // scaled up, with the legend panel
}

TEST(PlanCommand, PlansOnABuiltinMapWithCellsAndEveryPlanner) {
  TempDir dir;
  for (const char* planner : {"rrtconnect", "rrtstar", "prmstar", "informedrrtstar", "bitstar", "astar"}) {
    const auto r = run_fleetmap(std::string("plan --map office --from-cell 30,150 --to-cell 170,40 --time 1 --seed 3 --planner ") +
                                    planner + " --json p.json",
                                dir);
    ASSERT_EQ(r.exit_code, 0) << planner << ": " << r.err;
    const auto j = nlohmann::json::parse(slurp(dir / "p.json"));
    EXPECT_EQ(j["planner"], planner);
    EXPECT_NEAR(j["start"][0].get<double>(), 3.05, 1e-9);  // the centre of cell (30, 150)
    EXPECT_NEAR(j["start"][1].get<double>(), 15.05, 1e-9);
  }
}

// "unreachable" (not "no path within budget") means the answer came from the free space's regions,
// without spending the 30 s budget.
TEST(PlanCommand, UnreachableGoalFailsAtOnce) {
  TempDir dir;
  const auto room = write_room(dir).string();
  const auto r = run_fleetmap("plan --map " + room + " --resolution 0.1 --radius 0.1 --from 0.5,0.5 --to 3.35,1.45 "
                                  "--planner rrtstar --time 30 --json p.json",
                              dir);
  EXPECT_ONE_LINE_ERROR(r, "cannot be reached");
  EXPECT_EQ(r.exit_code, 1);
  const auto j = nlohmann::json::parse(slurp(dir / "p.json"));
  EXPECT_EQ(j["success"], false);
  EXPECT_EQ(j["status"], "unreachable");
  EXPECT_TRUE(j["waypoints"].empty());
  EXPECT_EQ(j["length_m"], nullptr);
}

TEST(PlanCommand, BadInputGetsOneLineAndExitCodeTwo) {
  TempDir dir;
  const auto room = write_room(dir).string();
  const std::string map = "plan --map " + room + " --resolution 0.1 ";
  auto expect_bad = [&](const std::string& args, const std::string& part) {
    const auto r = run_fleetmap(args, dir);
    EXPECT_ONE_LINE_ERROR(r, part);
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
  };
  // A goal inside an obstacle, too close to one, outside the map, in unknown space.
  expect_bad(map + "--from 0.5,0.5 --to 2.05,0.5", "--to 2.05,0.5: goal (2.05, 0.50) is inside an obstacle");
  expect_bad(map + "--from 0.5,0.5 --to 1.8,0.5 --radius 0.3", "robot radius 0.30 m");
  expect_bad(map + "--from 0.5,0.5 --to 9,0.5", "--to 9,0.5: goal (9.00, 0.50) is outside the map");
  expect_bad(map + "--from -1,0.5 --to 1,0.5", "--from -1,0.5: start (-1.00, 0.50) is outside the map");
  expect_bad(map + "--from-cell 5,5 --to-cell 45,5", "--to-cell 45,5: cell outside the map of 40x20 cells");
  expect_bad(map + "--from-cell 0,0 --to-cell 5,5", "--from-cell 0,0: start");
  // Malformed or missing values.
  expect_bad(map + "--from '0.5;0.5' --to 1,1", "--from '0.5;0.5': expected x,y in metres");
  expect_bad(map + "--from 0.5,0.5 --to 1,abc", "--to '1,abc'");
  expect_bad(map + "--from-cell 1.5,2 --to 1,1", "expected column,row as two integers");
  expect_bad(map + "--from 0.5,0.5", "missing goal: give --to x,y");
  expect_bad(map + "--from 0.5,0.5 --from-cell 1,1 --to 1,1", "excludes");
  expect_bad(map + "--from 0.5,0.5 --to 1,1 --planner rrtstr", "rrtstr");
  expect_bad(map + "--from 0.5,0.5 --to 1,1 --time 0", "--time");
  expect_bad(map + "--from 0.5,0.5 --to 1,1 --radius -1", "--radius");
  expect_bad(map + "--from 0.5,0.5 --to 1,1 --unknown maybe", "--unknown");
  expect_bad("plan --map nosuchmap --from 0.5,0.5 --to 1,1", "unknown map 'nosuchmap'");
  expect_bad("plan --from 0.5,0.5 --to 1,1", "--map");
  expect_bad(map + "--from 0.5,0.5 --to 1,1 --out " + room, "fleetmap never overwrites an input");
  // Unknown space blocks by default and is free by option.
  cv::Mat img(20, 20, CV_8UC1, cv::Scalar(205));
  img(cv::Rect(2, 2, 10, 10)).setTo(254);
  cv::imwrite((dir / "unknown.png").string(), img);
  const std::string unknown = "plan --map unknown.png --resolution 0.1 --from 0.6,1.4 --to 1.6,0.4 ";
  expect_bad(unknown, "--to 1.6,0.4: goal (1.60, 0.40) is in unknown space");
  EXPECT_EQ(run_fleetmap(unknown + "--unknown free --planner astar", dir).exit_code, 0);
}

TEST(PlanCommand, HelpListsEveryPlannerAndFlagWithDefaults) {
  TempDir dir;
  const auto r = run_fleetmap("plan --help", dir);
  EXPECT_EQ(r.exit_code, 0);
  for (const char* word : {"rrtstar", "informedrrtstar", "prmstar", "rrtconnect", "bitstar", "astar", "reactive",
                           "--map", "--from", "--to", "--from-cell", "--to-cell", "--planner", "--time", "--radius",
                           "--unknown", "--seed", "--out", "--json", "=obstacle", "=0.2", "=1", "map-alignment paper"}) {
    EXPECT_NE(r.out.find(word), std::string::npos) << word << " not in:\n" << r.out;
  }
}

}  // namespace
}  // namespace fleetmap::cli
