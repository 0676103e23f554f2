#include "io/laser_log.h"

#include <fmt/format.h>
#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <sstream>

#include "core/error.h"
#include "io/file_io.h"

namespace fleetmap::io {

// A source of lines: a gzip or plain file through zlib (which reads plain files as they are), or a
// string.
struct LaserLogReader::Lines {
  virtual ~Lines() = default;
  // The next line without its end; false at the end.
  virtual bool next(std::string& line) = 0;
  std::size_t number = 0;
};

namespace {

class FileLines final : public LaserLogReader::Lines {
 public:
  FileLines(const std::filesystem::path& path, const std::string& source) : source_(source) {
    file_ = gzopen(path.c_str(), "rb");
    if (file_ == nullptr) throw InputError(source + ": cannot open the log");
    gzbuffer(file_, 1 << 17);
  }
  ~FileLines() override {
    if (file_ != nullptr) gzclose(file_);
  }
  bool next(std::string& line) override {
    line.clear();
    char buffer[8192];
    while (true) {
      if (gzgets(file_, buffer, int(sizeof(buffer))) == nullptr) {
        int code = 0;
        const char* message = gzerror(file_, &code);
        if (code != Z_OK && code != Z_STREAM_END) {
          throw InputError(fmt::format("{}:{}: the file is damaged or cut short ({})", source_, number + 1, message));
        }
        if (line.empty()) return false;
        break;
      }
      line += buffer;
      if (!line.empty() && line.back() == '\n') {
        line.pop_back();
        break;
      }
      if (line.size() > (std::size_t(64) << 20)) throw InputError(fmt::format("{}:{}: a line over 64 MB", source_, number + 1));
    }
    if (!line.empty() && line.back() == '\r') line.pop_back();
    ++number;
    return true;
  }

 private:
  std::string source_;
  gzFile file_ = nullptr;
};

class TextLines final : public LaserLogReader::Lines {
 public:
  explicit TextLines(const std::string& text) : in_(text) {}
  bool next(std::string& line) override {
    if (!std::getline(in_, line)) return false;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    ++number;
    return true;
  }

 private:
  std::istringstream in_;
};

std::vector<std::string_view> words_of(const std::string& line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) out.emplace_back(line.data() + start, i - start);
  }
  return out;
}

// The words of one line and where it is, for numbers and messages about it.
class Line {
 public:
  Line(const std::string& source, std::size_t number, const std::string& text)
      : source_(source), number_(number), words_(words_of(text)) {}
  std::size_t size() const { return words_.size(); }
  std::string_view word(std::size_t i) const { return words_[i]; }
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(fmt::format("{}:{}: {}", source_, number_, what));
  }
  // At least `n` words, else the line was cut short.
  void need(std::size_t n, std::string_view message) const {
    if (words_.size() < n) {
      fail(fmt::format("{} line cut short: {} fields, {} expected", message, words_.size(), n));
    }
  }
  double number(std::size_t i, std::string_view what) const {
    if (i >= words_.size()) fail(fmt::format("{} missing (the line is cut short)", what));
    double v = 0.0;
    const std::string_view w = words_[i];
    const auto [end, error] = std::from_chars(w.data(), w.data() + w.size(), v);
    if (error != std::errc() || end != w.data() + w.size()) {
      // from_chars rejects a leading '+'; nan and inf are read to be refused by name.
      if (w == "nan" || w == "NaN" || w == "-nan") v = std::nan("");
      else if (w == "inf" || w == "-inf") v = w[0] == '-' ? -INFINITY : INFINITY;
      else fail(fmt::format("{}: expected a number, got '{}'", what, std::string(w.substr(0, 40))));
    }
    return v;
  }
  double finite(std::size_t i, std::string_view what) const {
    const double v = number(i, what);
    if (!std::isfinite(v)) fail(fmt::format("{}: expected a finite number, got '{}'", what, std::string(words_[i])));
    return v;
  }
  std::size_t count(std::size_t i, std::string_view what, std::size_t most) const {
    const double v = finite(i, what);
    if (v < 0.0 || v != std::floor(v) || v > double(most)) {
      fail(fmt::format("{}: expected a whole number from 0 to {}, got '{}'", what, most, std::string(words_[i])));
    }
    return std::size_t(v);
  }
  // A range reading: a NaN or negative one is refused (an infinite one is no return).
  double range(std::size_t i, std::size_t beam) const {
    const double v = number(i, fmt::format("range {}", beam + 1));
    if (std::isnan(v) || v < 0.0) fail(fmt::format("range {} is {}: a range is a distance, 0 or more", beam + 1, std::string(words_[i])));
    return v;
  }
  core::Pose2 pose(std::size_t i, std::string_view what) const {
    return {finite(i, what), finite(i + 1, what), finite(i + 2, what)};
  }

 private:
  const std::string& source_;
  std::size_t number_;
  std::vector<std::string_view> words_;
};

constexpr std::size_t kMostBeams = 100000;

// The beam angles of a FLASER or DP-SLAM Laser line: n beams over the 180 degrees in front, the
// first at -90 degrees. Lasers with an odd count (181, 361) include both ends; with an even count
// (180, 360), the last beam falls one step short of +90 degrees.
std::vector<double> front_angles(std::size_t n) {
  std::vector<double> a(n);
  if (n == 0) return a;
  const double step = n % 2 == 1 ? (n > 1 ? std::numbers::pi / double(n - 1) : 0.0) : std::numbers::pi / double(n);
  for (std::size_t i = 0; i < n; ++i) a[i] = -0.5 * std::numbers::pi + step * double(i);
  return a;
}

// Half a unit of the last digit of a number as written ("12.345": 0.0005; "12": 0.5).
double half_last_digit(const std::string& text) {
  const auto dot = text.find('.');
  const auto exponent = text.find_first_of("eE");
  const std::size_t digits = dot == std::string::npos ? 0 : (exponent == std::string::npos ? text.size() : exponent) - dot - 1;
  return 0.5 * std::pow(10.0, -double(digits));
}

bool declares_max_range(std::string_view name) {
  return name == "robot_front_laser_max" || name == "laser_front_laser_max_range";
}

}  // namespace

LaserLogReader::LaserLogReader(const std::filesystem::path& path, const LaserLogOptions& options)
    : source_(path.string()), options_(options) {
  std::error_code ec;
  if (!std::filesystem::exists(std::filesystem::symlink_status(path, ec))) throw InputError(source_ + ": no such file");
  if (std::filesystem::is_directory(path, ec)) throw InputError(source_ + ": a folder, not a log file");
  const std::string source = source_;
  make_lines_ = [path, source] { return std::unique_ptr<Lines>(new FileLines(path, source)); };
  open();
}

LaserLogReader::LaserLogReader(std::string text, std::string source, const LaserLogOptions& options)
    : source_(std::move(source)), options_(options) {
  auto shared = std::make_shared<const std::string>(std::move(text));
  make_lines_ = [shared] { return std::unique_ptr<Lines>(new TextLines(*shared)); };
  open();
}

LaserLogReader::~LaserLogReader() = default;

void LaserLogReader::open() {
  if (!(options_.max_range_m >= 0.0) || !std::isfinite(options_.max_range_m)) {
    throw InputError(fmt::format("{}: maximum range {}: expected a distance, 0 or more (0: as the log says)", source_,
                                 options_.max_range_m));
  }
  max_range_m_ = options_.max_range_m;
  if (max_range_m_ == 0.0) {
    // One pass before the scans: the maximum the log declares, else its largest reading.
    auto lines = make_lines_();
    double declared = 0.0, largest = 0.0;
    std::string text;
    while (lines->next(text)) {
      const Line line(source_, lines->number, text);
      if (line.size() == 0) continue;
      const std::string_view kind = line.word(0);
      try {
        if (kind == "PARAM" && line.size() >= 3 && declares_max_range(line.word(1))) {
          declared = std::max(declared, line.finite(2, "the maximum range"));
        } else if (kind == "ROBOTLASER1" || kind == "RAWLASER1") {
          declared = std::max(declared, line.finite(5, "maximum_range"));
        } else if (kind == "FLASER" || kind == "Laser") {
          const std::size_t n = line.count(1, "the number of readings", kMostBeams);
          for (std::size_t b = 0; b < n && 2 + b < line.size(); ++b) {
            const double r = line.number(2 + b, "a range");
            if (std::isfinite(r)) largest = std::max(largest, r);
          }
        }
      } catch (const InputError&) {
        // The scan pass names the problem where the scan is read.
      }
    }
    max_range_m_ = declared > 0.0 ? declared : largest;
  }
  lines_ = make_lines_();
}

std::optional<LogScan> LaserLogReader::read_counted() {
  std::optional<LogScan> scan = read_scan();
  if (scan) {
    ++scans_;
  } else if (scans_ == 0) {
    throw InputError(source_ + ": no laser scan in the log (expected FLASER, RAWLASER1 or ROBOTLASER1 lines, or "
                               "DP-SLAM's Laser lines)");
  }
  return scan;
}

std::optional<LogScan> LaserLogReader::next() {
  if (!ahead_.empty()) {
    LogScan out = std::move(ahead_.front());
    ahead_.pop_front();
    return out;
  }
  std::optional<LogScan> scan = read_counted();
  if (!scan) return scan;
  const std::optional<LogScan> before = std::move(previous_);
  previous_ = *scan;
  previous_->scan = {};  // only its odometry and time are needed
  if (!before || !(scan->odometry == before->odometry)) return scan;
  // The reading repeats the previous scan's to the last digit: read on to the next scan whose
  // reading differs, keeping the repeats (as many as there are; a robot at rest repeats its
  // reading for as long as it rests).
  ahead_.push_back(std::move(*scan));
  std::optional<LogScan> fresh;
  while ((fresh = read_counted())) {
    if (!(fresh->odometry == before->odometry)) break;
    ahead_.push_back(std::move(*fresh));
  }
  if (fresh) {
    // The repeats get the odometry interpolated in time between the last reading before them and
    // the first after (by their order when the times do not tell).
    const core::Pose2 step = before->odometry.inverse().compose(fresh->odometry);
    const double t0 = before->time_s, t1 = fresh->time_s;
    const std::size_t n = ahead_.size();
    for (std::size_t k = 0; k < n; ++k) {
      double f = double(k + 1) / double(n + 1);
      if (t1 > t0 && ahead_[k].time_s >= t0 && ahead_[k].time_s <= t1) f = (ahead_[k].time_s - t0) / (t1 - t0);
      ahead_[k].odometry = before->odometry.compose(core::Pose2(f * step.x, f * step.y, f * step.theta));
    }
    previous_ = *fresh;
    previous_->scan = {};
    ahead_.push_back(std::move(*fresh));
  }
  LogScan out = std::move(ahead_.front());
  ahead_.pop_front();
  return out;
}

std::optional<LogScan> LaserLogReader::read_scan() {
  std::string text;
  while (lines_->next(text)) {
    const Line line(source_, lines_->number, text);
    if (line.size() == 0 || line.word(0).front() == '#') continue;
    const std::string_view kind = line.word(0);
    if (kind == "ODOM") {
      line.need(4, "ODOM");
      const core::Pose2 odom = line.pose(1, "ODOM pose");
      if (!chain_) chain_ = odom;
      if (!segment_first_) segment_first_ = odom;
      segment_last_ = odom;
      continue;
    }
    if (kind == "Odometry") {
      line.need(4, "Odometry");
      pending_odometry_ = line.pose(1, "Odometry pose");
      continue;
    }
    const bool flaser = kind == "FLASER", dpslam = kind == "Laser", robot_laser = kind == "ROBOTLASER1",
               raw_laser = kind == "RAWLASER1";
    if (!flaser && !dpslam && !robot_laser && !raw_laser) continue;  // PARAM, SYNC, NEFF, TRUEPOS, ...

    LogScan out;
    out.line = lines_->number;
    out.scan.max_range = max_range_m_;
    std::optional<core::Pose2> field_odometry;
    std::size_t first_range = 0, n = 0;
    double max_range = max_range_m_;
    if (flaser || dpslam) {
      n = line.count(1, "the number of readings", kMostBeams);
      first_range = 2;
      out.scan.angles = front_angles(n);
      if (flaser) {
        line.need(2 + n + 7, "FLASER");
        out.logged_pose = line.pose(2 + n, "FLASER pose");
        field_odometry = line.pose(2 + n + 3, "FLASER odometry");
        out.timestamp = std::string(line.word(2 + n + 6));
      } else {
        line.need(2 + n, "Laser");
        if (!pending_odometry_) line.fail("a Laser line with no Odometry line before it");
        field_odometry = *pending_odometry_;
        pending_odometry_.reset();
        out.timestamp = std::to_string(scans_);  // DP-SLAM logs carry no time: the scan's index
      }
    } else {
      // RAWLASER1 / ROBOTLASER1 laser_type start_angle field_of_view angular_resolution maximum_range
      // accuracy remission_mode num_readings r1..rn num_remissions m1..mm [poses ...] timestamp ...
      line.need(9, std::string(kind));
      const double start = line.finite(2, "start_angle"), resolution = line.finite(4, "angular_resolution");
      if (options_.max_range_m == 0.0) max_range = line.finite(5, "maximum_range");
      n = line.count(8, "num_readings", kMostBeams);
      first_range = 9;
      line.need(9 + n + 1, std::string(kind));
      const std::size_t remissions = line.count(9 + n, "num_remissions", kMostBeams);
      std::size_t at = 9 + n + 1 + remissions;
      out.scan.angles.resize(n);
      for (std::size_t b = 0; b < n; ++b) out.scan.angles[b] = start + resolution * double(b);
      if (robot_laser) {
        line.need(at + 12 + 1, "ROBOTLASER1");
        out.logged_pose = line.pose(at, "laser pose");
        field_odometry = line.pose(at + 3, "robot pose");
        at += 11;
      } else {
        line.need(at + 1, "RAWLASER1");
      }
      out.timestamp = std::string(line.word(at));
    }
    out.scan.max_range = max_range;
    out.scan.ranges.resize(n);
    for (std::size_t b = 0; b < n; ++b) {
      const double r = line.range(first_range + b, b);
      // At the maximum range, or infinite (as ROS writes a beam that saw nothing): no return.
      const bool no_return = std::isinf(r) || (max_range > 0.0 && r >= max_range - 1e-6);
      out.scan.ranges[b] = no_return ? std::nullopt : std::optional<double>(r);
    }
    if (!dpslam) {
      double v = 0.0;
      const auto [end, error] = std::from_chars(out.timestamp.data(), out.timestamp.data() + out.timestamp.size(), v);
      if (error != std::errc() || end != out.timestamp.data() + out.timestamp.size() || !std::isfinite(v)) {
        line.fail("timestamp: expected a number, got '" + out.timestamp.substr(0, 40) + "'");
      }
      out.time_s = v;
    } else {
      out.time_s = double(scans_);
    }
    if (format_.empty()) format_ = dpslam ? "DP-SLAM" : "CARMEN";

    // Odometry: the motion the ODOM lines report since the last scan, else the scan's own field.
    if (segment_first_) {
      chain_ = chain_->compose(segment_first_->inverse().compose(*segment_last_));
      out.odometry = *chain_;
    } else if (chain_) {
      out.odometry = *chain_;  // no ODOM line since the last scan: the robot did not move
    } else if (field_odometry) {
      out.odometry = *field_odometry;
    } else if (last_odometry_) {
      out.odometry = *last_odometry_;  // the line carries none, and nothing reported a motion
    } else {
      line.fail("no odometry before this scan (no ODOM line, and the line carries none)");
    }
    last_odometry_ = out.odometry;
    segment_first_.reset();
    return out;
  }
  return std::nullopt;
}

std::vector<Relation> parse_relations(const std::string& text, const std::string& source) {
  std::vector<Relation> out;
  TextLines lines(text);
  std::string raw;
  while (lines.next(raw)) {
    const Line line(source, lines.number, raw);
    if (line.size() == 0 || line.word(0).front() == '#') continue;
    if (line.size() != 8) {
      line.fail(fmt::format("expected a relation 't1 t2 x y z roll pitch yaw' (8 numbers), got {} fields", line.size()));
    }
    Relation r;
    r.line = lines.number;
    r.t1_text = std::string(line.word(0));
    r.t2_text = std::string(line.word(1));
    r.t1 = line.finite(0, "t1");
    r.t2 = line.finite(1, "t2");
    // Plus a few units in the last place of the double, which rounding the text may have cost.
    r.t1_tolerance = half_last_digit(r.t1_text) + 4.0 * (std::nextafter(r.t1, INFINITY) - r.t1);
    r.t2_tolerance = half_last_digit(r.t2_text) + 4.0 * (std::nextafter(r.t2, INFINITY) - r.t2);
    r.motion = core::Pose2(line.finite(2, "x"), line.finite(3, "y"), line.finite(7, "yaw"));
    for (std::size_t i : {4u, 5u, 6u}) line.finite(i, i == 4 ? "z" : (i == 5 ? "roll" : "pitch"));
    out.push_back(std::move(r));
  }
  if (out.empty()) throw InputError(source + ": no relation in the file");
  return out;
}

std::vector<Relation> read_relations(const std::filesystem::path& path) {
  return parse_relations(read_file(path, std::int64_t(256) << 20), path.string());
}

}  // namespace fleetmap::io
