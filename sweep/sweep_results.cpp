#include "sweep/sweep_results.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <sstream>

#include "core/format.h"
#include "core/error.h"
#include "io/file_io.h"
#include "sweep/lower_bound.h"
#include "sim/run_metrics.h"

namespace fleetmap::sweep {

namespace fs = std::filesystem;

namespace {

using core::fixed;

std::string optional_int(const std::optional<int>& v) { return v ? std::to_string(*v) : ""; }

std::string levels_text(const std::vector<std::optional<int>>& levels) {
  std::string out;
  for (std::size_t k = 0; k < levels.size(); ++k) {
    if (k) out += ' ';
    out += levels[k] ? std::to_string(*levels[k]) : std::string("-");
  }
  return out;
}

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    out.push_back(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

std::string column_name(std::size_t i);

// Parses the fields of one row; every error names the line and the column.
struct FieldReader {
  const std::vector<std::string>& fields;
  const std::string& where;
  std::size_t next = 0;

  [[noreturn]] void fail(const std::string& expected) const {
    throw InputError(where + ": column '" + column_name(next - 1) + "': expected " + expected + ", got '" + fields[next - 1] + "'");
  }
  const std::string& text() { return fields[next++]; }
  long long integer(long long lo = std::numeric_limits<long long>::min()) {
    const std::string& t = text();
    try {
      std::size_t used = 0;
      const long long v = std::stoll(t, &used);
      if (used == t.size() && v >= lo) return v;
    } catch (const std::exception&) {
    }
    fail("a whole number");
  }
  std::uint64_t unsigned_integer() {
    const std::string& t = text();
    if (!t.empty() && std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      try {
        return std::stoull(t);
      } catch (const std::exception&) {
      }
    }
    fail("a whole number >= 0");
  }
  std::optional<int> optional_integer() {
    if (fields[next].empty()) return ++next, std::nullopt;
    return int(integer(0));
  }
  double number() {
    const std::string& t = text();
    if (t == "inf") return std::numeric_limits<double>::infinity();
    try {
      std::size_t used = 0;
      const double v = std::stod(t, &used);
      if (used == t.size() && std::isfinite(v)) return v;
    } catch (const std::exception&) {
    }
    fail("a number");
  }
  std::optional<double> optional_number() {
    if (fields[next].empty()) return ++next, std::nullopt;
    return number();
  }
  bool boolean() {
    const std::string& t = text();
    // Python's csv module writes its booleans capitalised.
    if (t == "true" || t == "True") return true;
    if (t == "false" || t == "False") return false;
    fail("true or false");
  }
  std::vector<std::optional<int>> levels() {
    const std::string& t = text();
    std::vector<std::optional<int>> out;
    std::istringstream in(t);
    std::string item;
    while (in >> item) {
      if (item == "-") {
        out.emplace_back();
        continue;
      }
      try {
        std::size_t used = 0;
        const int v = std::stoi(item, &used);
        if (used != item.size() || v < 0) fail(std::to_string(kCoverageLevels) + " steps or '-' separated by spaces");
        out.push_back(v);
      } catch (const InputError&) {
        throw;
      } catch (const std::exception&) {
        fail(std::to_string(kCoverageLevels) + " steps or '-' separated by spaces");
      }
    }
    if (out.size() != std::size_t(kCoverageLevels)) fail(std::to_string(kCoverageLevels) + " steps or '-' separated by spaces");
    return out;
  }
};

// Every column of results.csv, once: its name, how a record writes it, how a row reads it back.
struct Column {
  const char* name;
  std::string (*write)(const RunRecord&);
  void (*read)(FieldReader&, RunRecord&);
};

const std::vector<Column>& columns() {
  using R = const RunRecord&;
  using W = RunRecord&;
  using F = FieldReader&;
  static const std::vector<Column> kColumns = {
      {"map", [](R r) { return r.key.map; }, [](F f, W r) { r.key.map = f.text(); }},
      {"strategy", [](R r) { return r.key.strategy; }, [](F f, W r) { r.key.strategy = f.text(); }},
      {"robots", [](R r) { return std::to_string(r.key.robots); }, [](F f, W r) { r.key.robots = int(f.integer(1)); }},
      {"seed", [](R r) { return std::to_string(r.key.seed); }, [](F f, W r) { r.key.seed = f.unsigned_integer(); }},
      {"variant", [](R r) { return r.key.variant; }, [](F f, W r) { r.key.variant = f.text(); }},
      {"localization", [](R r) { return r.localization; }, [](F f, W r) { r.localization = f.text(); }},
      {"merging", [](R r) { return r.merging; }, [](F f, W r) { r.merging = f.text(); }},
      {"comm_range_m", [](R r) { return std::isinf(r.comm_range_m) ? std::string("inf") : fixed(r.comm_range_m, 3); },
       [](F f, W r) { r.comm_range_m = f.number(); }},
      {"sensor_range_m", [](R r) { return fixed(r.sensor_range_m, 3); }, [](F f, W r) { r.sensor_range_m = f.number(); }},
      {"step_limit", [](R r) { return std::to_string(r.step_limit); }, [](F f, W r) { r.step_limit = int(f.integer(1)); }},
      {"settings", [](R r) { return r.settings; }, [](F f, W r) { r.settings = f.text(); }},
      {"steps", [](R r) { return std::to_string(r.steps); }, [](F f, W r) { r.steps = int(f.integer(0)); }},
      {"finished", [](R r) { return std::string(r.finished ? "true" : "false"); }, [](F f, W r) { r.finished = f.boolean(); }},
      {"coverage", [](R r) { return fixed(r.coverage, 6); }, [](F f, W r) { r.coverage = f.number(); }},
      {"steps_to_95", [](R r) { return optional_int(r.steps_to_95); }, [](F f, W r) { r.steps_to_95 = f.optional_integer(); }},
      {"steps_to_99", [](R r) { return optional_int(r.steps_to_99); }, [](F f, W r) { r.steps_to_99 = f.optional_integer(); }},
      {"distance_m", [](R r) { return fixed(r.distance_m, 3); }, [](F f, W r) { r.distance_m = f.number(); }},
      {"redundancy", [](R r) { return fixed(r.redundancy, 6); }, [](F f, W r) { r.redundancy = f.number(); }},
      {"bytes_sent", [](R r) { return std::to_string(r.bytes_sent); }, [](F f, W r) { r.bytes_sent = f.integer(0); }},
      {"meetings", [](R r) { return std::to_string(r.meetings); }, [](F f, W r) { r.meetings = int(f.integer(0)); }},
      {"merges_made", [](R r) { return std::to_string(r.merges_made); }, [](F f, W r) { r.merges_made = int(f.integer(0)); }},
      {"blocked_moves", [](R r) { return std::to_string(r.blocked_moves); },
       [](F f, W r) { r.blocked_moves = int(f.integer(0)); }},
      {"position_rmse_m", [](R r) { return fixed(r.position_rmse_m, 6); }, [](F f, W r) { r.position_rmse_m = f.number(); }},
      {"wrong_cell_share", [](R r) { return fixed(r.wrong_cell_share, 6); }, [](F f, W r) { r.wrong_cell_share = f.number(); }},
      {"mean_wall_distance_m", [](R r) { return fixed(r.mean_wall_distance_m, 6); },
       [](F f, W r) { r.mean_wall_distance_m = f.number(); }},
      {"lower_bound_steps", [](R r) { return std::to_string(r.lower_bound_steps); },
       [](F f, W r) { r.lower_bound_steps = int(f.integer(0)); }},
      {"lower_bound_travel_steps", [](R r) { return std::to_string(r.lower_bound_travel_steps); },
       [](F f, W r) { r.lower_bound_travel_steps = int(f.integer(0)); }},
      {"lower_bound_area_steps", [](R r) { return std::to_string(r.lower_bound_area_steps); },
       [](F f, W r) { r.lower_bound_area_steps = int(f.integer(0)); }},
      {"efficiency", [](R r) { return r.efficiency ? fixed(*r.efficiency, 6) : std::string(); },
       [](F f, W r) { r.efficiency = f.optional_number(); }},
      {"wall_time_s", [](R r) { return fixed(r.wall_time_s, 3); }, [](F f, W r) { r.wall_time_s = f.number(); }},
      {"steps_to_percent", [](R r) { return levels_text(r.steps_to_percent); },
       [](F f, W r) { r.steps_to_percent = f.levels(); }},
  };
  return kColumns;
}

std::string column_name(std::size_t i) { return columns()[i].name; }

// The row's text; without the wall time (the only column two runs of one key may differ in) when asked.
std::string row_text(const RunRecord& r, bool wall_time) {
  std::string line;
  for (const auto& c : columns()) {
    if (!wall_time && std::string_view(c.name) == "wall_time_s") continue;
    if (!line.empty()) line += ',';
    line += c.write(r);
  }
  return line;
}

// Lines may end in CR LF (CSV's own line end, which Python's csv module writes).
std::string without_cr(std::string line) {
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return line;
}

std::string first_line(const std::string& text) { return without_cr(text.substr(0, text.find('\n'))); }

std::string errno_text() { return std::strerror(errno); }

// Where a header differs from results_header(): "column 3 is 'seeds', expected 'seed'".
std::string header_difference(const std::string& header) {
  const auto got = split_fields(header);
  for (std::size_t i = 0; i < columns().size(); ++i) {
    if (i >= got.size()) return fmt::format("it ends after {} columns, expected {}", got.size(), columns().size());
    if (got[i] != columns()[i].name) {
      return fmt::format("column {} is '{}', expected '{}'", i + 1, io::printable(got[i]), columns()[i].name);
    }
  }
  return fmt::format("it has {} columns, expected {}", got.size(), columns().size());
}

}  // namespace

std::string run_key_text(const RunKey& key) {
  return fmt::format("{}, {}, {} robot{}, seed {}{}", key.map, key.strategy, key.robots, key.robots == 1 ? "" : "s", key.seed,
                     key.variant.empty() ? "" : " (" + key.variant + ")");
}

std::string series_label(const RunKey& key) {
  return key.variant.empty() ? key.strategy : key.strategy + " " + key.variant;
}

RunKey run_key(const SweepRun& run) { return {run.map, run.strategy, run.robots, run.seed, run.variant}; }

RunRecord make_record(const sim::RunResult& result, const sim::World& world, const std::string& map_label,
                      const std::string& settings, double wall_time_s, const std::string& variant) {
  const sim::Scenario& s = result.scenario;
  const sim::RunTotals totals = sim::run_totals(result);
  RunRecord r;
  r.key = {map_label, s.exploration.strategy, s.robot_count, s.seed, variant};
  r.localization = s.localization;
  r.merging = s.merging;
  r.comm_range_m = s.communication.range_m;
  r.sensor_range_m = s.range.max_range_m;
  r.step_limit = s.steps;
  r.settings = settings;
  r.steps = result.steps;
  r.finished = result.finished;
  r.coverage = result.coverage.empty() ? 0.0 : result.coverage.back();
  r.steps_to_95 = result.steps_to_95;
  r.steps_to_99 = result.steps_to_99;
  r.distance_m = totals.distance_m;
  r.redundancy = result.redundancy;
  r.bytes_sent = result.bytes_sent;
  r.meetings = result.meetings;
  r.merges_made = totals.merges_made;
  r.blocked_moves = totals.blocked_moves;
  r.position_rmse_m = totals.position_rmse_m;
  r.wrong_cell_share = result.map_quality.wrong_cell_share;
  r.mean_wall_distance_m = result.map_quality.mean_wall_distance_m;

  std::vector<Eigen::Vector2d> starts;
  for (const auto& t : result.robots) starts.push_back(t.truth.front().position());
  LowerBoundOptions lb_options;
  lb_options.coverage = 0.99;
  lb_options.sensor_range_m = s.range.max_range_m;
  lb_options.step_length_m = s.robot.max_speed_mps * s.period_s;
  lb_options.robot_radius_m = s.robot.radius_m;
  const ExplorationLowerBound lb = exploration_lower_bound(world, starts, lb_options);
  r.lower_bound_steps = lb.steps();
  r.lower_bound_travel_steps = lb.travel_steps;
  r.lower_bound_area_steps = lb.area_steps;
  r.efficiency = exploration_efficiency(lb.steps(), r.steps_to_99);

  // The same rule as steps_to_95 / steps_to_99: the first step whose coverage reaches the level.
  r.steps_to_percent.assign(std::size_t(kCoverageLevels), std::nullopt);
  const auto& curve = result.coverage;
  std::size_t level = 0;
  for (std::size_t step = 0; step < curve.size() && level < r.steps_to_percent.size(); ++step) {
    const double c = curve[step];
    while (level < r.steps_to_percent.size() && c >= double(level + 1) / 100.0) r.steps_to_percent[level++] = int(step);
  }
  r.wall_time_s = wall_time_s;
  return r;
}

double coverage_at(const RunRecord& r, int step) {
  if (step >= r.steps) return r.coverage;
  int level = 0;
  while (level < int(r.steps_to_percent.size()) && r.steps_to_percent[std::size_t(level)] &&
         *r.steps_to_percent[std::size_t(level)] <= step) {
    ++level;
  }
  return level / 100.0;
}

std::string results_header() {
  std::string h;
  for (const auto& c : columns()) {
    if (!h.empty()) h += ',';
    h += c.name;
  }
  return h;
}

std::string format_record(const RunRecord& r) { return row_text(r, true); }

std::string record_without_wall_time(const RunRecord& r) { return row_text(r, false); }

RunRecord parse_record(const std::string& line, const std::string& where) {
  const auto fields = split_fields(line);
  if (fields.size() != columns().size()) {
    throw InputError(where + ": expected " + std::to_string(columns().size()) + " columns, found " + std::to_string(fields.size()));
  }
  FieldReader in{fields, where};
  RunRecord r;
  for (const auto& c : columns()) c.read(in, r);
  if (r.key.map.empty() || r.key.strategy.empty()) throw InputError(where + ": empty map or strategy");
  return r;
}

ResultsTable read_results(const fs::path& path) {
  const std::string text = io::read_file(path);
  ResultsTable table;
  const std::string name = path.string();
  if (const std::string header = first_line(text); header != results_header()) {
    throw InputError(name + ":1: not a results table of this fleetmap bench (" + header_difference(header) +
                     ": written by another version or another program); use another output folder");
  }
  std::map<RunKey, std::pair<std::size_t, int>> seen;  // key -> (record index, line)
  std::size_t pos = text.find('\n');
  int line_no = 1;
  while (pos != std::string::npos && pos + 1 < text.size()) {
    const std::size_t begin = pos + 1;
    pos = text.find('\n', begin);
    ++line_no;
    if (pos == std::string::npos) {
      table.partial_last_line = true;  // a row cut short: not a row
      break;
    }
    const std::string line = without_cr(text.substr(begin, pos - begin));
    if (line.empty()) continue;
    const std::string where = name + ":" + std::to_string(line_no);
    RunRecord r = parse_record(line, where);
    if (const auto it = seen.find(r.key); it != seen.end()) {
      if (record_without_wall_time(table.records[it->second.first]) != record_without_wall_time(r)) {
        throw InputError(where + ": the run of line " + std::to_string(it->second.second) + " again, with other results");
      }
      continue;
    }
    seen.emplace(r.key, std::make_pair(table.records.size(), line_no));
    table.records.push_back(std::move(r));
  }
  return table;
}

void check_settings(const std::vector<RunRecord>& records, const std::string& settings, const fs::path& path) {
  for (std::size_t i = 0; i < records.size(); ++i) {
    const auto& r = records[i];
    if (r.settings == settings) continue;
    throw InputError(path.string() + ": the run " + run_key_text(r.key) + " is from a sweep with other settings (settings " +
                     r.settings + ", this sweep " + settings + "; its localization " + r.localization + ", step limit " +
                     std::to_string(r.step_limit) + "): use another output folder, or the same settings");
  }
}

ResultsAppender::ResultsAppender(const fs::path& path) : path_(path) {
  if (!path.parent_path().empty()) io::ensure_directory(path.parent_path());
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw Error(path.string() + ": cannot open for appending: " + errno_text());
  try {
    prepare();
  } catch (...) {
    ::close(fd_);
    fd_ = -1;
    throw;
  }
}

void ResultsAppender::prepare() {
  const fs::path& path = path_;
  struct stat st {};
  if (::fstat(fd_, &st) != 0) throw Error(path.string() + ": cannot read its size: " + errno_text());
  std::string text;
  if (st.st_size > 0) {
    text = io::read_file(path);
    if (first_line(text) != results_header()) {
      throw InputError(path.string() + ":1: not a results table of this fleetmap bench; use another output folder");
    }
    // A row cut short (the machine stopped inside a write) is dropped, so appends start on a new line.
    const auto last_newline = text.rfind('\n');
    if (last_newline + 1 != text.size() && ::ftruncate(fd_, off_t(last_newline + 1)) != 0) {
      throw Error(path.string() + ": cannot cut off a partial row: " + errno_text());
    }
  }
  if (::lseek(fd_, 0, SEEK_END) < 0) throw Error(path.string() + ": cannot seek: " + errno_text());
  if (st.st_size == 0) {
    const std::string header = results_header() + "\n";
    if (::write(fd_, header.data(), header.size()) != ssize_t(header.size()) || ::fsync(fd_) != 0) {
      throw Error(path.string() + ": cannot write the header: " + errno_text());
    }
  }
}

ResultsAppender::~ResultsAppender() {
  if (fd_ >= 0) ::close(fd_);
}

void ResultsAppender::append(const RunRecord& record) {
  const std::string line = format_record(record) + "\n";
  // One write of the whole line: a reader (or a rerun after a kill) sees the row whole or not at all.
  const ssize_t n = ::write(fd_, line.data(), line.size());
  if (n != ssize_t(line.size())) {
    const std::string why = n < 0 ? errno_text() : "short write";
    if (n > 0) (void)::ftruncate(fd_, ::lseek(fd_, 0, SEEK_END) - n);  // take the partial row back
    throw Error(path_.string() + ": cannot append a row: " + why);
  }
  if (::fsync(fd_) != 0) throw Error(path_.string() + ": cannot flush a row to disk: " + errno_text());
}

void sort_records(std::vector<RunRecord>& records, const std::vector<SweepRun>& runs) {
  std::map<RunKey, std::size_t> order;
  for (const auto& r : runs) order.emplace(run_key(r), r.index);
  const auto rank = [&](const RunRecord& r) {
    const auto it = order.find(r.key);
    return it == order.end() ? std::numeric_limits<std::size_t>::max() : it->second;
  };
  std::stable_sort(records.begin(), records.end(), [&](const RunRecord& a, const RunRecord& b) {
    const auto ra = rank(a), rb = rank(b);
    return ra != rb ? ra < rb : a.key < b.key;
  });
}

void write_results(const fs::path& path, const std::vector<RunRecord>& records) {
  std::string text = results_header() + "\n";
  for (const auto& r : records) text += format_record(r) + "\n";
  io::write_file_atomic(path, text);
}

}  // namespace fleetmap::sweep
