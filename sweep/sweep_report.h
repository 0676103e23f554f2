#pragma once
// What a sweep's results.csv becomes: per map x strategy x team size the mean, standard deviation
// and 95% confidence interval of each metric (summary.csv, summary.md with the best per column
// marked), plots, and the paired comparison of two strategies. Everything is computed from the
// records alone, so a combined set of shards gives the same reports as one run of the sweep.
#include <opencv2/core/mat.hpp>

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "sweep/statistics.h"
#include "sweep/sweep_results.h"
#include "viz/drawing.h"

namespace fleetmap::sweep {

struct ReportMetric {
  std::string name;   // column in results.csv
  std::string title;  // in tables
  bool higher_is_better = false;
  int decimals = 1;   // in summary.md
  // nullopt leaves the run out of this metric (e.g. steps_to_99 of a run that never reached 99%).
  std::function<std::optional<double>(const RunRecord&)> value;
};

// steps_to_95, steps_to_99, distance_m, redundancy, bytes_sent, efficiency, coverage.
const std::vector<ReportMetric>& report_metrics();
// Throws InputError naming `what` and listing the metric names.
const ReportMetric& find_report_metric(const std::string& name, const std::string& what);

struct GroupSummary {
  std::string map, strategy;
  std::string variant;  // the sweep's further axes, "" without
  int robots = 0;
  std::string series() const { return variant.empty() ? strategy : strategy + " " + variant; }
  int runs = 0;
  std::vector<SampleSummary> metrics;  // in the order of report_metrics()
  int lower_bound_min = 0, lower_bound_max = 0;  // lower_bound_steps over the group's runs
};

// Groups (map x strategy x variant x team size) in the order their first record appears (records in sweep order give the sweep's order).
std::vector<GroupSummary> summarize_groups(const std::vector<RunRecord>& records);

std::string summary_csv(const std::vector<GroupSummary>& groups);
std::string summary_markdown(const std::vector<RunRecord>& records, const std::vector<GroupSummary>& groups);

struct PairedRow {
  std::string map;  // "all" for every map
  int robots = 0;   // 0 for every team size
  PairedComparison comparison;
};

struct StrategyComparison {
  std::string axis;  // what differs between the paired runs: "strategy", "robots", "map" or an axis of the sweep
  std::string a, b, metric;  // a and b: values of that axis
  bool higher_is_better = false;
  std::vector<PairedRow> rows;  // per map x team size, then per map, then overall
  int unpaired = 0;             // runs of a or b without a partner holding the metric
};

// Pairs runs that differ only in one setting and takes the differences a - b. `a` and `b` are two
// strategies ("coordinated"), or two values of one setting written SETTING=VALUE: "robots=4",
// "map=office", or an axis of the sweep ("beams=90", "comm_range=inf"). Runs pair when everything
// else (map, strategy, team size, the other axes, seed) is equal. Throws InputError when a value has
// no runs (naming the values present), the two name different settings, or a == b.
StrategyComparison compare_strategies(const std::vector<RunRecord>& records, const std::string& a, const std::string& b,
                                      const std::string& metric);
// A readable table of the comparison.
std::string comparison_text(const StrategyComparison& comparison);

struct SweepPlot {
  std::string file;  // e.g. "coverage_office.png"; the SVG beside it has the same stem
  viz::Drawing drawing;
  cv::Mat image;     // the drawing rasterized
};

// coverage_<map>.png (coverage against step, a panel per team size, a curve per strategy: the mean
// over seeds with its translucent 95% confidence band), time_<map>.png (steps to 99% against team
// size, with the lower bound, also for a single team size) and efficiency.png (mean efficiency
// per strategy on each map and on all).
std::vector<SweepPlot> sweep_plots(const std::vector<RunRecord>& records);

// report.html: the summary's tables, the plots (SVG, with tooltips on the curves and bars) and
// every run, linked to its replay where `replay_of` names one (a file beside the report; empty: none).
std::string report_html(const std::vector<RunRecord>& records, const std::vector<GroupSummary>& groups,
                        const std::vector<SweepPlot>& plots, const std::function<std::string(const RunKey&)>& replay_of);

// The name of a run's replay page in a bench folder: "replay_office_coordinated_4r_s3.html" (the
// variant's settings appended).
std::string replay_file_name(const RunKey& key);

// Writes summary.csv, summary.md, report.html and the plots into `dir`, each plot as PNG and as SVG
// beside it (each file atomically); returns the files. report.html links the runs' replays the
// folder holds (replay_file_name).
std::vector<std::filesystem::path> write_sweep_reports(const std::filesystem::path& dir,
                                                       const std::vector<RunRecord>& records);

// The texts of sweep.yaml and scenario.yaml, which define `sweep` in its output folder `dir` (a
// folder is resumed only by the sweep whose texts these are).
std::pair<std::string, std::string> sweep_definition(const std::filesystem::path& dir, const Sweep& sweep);
// Writes them into `dir`, each atomically; returns their paths.
std::vector<std::filesystem::path> write_sweep_definition(const std::filesystem::path& dir, const Sweep& sweep);
// Every file a sweep's output folder may hold: results.csv, the reports for these maps
// (write_sweep_reports), sweep.yaml and scenario.yaml, and the replays of `replayed`.
std::vector<std::string> sweep_folder_files(const std::vector<std::string>& map_labels,
                                            const std::vector<SweepRun>& replayed = {});

}  // namespace fleetmap::sweep
