#pragma once
// Real robots' laser logs, read scan by scan: CARMEN logs (FLASER, RAWLASER1 / ROBOTLASER1, ODOM,
// PARAM; plain or gzip-compressed) and DP-SLAM's logs (`Odometry x y theta`, `Laser n r1 ... rn`),
// and the ground-truth relations of Kümmerle et al. 2009 ("On measuring the accuracy of SLAM
// algorithms").
#include <cstddef>
#include <deque>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/transform2.h"
#include "mapping/range_scan.h"

namespace fleetmap::io {

// One laser scan of a log and the robot's raw odometry when it was taken.
struct LogScan {
  std::string timestamp;  // as the log writes it, every digit kept
  double time_s = 0.0;    // the same, as a number (seconds)
  std::size_t line = 0;   // the scan's line in the log, from 1
  // The scan in the laser's frame: beam angles, ranges in metres (nullopt: no return, a reading at
  // or beyond the sensor's maximum) and the maximum range.
  mapping::RangeScan scan;
  // Raw odometry at the scan. A log with ODOM lines gives it by the motion its ODOM lines report
  // between scans: from the first ODOM line after a scan to the last one before the next (a
  // corrected log re-bases its odometry onto the corrected pose right after each scan, and the
  // jump onto it is the correction, not odometry). A log without gives the FLASER line's odometry
  // fields (DP-SLAM: its Odometry lines).
  core::Pose2 odometry;
  // The pose the log itself gives the laser (FLASER's x y theta): a corrected log's answer (e.g.
  // GMapping's); empty for logs without one.
  std::optional<core::Pose2> logged_pose;
};

struct LaserLogOptions {
  // Readings at or beyond this are "no return". 0: the sensor's maximum as the log declares it
  // (PARAM robot_front_laser_max or laser_front_laser_max_range, a RAWLASER1 / ROBOTLASER1 line's
  // own maximum), else the largest reading in the log (read once before the scans): lasers report
  // "nothing within range" as their maximum reading (81.91 m, 50 m, 8.191 m in the logs fleetmap
  // was checked on), far beyond any real return.
  double max_range_m = 0.0;
};

// Reads a log's scans one by one, in order, without loading the file. Every problem is an
// InputError naming the file, the line and the problem: an unreadable or empty file, a line cut
// short or holding a word where a number belongs, a NaN or negative range, a log with no scan.
class LaserLogReader {
 public:
  // A log file, plain or gzip-compressed (by its content, not its name).
  explicit LaserLogReader(const std::filesystem::path& path, const LaserLogOptions& options = {});
  // A log held in memory; `source` names it in messages.
  LaserLogReader(std::string text, std::string source, const LaserLogOptions& options = {});
  ~LaserLogReader();
  LaserLogReader(const LaserLogReader&) = delete;
  LaserLogReader& operator=(const LaserLogReader&) = delete;

  // The next scan, or nullopt at the end of the log (InputError when the log had no scan at all).
  //
  // A scan whose odometry repeats the previous scan's exactly gets the odometry interpolated in time
  // between the last reading before it and the first that differs after it (the reader reads ahead
  // to it). An odometer that reports no new reading for some scans while the robot moves (MIT
  // CSAIL's, three times for four scans while turning up to 85 degrees) is otherwise read as a
  // robot that stood still and then jumped; a robot that did stand still gets its next step's
  // small motion spread over its rest, which no method can tell from standing.
  std::optional<LogScan> next();
  // "CARMEN" or "DP-SLAM" (known after the first scan).
  const std::string& format() const { return format_; }
  // The maximum range the reader took as "no return" (after the first scan).
  double max_range_m() const { return max_range_m_; }

 // Where the lines come from (a file or a string); defined in laser_log.cpp.
  struct Lines;

 private:
  void open();
  std::optional<LogScan> read_scan();
  std::optional<LogScan> read_counted();  // read_scan, counted; InputError for a log with no scan

  std::string source_;
  std::function<std::unique_ptr<Lines>()> make_lines_;
  std::unique_ptr<Lines> lines_;
  LaserLogOptions options_;
  std::string format_;
  double max_range_m_ = 0.0;
  std::size_t scans_ = 0;
  // Odometry from ODOM lines: the pose chain at the last scan, the first ODOM line since it, and
  // the last.
  std::optional<core::Pose2> chain_, segment_first_, segment_last_;
  std::optional<core::Pose2> pending_odometry_;     // DP-SLAM: the Odometry line before a Laser line
  std::optional<core::Pose2> last_odometry_;        // the previous scan's
  // next(): the last scan read (its odometry as read, and its time), and the scans read ahead.
  std::optional<LogScan> previous_;
  std::deque<LogScan> ahead_;
};

// One relation of Kümmerle et al. 2009: the true motion from the scan taken at `t1` to the one taken
// at `t2`, in the first scan's frame.
struct Relation {
  std::string t1_text, t2_text;  // as written
  double t1 = 0.0, t2 = 0.0;
  // Half a unit of the last digit written: a scan whose timestamp is this close is the one meant
  // (relations files print times with fewer digits than the logs).
  double t1_tolerance = 0.0, t2_tolerance = 0.0;
  core::Pose2 motion;            // x, y (m) and yaw (rad)
  std::size_t line = 0;
};

// Reads a relations file: one relation per line, `t1 t2 x y z roll pitch yaw`; blank lines and `#`
// comments skipped. InputError naming the file and line for anything else.
std::vector<Relation> read_relations(const std::filesystem::path& path);
std::vector<Relation> parse_relations(const std::string& text, const std::string& source);

}  // namespace fleetmap::io
