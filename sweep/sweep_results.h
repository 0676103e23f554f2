#pragma once
// results.csv: one row per run of a sweep. A row is appended whole with one write and flushed to
// disk, so an interrupted sweep leaves only whole rows; a rerun reads them back and skips the runs
// they hold. Rows are keyed by map, strategy, team size and seed, and carry the sweep's settings id
// so rows of different sweeps are never mixed.
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "sim/simulation.h"
#include "sweep/sweep.h"

namespace fleetmap::sweep {

struct RunKey {
  std::string map, strategy;
  int robots = 0;
  std::uint64_t seed = 0;
  std::string variant;  // the sweep's further axes: "beams=90 comm_range=5" (sweep::variant_label)
  auto operator<=>(const RunKey&) const = default;
};

// The key of a run of a sweep.
RunKey run_key(const SweepRun& run);
// "office, coordinated, 2 robots, seed 3 (beams=90)": a run in messages.
std::string run_key_text(const RunKey& key);
// How reports name the runs of one strategy and variant: "coordinated", "coordinated beams=90".
std::string series_label(const RunKey& key);

// The number of coverage levels kept per run: the first step at each whole percent 1..100.
inline constexpr int kCoverageLevels = 100;

struct RunRecord {
  RunKey key;
  // Settings shared by the sweep's runs (also in `settings`, with everything else).
  std::string localization;
  std::string merging;        // how robots bring teammates' maps into their frame
  double comm_range_m = 0.0;  // +inf: unlimited
  double sensor_range_m = 0.0;
  int step_limit = 0;
  std::string settings;
  // The run (as in metrics.json).
  int steps = 0;
  bool finished = false;
  double coverage = 0.0;
  std::optional<int> steps_to_95, steps_to_99;
  double distance_m = 0.0;
  double redundancy = 0.0;
  std::int64_t bytes_sent = 0;
  int meetings = 0;
  int merges_made = 0;        // maps brought into a teammate's frame (rendezvous or overlap merging)
  int blocked_moves = 0;
  double position_rmse_m = 0.0;
  double wrong_cell_share = 0.0;      // the merged map against the truth (metrics.json map_quality)
  double mean_wall_distance_m = 0.0;
  // sweep/lower_bound.h.
  int lower_bound_steps = 0, lower_bound_travel_steps = 0, lower_bound_area_steps = 0;
  std::optional<double> efficiency;  // lower_bound_steps / steps_to_99
  // steps_to_percent[k - 1]: the first step with coverage >= k %, nullopt if never (the coverage curve).
  std::vector<std::optional<int>> steps_to_percent;
  double wall_time_s = 0.0;  // the only field that differs between two runs of the same key
};

// The record of a finished run; the lower bound is computed from the run's truth and starts.
RunRecord make_record(const sim::RunResult& result, const sim::World& world, const std::string& map_label,
                      const std::string& settings, double wall_time_s, const std::string& variant = "");
// Coverage of a record after `step` (step function of steps_to_percent; the final coverage after the run).
double coverage_at(const RunRecord& record, int step);

std::string results_header();
// One line without the newline. Numbers have fixed decimals, so equal runs give equal text.
std::string format_record(const RunRecord& record);
// `where` ("results.csv:12") names the line in errors.
RunRecord parse_record(const std::string& line, const std::string& where);
// The record's text without its wall time: equal for two runs of the same key and settings.
std::string record_without_wall_time(const RunRecord& record);

struct ResultsTable {
  std::vector<RunRecord> records;
  bool partial_last_line = false;  // the file ended inside a row (a write cut short); it was ignored
};

// Reads results.csv. Throws InputError naming the file and line for a foreign header or a bad row,
// and for a run listed twice with different results.
ResultsTable read_results(const std::filesystem::path& path);

// Checks that every record was run with `settings`; throws InputError naming the file, the line and
// what differs.
void check_settings(const std::vector<RunRecord>& records, const std::string& settings,
                    const std::filesystem::path& path);

// Appends rows to results.csv: each append is one write() of a whole line followed by fsync().
class ResultsAppender {
 public:
  // Opens (creates with the header) `path`. An existing file must start with the header; a partial
  // last line is cut off first. Throws fleetmap::Error naming the path on failure.
  explicit ResultsAppender(const std::filesystem::path& path);
  ~ResultsAppender();
  ResultsAppender(const ResultsAppender&) = delete;
  ResultsAppender& operator=(const ResultsAppender&) = delete;
  void append(const RunRecord& record);

 private:
  void prepare();  // checks the header, cuts a partial row, writes the header of a new file

  std::filesystem::path path_;
  int fd_ = -1;
};

// Sorts records into the order of `runs` (by key); records of keys not in `runs` go last, by key.
void sort_records(std::vector<RunRecord>& records, const std::vector<SweepRun>& runs);
// Writes results.csv atomically (a temporary file renamed over it).
void write_results(const std::filesystem::path& path, const std::vector<RunRecord>& records);

}  // namespace fleetmap::sweep
