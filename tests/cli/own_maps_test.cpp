// End-to-end: a user's own map files, made the ways users make them (a laser map with an unmapped
// courtyard, a transparent background, grey walls, a bare image beside a map_server map), and the
// first commands a user types, mistakes included. Every case ends in a right result or in words
// that say what happened.
#include <gtest/gtest.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io/map_io.h"
#include "tests/cli_run.h"

namespace fleetmap::cli {
namespace {

using fleetmap::testing::run_fleetmap;
using fleetmap::testing::slurp;
using fleetmap::testing::TempDir;

constexpr std::uint8_t kLabFree = 254, kLabWall = 0, kLabUnknown = 205;

// A 40 x 40 m lab at 0.1 m per cell: a ring of corridors and rooms around an unmapped courtyard
// (unknown), with a fan of laser streaks through a window into the courtyard ending in a small
// free pocket at the map's centre (1.4 x 2 m, closed but for the streaks), and a room with no door.
cv::Mat courtyard_lab() {
  cv::Mat img(400, 400, CV_8UC1, cv::Scalar(kLabUnknown));
  img(cv::Rect(40, 40, 320, 320)).setTo(kLabFree);
  img(cv::Rect(100, 100, 200, 200)).setTo(kLabUnknown);
  cv::rectangle(img, {40, 40}, {359, 359}, kLabWall, 2);
  cv::rectangle(img, {100, 100}, {299, 299}, kLabWall, 2);
  for (int x : {160, 240}) {
    img(cv::Rect(x, 40, 2, 60)).setTo(kLabWall);   // the room between them has no door
    img(cv::Rect(x, 300, 2, 60)).setTo(kLabWall);
    img(cv::Rect(x, 320, 2, 10)).setTo(kLabFree);  // a door
  }
  img(cv::Rect(100, 198, 2, 4)).setTo(kLabFree);  // the window
  for (int k = -6; k <= 6; ++k) cv::line(img, {102, 200}, {190, 200 + 8 * k}, kLabFree, 1);
  img(cv::Rect(190, 193, 20, 14)).setTo(kLabFree);
  cv::rectangle(img, {189, 192}, {210, 207}, kLabWall, 1);
  img(cv::Rect(189, 198, 1, 4)).setTo(kLabFree);
  return img;
}

nlohmann::json own_metrics(const std::filesystem::path& dir) { return nlohmann::json::parse(slurp(dir / "metrics.json")); }

TEST(OwnMaps, RobotsStartInTheLargestRegionNotInAPocketAtTheCentre) {
  TempDir dir;
  cv::imwrite((dir / "lab.png").string(), courtyard_lab());
  const auto r = run_fleetmap("explore --map lab.png --resolution 0.1 --robots 3 --steps 60 --out run", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("in the largest region a robot can reach (the default; --cluster-at x,y or --start x,y"),
            std::string::npos)
      << r.out;
  const auto m = own_metrics(dir / "run");
  const auto& space = m["space"];
  // The ring holds about 500 m2 of free space; the pocket and the streaks about 4.
  EXPECT_GT(space["observable_m2"].get<double>(), 400.0) << space;
  EXPECT_EQ(space["pose_cells"], space["largest_region_pose_cells"]);
  EXPECT_EQ(space["start_regions"], 1);
  EXPECT_FALSE(space.contains("warning"));
}

TEST(OwnMaps, AStartInAPocketIsSaidOnStderrAndInTheMetrics) {
  TempDir dir;
  cv::imwrite((dir / "lab.png").string(), courtyard_lab());
  const auto r = run_fleetmap("explore --map lab.png --resolution 0.1 --robots 2 --cluster-at 20,20 --out run", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("fleetmap: warning: lab: the robots start outside the largest region a robot can reach"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("of the map's"), std::string::npos) << r.err;
  const auto space = own_metrics(dir / "run")["space"];
  EXPECT_LT(space["observable_share_of_free"].get<double>(), 0.05) << space;
  ASSERT_TRUE(space.contains("warning"));
  EXPECT_NE(space["warning"].get<std::string>().find("largest region"), std::string::npos);
}

TEST(OwnMaps, StartFlagsPlaceEachRobotAndSayWhenTheyCannotMeet) {
  TempDir dir;
  cv::imwrite((dir / "lab.png").string(), courtyard_lab());
  // One robot in the room with no door, one in the ring.
  const auto r = run_fleetmap("explore --map lab.png --resolution 0.1 --start 20,33,90 --start 5,20 --steps 5 --out run", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("the robots start in 2 regions they cannot drive between"), std::string::npos) << r.err;
  const auto m = own_metrics(dir / "run");
  EXPECT_EQ(m["robots"], 2);
  EXPECT_EQ(m["space"]["start_regions"], 2);
  const std::string scenario = slurp(dir / "run" / "scenario.yaml");
  EXPECT_NE(scenario.find("- [20, 33, 90]"), std::string::npos) << scenario;
  EXPECT_EQ(r.out.find("the default"), std::string::npos);  // the user chose the starts

  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --map lab.png --start 2,x --out bad", dir), "--start '2,x': expected x,y");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --map lab.png --start 20,33 --robots 3 --out bad", dir),
                        "--robots 3 and 1 --start poses disagree");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --map lab.png --cluster-at 20 --out bad", dir), "--cluster-at '20'");
  EXPECT_FALSE(std::filesystem::exists(dir / "bad"));
}

TEST(OwnMaps, ATransparentBackgroundIsUnknownNotWall) {
  TempDir dir;
  const cv::Mat grey = courtyard_lab();
  cv::imwrite((dir / "lab.png").string(), grey);
  // As image editors save it: the unknown area transparent, its colour black.
  cv::Mat rgba(grey.size(), CV_8UC4);
  for (int y = 0; y < grey.rows; ++y)
    for (int x = 0; x < grey.cols; ++x) {
      const std::uint8_t v = grey.at<std::uint8_t>(y, x);
      rgba.at<cv::Vec4b>(y, x) = v == kLabUnknown ? cv::Vec4b(0, 0, 0, 0) : cv::Vec4b(v, v, v, 255);
    }
  cv::imwrite((dir / "lab_rgba.png").string(), rgba);
  const auto opaque = io::load_map(dir / "lab.png"), transparent = io::load_map(dir / "lab_rgba.png");
  EXPECT_EQ(transparent.count(mapping::CellState::Occupied), opaque.count(mapping::CellState::Occupied));
  EXPECT_EQ(transparent.count(mapping::CellState::Unknown), opaque.count(mapping::CellState::Unknown));
  const auto show = run_fleetmap("maps show lab_rgba.png --resolution 0.1 --out show.png", dir);
  ASSERT_EQ(show.exit_code, 0) << show.err;
  const int unknown = cv::countNonZero(grey == kLabUnknown);
  EXPECT_NE(show.err.find(fmt::format("lab_rgba.png: {} pixels ({:.1f}%) are transparent, read as unknown", unknown,
                                      100.0 * unknown / double(grey.total()))),
            std::string::npos)
      << show.err;
  // The two files are one map: they merge in place.
  const auto merge = run_fleetmap("merge lab.png lab_rgba.png --resolution 0.1 --json m.json --out m.png", dir);
  ASSERT_EQ(merge.exit_code, 0) << merge.err << merge.out;
  const auto t = nlohmann::json::parse(slurp(dir / "m.json"))["transforms"][0];
  EXPECT_NEAR(t["tx_m"].get<double>(), 0.0, 0.005);
  EXPECT_NEAR(t["theta_deg"].get<double>(), 0.0, 0.05);
}

TEST(OwnMaps, GreyWallsBetweenTheThresholdsGetAHintWithTheThresholdToUse) {
  TempDir dir;
  cv::Mat img = courtyard_lab();
  const int walls = cv::countNonZero(img == kLabWall);
  img.setTo(110, img == kLabWall);
  cv::imwrite((dir / "grey.png").string(), img);
  cv::imwrite((dir / "lab.png").string(), courtyard_lab());
  const auto r = run_fleetmap("merge grey.png lab.png --resolution 0.1 --out m.png", dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("the first map has no walls"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find(fmt::format("grey.png: {} pixels ({:.1f}%) are grey from 110 to 110, between the thresholds, and "
                                   "read as unknown (darker than 90 is a wall, lighter than 205 free",
                                   walls, 100.0 * walls / double(img.total()))),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("to read grey 110 as walls, give a map_server YAML with occupied_thresh below 0.569"),
            std::string::npos)
      << r.err;
  // The advice works.
  dir.write("grey.yaml", "image: grey.png\nresolution: 0.1\norigin: [0, 0, 0]\noccupied_thresh: 0.56\nfree_thresh: 0.196\nnegate: 0\n");
  EXPECT_EQ(io::load_map(dir / "grey.yaml").count(mapping::CellState::Occupied),
            io::load_map(dir / "lab.png").count(mapping::CellState::Occupied));
}

TEST(OwnMaps, AColouredLineIsSaidToBeReadByItsMean) {
  TempDir dir;
  cv::Mat img;
  cv::cvtColor(courtyard_lab(), img, cv::COLOR_GRAY2BGR);
  cv::line(img, {50, 380}, {350, 380}, cv::Scalar(0, 0, 255), 2);  // a red line in the unknown margin
  cv::imwrite((dir / "annotated.png").string(), img);
  std::vector<cv::Mat> channels;
  cv::split(img, channels);
  const int red = cv::countNonZero((channels[2] == 255) & (channels[0] == 0));
  const auto r = run_fleetmap("maps show annotated.png --resolution 0.1 --out show.png", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("are coloured, each read by the mean of its red, green and blue"), std::string::npos) << r.err;
  // Red (0, 0, 255) has the mean 85: darker than 90, a wall.
  EXPECT_NE(r.err.find(fmt::format(": {} as walls, 0 as free, 0 as unknown", red)), std::string::npos) << r.err;
}

TEST(OwnMaps, AMergeRefusedForAWallInOpenSpaceSaysWhereTheWallIs) {
  TempDir dir;
  cv::imwrite((dir / "lab.png").string(), courtyard_lab());
  cv::Mat drawn;
  cv::cvtColor(courtyard_lab(), drawn, cv::COLOR_GRAY2BGR);
  // A line drawn in red across the bottom corridor (read as a wall: its mean is 85).
  cv::line(drawn, {250, 305}, {250, 355}, cv::Scalar(0, 0, 255), 3);
  cv::imwrite((dir / "drawn.png").string(), drawn);
  const auto r = run_fleetmap("merge lab.png drawn.png --resolution 0.1 --json m.json --out m.png", dir);
  EXPECT_EQ(r.exit_code, 1) << r.err << r.out;
  EXPECT_NE(r.out.find("a wall of one map stands in the other's open space"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("; the wall stands around pixel (25"), std::string::npos) << r.out;
  const auto t = nlohmann::json::parse(slurp(dir / "m.json"))["transforms"][0];
  ASSERT_TRUE(t.contains("wall_in_open_space_px")) << t;
  EXPECT_NEAR(t["wall_in_open_space_px"][0].get<double>(), 250.0, 3.0);
  EXPECT_NEAR(t["wall_in_open_space_px"][1].get<double>(), 330.0, 15.0);
}

TEST(OwnMaps, ABareImageSaysWhichResolutionItTookAndMergesWithAMapServerMapAtItsResolution) {
  TempDir dir;
  cv::imwrite((dir / "a.png").string(), courtyard_lab());
  cv::imwrite((dir / "b.png").string(), courtyard_lab());
  dir.write("b.yaml", "image: b.png\nresolution: 0.1\norigin: [0, 0, 0]\noccupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n");
  const auto explore = run_fleetmap("explore --map a.png --robots 1 --steps 2 --out run", dir);
  ASSERT_EQ(explore.exit_code, 0) << explore.err;
  EXPECT_NE(explore.err.find("fleetmap: note: a.png: a bare image (no map_server YAML), read at 0.05 m per cell, the "
                             "default; --resolution sets it; walls darker than 90, free lighter than 205 (map_server's "
                             "default thresholds)"),
            std::string::npos)
      << explore.err;
  // Given the resolution, the thresholds are still said: they were taken silently.
  const auto given = run_fleetmap("maps show a.png --resolution 0.1 --out s.png", dir);
  EXPECT_NE(given.err.find("a.png: a bare image (no map_server YAML): walls darker than 90, free lighter than 205"),
            std::string::npos)
      << given.err;
  // In a merge, the bare image takes the resolution of the map_server map: the same map, in place.
  const auto merge = run_fleetmap("merge b.yaml a.png --json m.json --out m.png", dir);
  ASSERT_EQ(merge.exit_code, 0) << merge.err << merge.out;
  EXPECT_NE(merge.err.find("a.png: a bare image (no map_server YAML), read at 0.1 m per cell, that of b.yaml"),
            std::string::npos)
      << merge.err;
  const auto t = nlohmann::json::parse(slurp(dir / "m.json"))["transforms"][0];
  EXPECT_EQ(t["scale"].get<double>(), 1.0);
  // Told another resolution, the refusal says the cells differ.
  const auto told = run_fleetmap("merge b.yaml a.png --resolution 0.05 --out m2.png", dir);
  EXPECT_EQ(told.err.find("read at"), std::string::npos) << told.err;  // the user chose it: no note
  const auto bench = run_fleetmap("bench --maps a.png --resolution 0.1 --robots 1 --seeds 1 --strategies coordinated "
                                  "--steps 5 --out b1",
                                  dir);
  ASSERT_EQ(bench.exit_code, 0) << bench.err;
  EXPECT_EQ(bench.err.find("read at"), std::string::npos) << bench.err;
  EXPECT_NE(slurp(dir / "b1" / "scenario.yaml").find("map_resolution: 0.1"), std::string::npos);
}

TEST(OwnMaps, Nav2MapSaverThresholdsKeepItsUnknownGreyUnknown) {
  TempDir dir;
  cv::imwrite((dir / "map.pgm").string(), courtyard_lab());
  // As nav2's map_saver writes it: trinary, free_thresh 0.25, a negative origin.
  dir.write("map.yaml", "image: map.pgm\nmode: trinary\nresolution: 0.1\norigin: [-5.0, -5.0, 0]\nnegate: 0\n"
                        "occupied_thresh: 0.65\nfree_thresh: 0.25\n");
  const auto grid = io::load_map(dir / "map.yaml");
  EXPECT_EQ(grid.count(mapping::CellState::Unknown), cv::countNonZero(courtyard_lab() == kLabUnknown));
  const auto r = run_fleetmap("maps show map.yaml --out show.png", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("are map_saver's unknown grey 205, read as unknown as map_saver meant, although the thresholds "
                       "(occupied_thresh 0.65, free_thresh 0.25) would read them as free"),
            std::string::npos)
      << r.err;
  // Planning cannot cut through the unmapped courtyard.
  const auto plan = run_fleetmap("plan --map map.yaml --from 0,15 --to 10,15 --planner astar --out p.png", dir);
  EXPECT_NE(plan.exit_code, 0) << plan.out;
  EXPECT_NE(plan.err.find("unknown space"), std::string::npos) << plan.err;
}

TEST(OwnMaps, MapsDrawnDarkOn16BitsOrTurnedAreSaid) {
  TempDir dir;
  cv::Mat dark;
  cv::bitwise_not(courtyard_lab(), dark);
  dark.setTo(0, courtyard_lab() == kLabUnknown);  // no unknown: free space black, walls white
  cv::imwrite((dir / "dark.png").string(), dark);
  const auto show = run_fleetmap("maps show dark.png --resolution 0.1 --out s.png", dir);
  EXPECT_NE(show.err.find("if free space is drawn dark, give a map_server YAML with negate: 1"), std::string::npos)
      << show.err;
  const auto explore = run_fleetmap("explore --map dark.png --resolution 0.1 --out run", dir);
  EXPECT_ONE_LINE_ERROR(explore, "negate: 1");
  cv::Mat sixteen;
  courtyard_lab().convertTo(sixteen, CV_16U);  // 8-bit greys stored in 16 bits
  cv::imwrite((dir / "sixteen.png").string(), sixteen);
  EXPECT_NE(run_fleetmap("maps show sixteen.png --resolution 0.1 --out s16.png", dir)
                .err.find("a 16-bit image whose samples all lie below 256"),
            std::string::npos);
  cv::imwrite((dir / "lab.pgm").string(), courtyard_lab());
  dir.write("turned.yaml", "image: lab.pgm\nresolution: 0.1\norigin: [0, 0, 0.5]\n");
  EXPECT_NE(run_fleetmap("maps show turned.yaml --out t.png", dir).err.find("origin yaw 0.5 rad: coordinates"),
            std::string::npos);
}

TEST(OwnMaps, TheReadmeChainRunsWithRobotsThatDoNotMerge) {
  TempDir dir;
  // Each robot explores the whole map alone (about 1850 steps, 3 s).
  const auto run = run_fleetmap("explore --map office --robots 2 --merging none --out run", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("merging (none): every robot mapped alone"), std::string::npos) << run.out;
  EXPECT_EQ(own_metrics(dir / "run")["merges"].size(), 0u);
  const auto merge = run_fleetmap("merge run/robot_1.yaml run/robot_2.yaml --out merged.yaml --picture merged.png", dir);
  ASSERT_EQ(merge.exit_code, 0) << merge.err << merge.out;
  const auto plan = run_fleetmap("plan --map merged.yaml --from 1,1 --to 6,4 --out path.png", dir);
  EXPECT_EQ(plan.exit_code, 0) << plan.err << plan.out;
}

TEST(OwnMaps, LandmarkMergingWithoutLandmarkEstimatesIsRefusedBeforeAnythingIsWritten) {
  TempDir dir;
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --map office --robots 2 --merging landmarks --out run", dir),
                        "merging 'landmarks' aligns the robots' estimated landmark maps, and localization 'ideal' "
                        "estimates no landmarks: choose one that does (ekf-slam, fastslam2");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("bench --maps office --robots 2 --seeds 1 --merging landmarks --out b", dir),
                        "estimates no landmarks");
  EXPECT_FALSE(std::filesystem::exists(dir / "run"));
  EXPECT_FALSE(std::filesystem::exists(dir / "b"));
  const auto ok = run_fleetmap(
      "explore --map office --robots 2 --merging landmarks --localization ekf-slam --landmarks 0.5 --steps 5 --out ok", dir);
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
}

TEST(OwnMaps, MistypedFlagsValuesAndCommandsGetTheNearestName) {
  TempDir dir;
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --robot 4", dir), "unknown flag '--robot' (did you mean '--robots'?)");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --merging nnoe", dir), "unknown value 'nnoe' (did you mean 'none'?)");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --map offce", dir), "unknown map 'offce' (did you mean 'office'?)");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explroe --map office", dir), "unknown command 'explroe' (did you mean 'explore'?)");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("merge a.png b.png --methd overlap", dir), "unknown flag '--methd' (did you mean '--method'?)");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("plan --map office --planner rrtstr", dir), "(did you mean 'rrtstar'?)");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("bench --merging overlp", dir), "(did you mean 'overlap'?)");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --map office 4", dir), "unexpected argument '4'");
  // A flag whose value repeats an earlier one is still named, and so is a flag before any command.
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --robots 4 --sensor_range 4", dir),
                        "unknown flag '--sensor_range' (did you mean '--sensor-range'?)");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("--verison", dir), "unknown flag '--verison' (did you mean '--version'?)");
  // A mistyped flag is named, not its value taken for a file.
  EXPECT_ONE_LINE_ERROR(run_fleetmap("replay-compare a.html b.html --lable x y", dir),
                        "unknown flag '--lable' (did you mean '--label'?)");
  // Scenario files: keys and values.
  dir.write("s.yaml", "map: office\nrobots: {cuont: 2}\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --scenario s.yaml", dir),
                        "unknown key 'robots.cuont' (did you mean 'count'?) (valid in 'robots': count, random, starts");
  dir.write("t.yaml", "map: office\nexploration: {strategy: tuor}\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --scenario t.yaml", dir), "unknown value 'tuor' (did you mean 'tour'?)");
  // Errors found after reading still name the file.
  dir.write("u.yaml", "map: office\nlocalization: {method: ekf_slam}\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --scenario u.yaml", dir),
                        "u.yaml:2: key 'localization.method': unknown value 'ekf_slam' (did you mean 'ekf-slam'?)");
  dir.write("v.yaml", "map: ofice\n");
  EXPECT_ONE_LINE_ERROR(run_fleetmap("explore --scenario v.yaml", dir), "v.yaml: map: unknown map 'ofice' (did you mean 'office'?)");
}

}  // namespace
}  // namespace fleetmap::cli
