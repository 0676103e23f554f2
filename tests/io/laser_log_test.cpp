#include "io/laser_log.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <numbers>
#include <string>

#include "core/error.h"
#include "tests/test_support.h"

namespace fleetmap::io {
namespace {

using fleetmap::testing::expect_input_error;
using fleetmap::testing::TempDir;

// A FLASER line of `ranges` with the given pose fields and timestamp.
std::string flaser(const std::vector<std::string>& ranges, const std::string& pose, const std::string& odometry,
                   const std::string& time) {
  std::string line = "FLASER " + std::to_string(ranges.size());
  for (const auto& r : ranges) line += " " + r;
  return line + " " + pose + " " + odometry + " " + time + " host " + time + "\n";
}

std::vector<LogScan> all(LaserLogReader& reader) {
  std::vector<LogScan> out;
  while (auto s = reader.next()) out.push_back(*s);
  return out;
}

TEST(LaserLog, FlaserScansCarryTheirBeamsTimeAndBothPoses) {
  const std::string log = "# a comment\nPARAM robot_front_laser_max 80.0 nohost 0\n" +
                          flaser({"1.5", "2.25", "80.0"}, "1 2 0.5", "1.1 2.1 0.6", "1134864629.895182") +
                          "NEFF 15\n" + flaser({"1", "2", "3"}, "1 2 0.5", "1.1 2.1 0.6", "1134864630.000001");
  LaserLogReader reader(log, "test.log");
  const auto scans = all(reader);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(reader.format(), "CARMEN");
  const LogScan& s = scans[0];
  EXPECT_EQ(s.line, 3u);
  EXPECT_EQ(s.timestamp, "1134864629.895182");  // every digit kept
  EXPECT_DOUBLE_EQ(s.time_s, 1134864629.895182);
  // Three beams over the front half: -90, 0 and +90 degrees.
  ASSERT_EQ(s.scan.angles.size(), 3u);
  EXPECT_NEAR(s.scan.angles[0], -std::numbers::pi / 2, 1e-12);
  EXPECT_NEAR(s.scan.angles[2], std::numbers::pi / 2, 1e-12);
  EXPECT_EQ(s.scan.ranges[0], 1.5);
  EXPECT_EQ(s.scan.ranges[1], 2.25);
  EXPECT_FALSE(s.scan.ranges[2].has_value());  // at the declared maximum: no return
  EXPECT_EQ(s.scan.max_range, 80.0);
  ASSERT_TRUE(s.logged_pose.has_value());
  EXPECT_EQ(s.logged_pose->x, 1.0);
  EXPECT_EQ(s.odometry.x, 1.1);  // no ODOM lines: the FLASER line's odometry
  EXPECT_EQ(s.odometry.theta, 0.6);
}

TEST(LaserLog, WithoutADeclaredMaximumTheLargestReadingIsNoReturn) {
  const std::string log = flaser({"1", "8.191", "2"}, "0 0 0", "0 0 0", "1") + flaser({"8.191", "3", "4"}, "0 0 0", "0 0 0", "2");
  LaserLogReader reader(log, "test.log");
  const auto scans = all(reader);
  EXPECT_EQ(reader.max_range_m(), 8.191);
  EXPECT_FALSE(scans[0].scan.ranges[1].has_value());
  EXPECT_FALSE(scans[1].scan.ranges[0].has_value());
  EXPECT_EQ(scans[1].scan.ranges[2], 4.0);
  // Told the maximum, the reader takes it.
  LaserLogReader told(log, "test.log", LaserLogOptions{10.0});
  EXPECT_EQ(all(told)[0].scan.ranges[1], 8.191);
}

// A beam logged as inf (ROS's "saw nothing") is no return, also on a line that declares no
// maximum range (maximum_range 0), where no reading is at the maximum.
TEST(LaserLog, AnInfiniteRangeIsNoReturn) {
  const std::string log = "ROBOTLASER1 0 -1.0 2.0 0.5 0.0 0.01 0 3 1 inf 2 0 0 0 0 0 0 0 0 0 0 0 0 0 77.5 host 77.5\n";
  LaserLogReader reader(log, "test.log");
  const auto scans = all(reader);
  ASSERT_EQ(scans.size(), 1u);
  ASSERT_EQ(scans[0].scan.ranges.size(), 3u);
  EXPECT_EQ(scans[0].scan.ranges[0], 1.0);
  EXPECT_FALSE(scans[0].scan.ranges[1].has_value());
  EXPECT_EQ(scans[0].scan.ranges[2], 2.0);
}

TEST(LaserLog, EvenBeamCountsEndOneStepShortOfTheLeft) {
  std::vector<std::string> r(180, "1");
  LaserLogReader reader(flaser(r, "0 0 0", "0 0 0", "1"), "test.log");
  const auto s = *reader.next();
  EXPECT_NEAR(s.scan.angles[1] - s.scan.angles[0], std::numbers::pi / 180.0, 1e-12);
  EXPECT_NEAR(s.scan.angles.back(), std::numbers::pi / 2 - std::numbers::pi / 180.0, 1e-12);
}

// A corrected log: after each scan the odometry is re-based onto the corrected pose. The raw motion
// between scans is what the ODOM lines report from the re-base line on, never the jump onto it.
TEST(LaserLog, ACorrectedLogsOdometryIsTheRawMotionNotTheCorrection) {
  std::string log = "ODOM 0 0 0 0 0 0 1 h 1\nODOM 1 0 0 0 0 0 2 h 2\n";
  log += flaser({"1", "1", "1"}, "0.9 0.05 0.01", "1 0 0", "2");  // GMapping's answer: 0.9, 0.05
  log += "ODOM 0.9 0.05 0.01 0 0 0 0 h 0\n";                        // re-based onto it
  // Then 1 m forward along the re-based heading, in two ODOM lines.
  for (const double d : {0.5, 1.0}) {
    log += "ODOM " + std::to_string(0.9 + d * std::cos(0.01)) + " " + std::to_string(0.05 + d * std::sin(0.01)) +
           " 0.01 0 0 0 3 h 3\n";
  }
  log += flaser({"1", "1", "1"}, "2 0.1 0.02", "1.9 0.05 0.01", "4");
  LaserLogReader reader(log, "corrected.log");
  const auto scans = all(reader);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_NEAR(scans[0].odometry.x, 1.0, 1e-12);  // the raw odometry at the first scan
  // 1 m straight ahead, whatever the correction did to the pose.
  const core::Pose2 step = scans[0].odometry.inverse().compose(scans[1].odometry);
  EXPECT_NEAR(step.x, 1.0, 1e-6);
  EXPECT_NEAR(step.y, 0.0, 1e-6);
  EXPECT_NEAR(step.theta, 0.0, 1e-12);
  EXPECT_NEAR(scans[1].logged_pose->x, 2.0, 1e-12);  // the corrected pose is still there to compare with
}

TEST(LaserLog, AnOdometerThatRepeatsItsReadingIsInterpolatedToTheNextOne) {
  // Scans 1-3 repeat scan 0's reading while the robot turns; scan 4 has the reading again. The
  // repeats get the motion in proportion to their time; the rest is left as read.
  std::string log = flaser({"1", "2", "3"}, "0 0 0", "0 0 0", "10.0");
  for (const char* t : {"10.2", "10.4", "10.5"}) log += flaser({"1", "2", "3"}, "0 0 0", "0 0 0", t);
  log += flaser({"1", "2", "3"}, "0 0 0", "1 0 0.8", "11.0") + flaser({"1", "2", "3"}, "0 0 0", "1.2 0 0.8", "11.2");
  LaserLogReader reader(log, "test.log");
  const auto scans = all(reader);
  ASSERT_EQ(scans.size(), 6u);
  EXPECT_EQ(scans[0].odometry, core::Pose2(0, 0, 0));
  EXPECT_NEAR(scans[1].odometry.x, 0.2, 1e-12);
  EXPECT_NEAR(scans[1].odometry.theta, 0.16, 1e-12);
  EXPECT_NEAR(scans[2].odometry.theta, 0.32, 1e-12);
  EXPECT_NEAR(scans[3].odometry.x, 0.5, 1e-12);
  EXPECT_NEAR(scans[3].odometry.theta, 0.4, 1e-12);
  EXPECT_EQ(scans[4].odometry, core::Pose2(1, 0, 0.8));
  EXPECT_EQ(scans[5].odometry, core::Pose2(1.2, 0, 0.8));
  EXPECT_EQ(scans[3].timestamp, "10.5");
  EXPECT_EQ(scans[3].line, 4u);
}

TEST(LaserLog, DpSlamLogsPairOdometryAndLaserLines) {
  const std::string log = "Odometry -2.42 4.80 2.59\nLaser 3 0.64 0.65 8.191\nOdometry -2.40 4.81 2.60\nLaser 3 1 2 3\n";
  LaserLogReader reader(log, "loop5.log");
  const auto scans = all(reader);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(reader.format(), "DP-SLAM");
  EXPECT_EQ(scans[0].odometry.x, -2.42);
  EXPECT_EQ(scans[1].odometry.theta, 2.60);
  EXPECT_EQ(scans[0].timestamp, "0");
  EXPECT_EQ(scans[1].timestamp, "1");
  EXPECT_FALSE(scans[0].scan.ranges[2].has_value());  // the log's largest reading
  EXPECT_FALSE(scans[0].logged_pose.has_value());
}

TEST(LaserLog, RobotLaserLinesCarryTheirOwnAnglesAndMaximum) {
  // laser_type start fov resolution max accuracy remission_mode n r... m rem... laser_pose robot_pose
  // tv rv forward side turn_axis timestamp host logger
  const std::string log =
      "ROBOTLASER1 0 -1.0 2.0 0.5 5.0 0.01 0 5 1 2 3 4 5.0 0 1 2 0.1 1.5 2.5 0.2 0 0 0 0 0 77.5 host 77.5\n"
      "RAWLASER1 0 -0.5 1.0 0.5 5.0 0.01 0 3 1 2 3 0 78.5 host 78.5\n";
  LaserLogReader reader(log, "robot.log");
  const auto scans = all(reader);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_NEAR(scans[0].scan.angles[0], -1.0, 1e-12);
  EXPECT_NEAR(scans[0].scan.angles[4], 1.0, 1e-12);
  EXPECT_FALSE(scans[0].scan.ranges[4].has_value());  // its own maximum, 5 m
  EXPECT_EQ(scans[0].logged_pose->theta, 0.1);
  EXPECT_EQ(scans[0].odometry.x, 1.5);
  EXPECT_EQ(scans[0].timestamp, "77.5");
  EXPECT_EQ(scans[1].timestamp, "78.5");
  EXPECT_EQ(scans[1].odometry.x, 1.5);  // no odometry of its own: the robot has not moved
}

TEST(LaserLog, AGzipLogReadsAsThePlainOne) {
  TempDir dir;
  const std::string log = flaser({"1", "2", "3"}, "0 0 0", "0 0 0", "1.5") + flaser({"4", "5", "6"}, "0 0 0", "1 0 0", "2.5");
  dir.write("plain.log", log);
  gzFile gz = gzopen((dir / "packed.log.gz").c_str(), "wb");
  ASSERT_NE(gz, nullptr);
  gzwrite(gz, log.data(), unsigned(log.size()));
  gzclose(gz);
  LaserLogReader plain(dir / "plain.log"), packed(dir / "packed.log.gz");
  const auto a = all(plain), b = all(packed);
  ASSERT_EQ(a.size(), 2u);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(a[1].scan.ranges, b[1].scan.ranges);
  EXPECT_EQ(a[1].odometry.x, b[1].odometry.x);
  EXPECT_EQ(b[1].timestamp, "2.5");
}

TEST(LaserLogBadInput, EveryProblemNamesTheFileAndLine) {
  const auto read_all = [](const std::string& text) {
    LaserLogReader reader(text, "bad.log");
    while (reader.next()) {
    }
  };
  const std::string good = flaser({"1", "2", "3"}, "0 0 0", "0 0 0", "1");
  expect_input_error([&] { read_all(good + "FLASER 3 1 2\n"); }, {"bad.log:2:", "FLASER line cut short"});
  expect_input_error([&] { read_all(good + flaser({"1", "nan", "3"}, "0 0 0", "0 0 0", "2")); },
                     {"bad.log:2:", "range 2 is nan"});
  expect_input_error([&] { read_all(flaser({"1", "-0.5", "3"}, "0 0 0", "0 0 0", "2")); }, {"bad.log:1:", "range 2 is -0.5"});
  expect_input_error([&] { read_all(flaser({"1", "x", "3"}, "0 0 0", "0 0 0", "2")); }, {"bad.log:1:", "expected a number, got 'x'"});
  expect_input_error([&] { read_all("FLASER many 1 2\n"); }, {"bad.log:1:", "the number of readings"});
  expect_input_error([&] { read_all(flaser({"1"}, "0 0 0", "0 0 0", "soon")); }, {"bad.log:1:", "timestamp"});
  expect_input_error([&] { read_all("ODOM 1 2\n"); }, {"bad.log:1:", "ODOM line cut short"});
  expect_input_error([&] { read_all("Laser 2 1 2\n"); }, {"bad.log:1:", "no Odometry line before it"});
  expect_input_error([&] { read_all("# nothing but\nODOM 0 0 0 0 0 0 1 h 1\n"); }, {"bad.log", "no laser scan in the log"});
  expect_input_error([&] { read_all(""); }, {"bad.log", "no laser scan"});
  TempDir dir;
  expect_input_error([&] { LaserLogReader reader(dir / "missing.log"); }, {"missing.log", "no such file"});
  // A gzip file cut short is named, not read as a shorter log.
  std::string big;
  for (int i = 0; i < 2000; ++i) big += flaser({"1", "2", "3"}, "0 0 0", "0 0 0", std::to_string(i));
  gzFile gz = gzopen((dir / "cut.log.gz").c_str(), "wb");
  gzwrite(gz, big.data(), unsigned(big.size()));
  gzclose(gz);
  std::ifstream in(dir / "cut.log.gz", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  dir.write("cut.log.gz", bytes.substr(0, bytes.size() / 2));
  expect_input_error([&] {
    LaserLogReader reader(dir / "cut.log.gz");
    while (reader.next()) {
    }
  }, {"cut.log.gz:", "damaged or cut short"});
}

TEST(Relations, ReadWithTheToleranceTheirDigitsGive) {
  const auto r = parse_relations("# t1 t2 x y z roll pitch yaw\n1134864645.90321 1134864646.32420 0.31293 0.02935 0 0 0 0.24198\n",
                                 "rel.txt");
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].line, 2u);
  EXPECT_EQ(r[0].t1_text, "1134864645.90321");
  // Half the last digit, and four units in the last place of a double near 1.1e9 (2.4e-7 each).
  EXPECT_NEAR(r[0].t1_tolerance, 0.000005 + 4 * 2.384185791015625e-07, 1e-12);
  EXPECT_NEAR(r[0].motion.x, 0.31293, 1e-12);
  EXPECT_NEAR(r[0].motion.theta, 0.24198, 1e-12);
  expect_input_error([] { parse_relations("1 2 3\n", "rel.txt"); }, {"rel.txt:1:", "8 numbers"});
  expect_input_error([] { parse_relations("1 2 3 4 0 0 0 nan\n", "rel.txt"); }, {"rel.txt:1:", "yaw"});
  expect_input_error([] { parse_relations("# only a comment\n", "rel.txt"); }, {"rel.txt", "no relation"});
}

// The logs of ../shared/datasets/carmen/ read whole: their scan counts as their README gives them.
TEST(LaserLog, TheSharedRealLogsReadWhole) {
  const std::filesystem::path folder = std::filesystem::path(FLEETMAP_SOURCE_DIR) / ".." / "shared" / "datasets" / "carmen";
  if (!std::filesystem::is_directory(folder)) GTEST_SKIP() << "no " << folder;
  for (const auto& [file, scans] : std::vector<std::pair<std::string, std::size_t>>{
           {"mit-csail.clf.gz", 1988}, {"intel-corrected.log.gz", 910}, {"aces-corrected.log.gz", 440},
           {"freiburg-079-corrected.log.gz", 4791}, {"duke-loop5.log.gz", 551}}) {
    LaserLogReader reader(folder / file);
    std::size_t n = 0;
    while (reader.next()) ++n;
    EXPECT_EQ(n, scans) << file;
  }
}

}  // namespace
}  // namespace fleetmap::io
