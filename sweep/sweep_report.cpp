// One file, over 500 lines, on purpose: summary.md, summary.csv, the paired comparison and the
// plots are read from the same grouped records and must agree cell for cell.
#include "sweep/sweep_report.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "core/format.h"
#include "core/error.h"
#include "core/suggest.h"
#include "exploration/strategy.h"
#include "io/file_io.h"
#include "io/map_image.h"
#include "io/map_io.h"
#include "viz/html.h"
#include "viz/plot.h"

namespace fleetmap::sweep {

namespace fs = std::filesystem;

namespace {

std::optional<double> optional_steps(const std::optional<int>& v) {
  return v ? std::optional<double>(double(*v)) : std::nullopt;
}

std::string number(double v, int decimals) {
  if (!std::isfinite(v)) return "";
  return core::fixed(v, decimals);
}

// Full precision for CSV: the same records give the same text.
std::string csv_number(double v) {
  if (!std::isfinite(v)) return "";
  return fmt::format("{:.10g}", v);
}

std::string team_text(int robots) { return std::to_string(robots) + (robots == 1 ? " robot" : " robots"); }

// Distinct values in order of first appearance.
template <typename T, typename F>
std::vector<T> distinct(const std::vector<RunRecord>& records, F get) {
  std::vector<T> out;
  for (const auto& r : records) {
    const T v = get(r);
    if (std::find(out.begin(), out.end(), v) == out.end()) out.push_back(v);
  }
  return out;
}

std::vector<std::string> maps_of(const std::vector<RunRecord>& r) {
  return distinct<std::string>(r, [](const RunRecord& x) { return x.key.map; });
}
std::vector<std::string> strategies_of(const std::vector<RunRecord>& r) {
  return distinct<std::string>(r, [](const RunRecord& x) { return x.key.strategy; });
}
// Strategies, each with its variants of the sweep's further axes: the curves of the plots.
std::vector<std::string> series_of(const std::vector<RunRecord>& r) {
  return distinct<std::string>(r, [](const RunRecord& x) { return series_label(x.key); });
}
std::vector<int> teams_of(const std::vector<RunRecord>& r) {
  auto t = distinct<int>(r, [](const RunRecord& x) { return x.key.robots; });
  std::sort(t.begin(), t.end());
  return t;
}

viz::Color strategy_color(const std::vector<std::string>& strategies, const std::string& s) {
  return viz::palette_color(int(std::find(strategies.begin(), strategies.end(), s) - strategies.begin()));
}

using core::join;

std::size_t metric_index(const std::string& name) {
  const auto& m = report_metrics();
  return std::size_t(std::find_if(m.begin(), m.end(), [&](const ReportMetric& x) { return x.name == name; }) - m.begin());
}

// The row whose mean is best in metric m and whose 95% interval lies clear of every other row's
// interval; nullptr when there is none (intervals overlap, or a row has too few runs for one).
const GroupSummary* clearly_best(const std::vector<const GroupSummary*>& rows, std::size_t m, bool higher_is_better) {
  const GroupSummary* best = nullptr;
  for (const auto* g : rows) {
    const double v = g->metrics[m].mean;
    if (!std::isfinite(v)) continue;
    if (!best || (higher_is_better ? v > best->metrics[m].mean : v < best->metrics[m].mean)) best = g;
  }
  if (!best) return nullptr;
  const SampleSummary& b = best->metrics[m];
  int others = 0;
  for (const auto* g : rows) {
    const SampleSummary& o = g->metrics[m];
    if (g == best || o.n == 0) continue;
    ++others;
    if (!std::isfinite(b.ci_low) || !std::isfinite(o.ci_low)) return nullptr;
    if (!(b.ci_high < o.ci_low || o.ci_high < b.ci_low)) return nullptr;
  }
  return others > 0 ? best : nullptr;
}

}  // namespace

const std::vector<ReportMetric>& report_metrics() {
  static const std::vector<ReportMetric> kMetrics = {
      {"steps_to_95", "steps to 95%", false, 1, [](const RunRecord& r) { return optional_steps(r.steps_to_95); }},
      {"steps_to_99", "steps to 99%", false, 1, [](const RunRecord& r) { return optional_steps(r.steps_to_99); }},
      {"distance_m", "distance (m)", false, 1, [](const RunRecord& r) { return std::optional<double>(r.distance_m); }},
      {"redundancy", "redundancy", false, 3, [](const RunRecord& r) { return std::optional<double>(r.redundancy); }},
      {"bytes_sent", "bytes sent", false, 0, [](const RunRecord& r) { return std::optional<double>(double(r.bytes_sent)); }},
      {"efficiency", "efficiency", true, 3, [](const RunRecord& r) { return r.efficiency; }},
      {"coverage", "final coverage", true, 4, [](const RunRecord& r) { return std::optional<double>(r.coverage); }},
  };
  return kMetrics;
}

const ReportMetric& find_report_metric(const std::string& name, const std::string& what) {
  std::vector<std::string> names;
  for (const auto& m : report_metrics()) {
    if (m.name == name) return m;
    names.push_back(m.name);
  }
  throw InputError(what + ": unknown metric '" + name + "'" + core::did_you_mean(name, names) + " (valid: " + join(names) + ")");
}

std::vector<GroupSummary> summarize_groups(const std::vector<RunRecord>& records) {
  struct Group {
    GroupSummary summary;
    std::vector<std::vector<double>> values;
  };
  std::vector<Group> groups;
  std::map<std::tuple<std::string, std::string, std::string, int>, std::size_t> index;
  const auto& metrics = report_metrics();
  for (const auto& r : records) {
    const auto key = std::make_tuple(r.key.map, r.key.strategy, r.key.variant, r.key.robots);
    auto it = index.find(key);
    if (it == index.end()) {
      it = index.emplace(key, groups.size()).first;
      Group g;
      g.summary.map = r.key.map;
      g.summary.strategy = r.key.strategy;
      g.summary.variant = r.key.variant;
      g.summary.robots = r.key.robots;
      g.summary.lower_bound_min = g.summary.lower_bound_max = r.lower_bound_steps;
      g.values.resize(metrics.size());
      groups.push_back(std::move(g));
    }
    Group& g = groups[it->second];
    ++g.summary.runs;
    g.summary.lower_bound_min = std::min(g.summary.lower_bound_min, r.lower_bound_steps);
    g.summary.lower_bound_max = std::max(g.summary.lower_bound_max, r.lower_bound_steps);
    for (std::size_t m = 0; m < metrics.size(); ++m) {
      if (const auto v = metrics[m].value(r)) g.values[m].push_back(*v);
    }
  }
  std::vector<GroupSummary> out;
  for (auto& g : groups) {
    for (const auto& v : g.values) g.summary.metrics.push_back(summarize(v));
    out.push_back(std::move(g.summary));
  }
  return out;
}

std::string summary_csv(const std::vector<GroupSummary>& groups) {
  std::string text = "map,strategy,variant,robots,runs,lower_bound_steps_min,lower_bound_steps_max";
  for (const auto& m : report_metrics()) {
    for (const char* part : {"_n", "_mean", "_sd", "_ci95_low", "_ci95_high"}) text += "," + m.name + part;
  }
  text += "\n";
  for (const auto& g : groups) {
    text += g.map + "," + g.strategy + "," + g.variant + "," + std::to_string(g.robots) + "," + std::to_string(g.runs) + "," +
            std::to_string(g.lower_bound_min) + "," + std::to_string(g.lower_bound_max);
    for (const auto& s : g.metrics) {
      text += "," + std::to_string(s.n) + "," + csv_number(s.mean) + "," + csv_number(s.sd) + "," + csv_number(s.ci_low) +
              "," + csv_number(s.ci_high);
    }
    text += "\n";
  }
  return text;
}

namespace {

// One table of the summary: a map and team size, a row per strategy (and variant).
struct SummaryTable {
  std::string map, heading;
  std::vector<std::string> header;
  struct Cell {
    Cell(std::string text = {}) : text(std::move(text)) {}
    std::string text;
    bool best = false;  // clearly the best in its column
    std::string note;   // "(k/n)" when only k of n runs have the metric
  };
  std::vector<std::vector<Cell>> rows;
};

// The line under the title: what was run, with which settings.
std::string sweep_description(const std::vector<RunRecord>& records) {
  const auto seeds = distinct<std::uint64_t>(records, [](const RunRecord& r) { return r.key.seed; });
  std::vector<std::string> team_texts;
  for (int t : teams_of(records)) team_texts.push_back(std::to_string(t));
  const RunRecord& first = records.front();
  const std::string settings = fmt::format(
      "localization {}, merging {}, communication range {}, sensor range {:g} m, step limit {} (settings {})",
      first.localization, first.merging, std::isinf(first.comm_range_m) ? "unlimited" : number(first.comm_range_m, 1) + " m",
      first.sensor_range_m, first.step_limit, first.settings);
  const auto variants = distinct<std::string>(records, [](const RunRecord& r) { return r.key.variant; });
  const std::string varied = variants.size() > 1 || !variants.front().empty() ? "; variants " + join(variants) : "";
  return std::to_string(records.size()) + " runs: maps " + join(maps_of(records)) + "; strategies " + join(strategies_of(records)) +
         varied + "; team sizes " + join(team_texts) + "; " + std::to_string(seeds.size()) +
         (seeds.size() == 1 ? " seed. " : " seeds. ") + settings + ".";
}

std::vector<SummaryTable> summary_tables(const std::vector<RunRecord>& records, const std::vector<GroupSummary>& groups) {
  const auto& metrics = report_metrics();
  std::vector<SummaryTable> tables;
  for (const auto& map : maps_of(records)) {
    for (int team : teams_of(records)) {
      std::vector<const GroupSummary*> rows;
      for (const auto& g : groups) {
        if (g.map == map && g.robots == team) rows.push_back(&g);
      }
      if (rows.empty()) continue;
      int lb_lo = rows.front()->lower_bound_min, lb_hi = rows.front()->lower_bound_max;
      for (const auto* g : rows) lb_lo = std::min(lb_lo, g->lower_bound_min), lb_hi = std::max(lb_hi, g->lower_bound_max);
      SummaryTable table;
      table.map = map;
      table.heading = team_text(team) + " (lower bound " +
                      (lb_lo == lb_hi ? std::to_string(lb_lo) : std::to_string(lb_lo) + "-" + std::to_string(lb_hi)) +
                      " steps to 99%)";
      table.header = {"strategy", "runs"};
      for (const auto& m : metrics) table.header.push_back(m.title);
      std::vector<const GroupSummary*> best(metrics.size(), nullptr);
      for (std::size_t m = 0; m < metrics.size(); ++m) best[m] = clearly_best(rows, m, metrics[m].higher_is_better);
      for (const auto* g : rows) {
        std::vector<SummaryTable::Cell> row = {{g->series()}, {std::to_string(g->runs)}};
        for (std::size_t m = 0; m < metrics.size(); ++m) {
          const SampleSummary& s = g->metrics[m];
          SummaryTable::Cell cell{"—"};
          if (s.n > 0) {
            cell.text = number(s.mean, metrics[m].decimals);
            if (s.n > 1) cell.text += " ± " + number(s.half_width(), metrics[m].decimals);
            cell.best = best[m] == g;
            if (s.n < g->runs) cell.note = fmt::format("({}/{})", s.n, g->runs);
          }
          row.push_back(std::move(cell));
        }
        table.rows.push_back(std::move(row));
      }
      tables.push_back(std::move(table));
    }
  }
  return tables;
}

}  // namespace

std::string replay_file_name(const RunKey& key) {
  std::string name = fmt::format("replay_{}_{}_{}r_s{}", key.map, key.strategy, key.robots, key.seed);
  if (!key.variant.empty()) name += "_" + key.variant;
  // A plain file name whatever the map's or variant's text: other characters become '-'.
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '.' && c != '-') c = '-';
  }
  return name + ".html";
}

std::string summary_markdown(const std::vector<RunRecord>& records, const std::vector<GroupSummary>& groups) {
  std::string md = "# Strategy sweep\n\n";
  if (records.empty()) return md + "No runs yet.\n";
  md += sweep_description(records) + "\n\n";
  md += "Each cell: mean ± half-width of the 95% confidence interval (Student t) over seeds; (k/n) when only k of n runs "
        "reached the level. **Bold**: the best strategy in the column for that map and team size (lowest; highest for "
        "efficiency and coverage), only when its 95% interval overlaps no other row's (so never with one seed). "
        "Efficiency = lower bound / steps to 99% (README.md, \"Benchmarking strategies\").\n";
  std::string map;
  for (const auto& table : summary_tables(records, groups)) {
    if (table.map != map) md += "\n## " + table.map + "\n";
    map = table.map;
    md += "\n### " + table.heading + "\n\n|";
    for (const auto& h : table.header) md += " " + h + " |";
    md += "\n|---|";
    for (std::size_t m = 1; m < table.header.size(); ++m) md += "---:|";
    md += "\n";
    for (const auto& row : table.rows) {
      md += "|";
      for (const auto& c : row) md += " " + (c.best ? "**" + c.text + "**" : c.text) + (c.note.empty() ? "" : " " + c.note) + " |";
      md += "\n";
    }
  }
  return md;
}

std::string report_html(const std::vector<RunRecord>& records, const std::vector<GroupSummary>& groups,
                        const std::vector<SweepPlot>& plots, const std::function<std::string(const RunKey&)>& replay_of) {
  using viz::html_escape;
  std::string h = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>Strategy sweep</title>\n";
  h += std::string(viz::page_style());
  h += "<style>svg { max-width: 100%; height: auto; } svg .tip:hover { fill-opacity: 0.35; } td.best { font-weight: bold; "
       "background: #eaf4ea; } .plots { display: flex; flex-wrap: wrap; gap: 12px; }</style>\n</head>\n<body>\n";
  h += "<h1>Strategy sweep</h1>\n";
  if (records.empty()) return h + "<p>No runs yet.</p>\n</body>\n</html>\n";
  h += "<p class=\"facts\">" + html_escape(sweep_description(records)) + "</p>\n";
  h += "<p>Each cell: mean ± half-width of the 95% confidence interval (Student t) over seeds; (k/n) when only k of n runs "
       "reached the level. <b>Bold</b>: the best strategy in the column for that map and team size, only when its 95% "
       "interval overlaps no other row's. Efficiency = lower bound / steps to 99%. Rest the pointer on a plot's curve or bar "
       "for its numbers.</p>\n";
  std::string map;
  for (const auto& table : summary_tables(records, groups)) {
    if (table.map != map) {
      h += "<h2>" + html_escape(table.map) + "</h2>\n<div class=\"plots\">\n";
      for (const auto& p : plots) {
        if (p.file == "coverage_" + table.map + ".png" || p.file == "time_" + table.map + ".png") {
          const std::string svg = viz::to_svg(p.drawing);
          h += svg.substr(svg.find("<svg"));  // inline, without the XML declaration
        }
      }
      h += "</div>\n";
    }
    map = table.map;
    h += "<h3>" + html_escape(table.heading) + "</h3>\n<table>\n<tr>";
    for (std::size_t k = 0; k < table.header.size(); ++k)
      h += std::string(k == 0 ? "<th class=\"text\">" : "<th>") + html_escape(table.header[k]) + "</th>";
    h += "</tr>\n";
    for (const auto& row : table.rows) {
      h += "<tr>";
      for (std::size_t k = 0; k < row.size(); ++k) {
        const auto& c = row[k];
        h += std::string(k == 0 ? "<td class=\"text\">" : c.best ? "<td class=\"best\">" : "<td>") + html_escape(c.text) +
             (c.note.empty() ? "" : " " + html_escape(c.note)) + "</td>";
      }
      h += "</tr>\n";
    }
    h += "</table>\n";
  }
  for (const auto& p : plots) {
    if (p.file != "efficiency.png") continue;
    h += "<h2>Efficiency</h2>\n";
    const std::string svg = viz::to_svg(p.drawing);
    h += svg.substr(svg.find("<svg"));
  }
  // Every run, with its replay when one was written.
  h += "<h2>Runs</h2>\n<details><summary>" + std::to_string(records.size()) +
       " runs (click to show)</summary>\n<table>\n<tr><th class=\"text\">map</th><th class=\"text\">strategy</th>"
       "<th>robots</th><th>seed</th><th>steps to 99%</th><th>coverage</th><th>distance (m)</th><th class=\"text\">replay</th></tr>\n";
  for (const auto& r : records) {
    const std::string replay = replay_of ? replay_of(r.key) : std::string();
    h += "<tr><td class=\"text\">" + html_escape(r.key.map) + "</td><td class=\"text\">" + html_escape(series_label(r.key)) +
         "</td><td>" + std::to_string(r.key.robots) + "</td><td>" + std::to_string(r.key.seed) + "</td><td>" +
         (r.steps_to_99 ? std::to_string(*r.steps_to_99) : std::string("—")) + "</td><td>" + number(100.0 * r.coverage, 1) +
         "%</td><td>" + number(r.distance_m, 1) + "</td><td class=\"text\">" +
         (replay.empty() ? std::string() : "<a href=\"" + html_escape(replay) + "\">replay</a>") + "</td></tr>\n";
  }
  h += "</table>\n</details>\n</body>\n</html>\n";
  return h;
}

namespace {

struct AxisValue {
  std::string axis, value;
};

// "coordinated" is a strategy; "beams=90" a value of a setting.
AxisValue compared_value(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos) return {"strategy", text};
  return {text.substr(0, eq), text.substr(eq + 1)};
}

std::optional<std::string> value_on(const RunRecord& r, const std::string& axis) {
  if (axis == "strategy") return r.key.strategy;
  if (axis == "robots") return std::to_string(r.key.robots);
  if (axis == "map") return r.key.map;
  return variant_value(r.key.variant, axis);
}

// The run's key without the compared setting: runs with equal partner keys pair.
RunKey partner_key(const RunRecord& r, const std::string& axis) {
  RunKey k = r.key;
  if (axis == "strategy") k.strategy.clear();
  else if (axis == "robots") k.robots = 0;
  else if (axis == "map") k.map.clear();
  else k.variant = variant_without(k.variant, axis);
  return k;
}

std::vector<std::string> values_present(const std::vector<RunRecord>& records, const std::string& axis) {
  std::vector<std::string> values;
  for (const auto& r : records) {
    const auto v = value_on(r, axis);
    if (v && std::find(values.begin(), values.end(), *v) == values.end()) values.push_back(*v);
  }
  return values;
}

// The settings runs can be compared on: robots, map, and the axes the sweep varied.
std::vector<std::string> axes_present(const std::vector<RunRecord>& records) {
  std::vector<std::string> axes = {"robots", "map"};
  for (const auto& r : records) {
    for (const auto& name : variant_names(r.key.variant)) {
      if (std::find(axes.begin(), axes.end(), name) == axes.end()) axes.push_back(name);
    }
  }
  return axes;
}

}  // namespace

StrategyComparison compare_strategies(const std::vector<RunRecord>& records, const std::string& a_text,
                                      const std::string& b_text, const std::string& metric_name) {
  const ReportMetric& metric = find_report_metric(metric_name, "metric");
  const AxisValue a = compared_value(a_text), b = compared_value(b_text);
  if (a.axis != b.axis) {
    throw InputError("compare two values of one setting, got '" + a_text + "' (" + a.axis + ") and '" + b_text + "' (" +
                     b.axis + ")");
  }
  const std::string& axis = a.axis;
  for (const auto& x : {a, b}) {
    const bool present = std::any_of(records.begin(), records.end(), [&](const RunRecord& r) { return value_on(r, axis) == x.value; });
    if (present) continue;
    const auto values = values_present(records, axis);
    const std::string there = values.empty() ? std::string("none") : join(values);
    if (axis == "strategy") {
      // A strategy that exists but was not run is no typo.
      const auto known = exploration::strategy_names();
      const bool exists = std::find(known.begin(), known.end(), x.value) != known.end();
      throw InputError("no runs of strategy '" + x.value + "' in the results" + (exists ? "" : core::did_you_mean(x.value, values)) +
                       " (strategies there: " + there + ")");
    }
    const std::string hint = values.empty() ? core::did_you_mean(axis, axes_present(records)) : core::did_you_mean(x.value, values);
    throw InputError("no runs with " + axis + "=" + x.value + " in the results" + hint + " (" + axis + " there: " + there +
                     "; settings to compare: strategy names, robots=N, map=NAME, or an axis the sweep varied)");
  }
  if (a.value == b.value) {
    throw InputError(axis == "strategy" ? "give two different strategies, got '" + a.value + "' twice"
                                        : "give two different values of " + axis + ", got '" + a.value + "' twice");
  }
  StrategyComparison c;
  c.axis = axis;
  c.a = a_text;
  c.b = b_text;
  c.metric = metric.name;
  c.higher_is_better = metric.higher_is_better;
  std::map<RunKey, std::pair<std::optional<double>, std::optional<double>>> pairs;
  int runs = 0;
  for (const auto& r : records) {
    const auto v = value_on(r, axis);
    if (v != a.value && v != b.value) continue;
    ++runs;
    auto& p = pairs[partner_key(r, axis)];
    (v == a.value ? p.first : p.second) = metric.value(r);
  }
  struct Sample {
    std::vector<double> a, b;
  };
  std::map<std::pair<std::string, int>, Sample> by_group;
  std::map<std::string, Sample> by_map;
  Sample all;
  int paired = 0;
  for (const auto& [key, p] : pairs) {
    if (!p.first || !p.second) continue;
    paired += 2;
    for (Sample* s : {&by_group[{key.map, key.robots}], &by_map[key.map], &all}) {
      s->a.push_back(*p.first);
      s->b.push_back(*p.second);
    }
  }
  c.unpaired = runs - paired;
  // Rows per map and team size, then per map, then over everything (a compared map or team size
  // has no rows of its own).
  const std::vector<std::string> maps = axis == "map" ? std::vector<std::string>{""} : maps_of(records);
  const std::vector<int> teams = axis == "robots" ? std::vector<int>{0} : teams_of(records);
  if (axis != "map" && axis != "robots") {
    for (const auto& map : maps) {
      for (int team : teams) {
        if (const auto it = by_group.find({map, team}); it != by_group.end()) {
          c.rows.push_back({map, team, compare_paired(it->second.a, it->second.b)});
        }
      }
    }
  }
  if (axis != "map") {
    for (const auto& map : maps) {
      if (const auto it = by_map.find(map); it != by_map.end()) c.rows.push_back({map, 0, compare_paired(it->second.a, it->second.b)});
    }
  }
  c.rows.push_back({"all", 0, compare_paired(all.a, all.b)});
  return c;
}

std::string comparison_text(const StrategyComparison& c) {
  const ReportMetric& metric = find_report_metric(c.metric, "metric");
  const int d = std::max(metric.decimals, 2);
  const std::string alike = c.axis == "strategy" ? "the same map, team size and seed"
                            : c.axis == "robots" ? "the same map, strategy, seed and other settings"
                            : c.axis == "map"    ? "the same strategy, team size, seed and other settings"
                                                 : "the same map, strategy, team size, seed and other settings";
  std::string t = "Paired comparison of " + c.metric + ": " + c.a + " - " + c.b + " over runs with " + alike + "\n";
  t += "(negative: " + c.a + "'s value is lower; " + (c.higher_is_better ? "higher" : "lower") +
       " is better. The interval is the 95% confidence interval of the mean difference, p the two-sided paired t test)\n\n";
  t += "| map | robots | pairs | mean difference | 95% CI | p | " + c.a + " better | " + c.b + " better | ties |\n";
  t += "|---|---|---:|---:|---|---:|---:|---:|---:|\n";
  for (const auto& row : c.rows) {
    const auto& x = row.comparison;
    const int a_better = c.higher_is_better ? x.b_lower : x.a_lower;
    const int b_better = c.higher_is_better ? x.a_lower : x.b_lower;
    const std::string p = !std::isfinite(x.p_value) ? ""
                          : x.p_value < 0.001     ? fmt::format("{:.1e}", x.p_value)
                                                  : fmt::format("{:.3f}", x.p_value);
    const std::string ci = x.difference.n > 1 ? "[" + number(x.difference.ci_low, d) + ", " + number(x.difference.ci_high, d) + "]" : "";
    t += "| " + row.map + " | " + (row.robots > 0 ? std::to_string(row.robots) : std::string("all")) + " | " +
         std::to_string(x.difference.n) + " | " + number(x.difference.mean, d) + " | " + ci + " | " + p + " | " +
         std::to_string(a_better) + " | " + std::to_string(b_better) + " | " + std::to_string(x.ties) + " |\n";
  }
  if (c.unpaired > 0) {
    t += "\n" + std::to_string(c.unpaired) + " runs had no partner with a value of " + c.metric +
         " (the partner run is missing, or a level was never reached) and were left out.\n";
  }
  return t;
}

namespace {

// Coverage against step on `map`: a panel per team size, a curve per strategy with its 95% band.
viz::Drawing coverage_plot(const std::vector<RunRecord>& records, const std::string& map, const std::vector<int>& teams,
                           const std::vector<std::string>& strategies) {
  std::vector<viz::Drawing> panels;
  for (int team : teams) {
    std::vector<const RunRecord*> runs;
    int last = 1;
    for (const auto& r : records) {
      if (r.key.map != map || r.key.robots != team) continue;
      runs.push_back(&r);
      last = std::max(last, r.steps_to_99 ? *r.steps_to_99 : r.steps);
    }
    if (runs.empty()) continue;
    last = int(std::ceil(last * 1.05));
    viz::LinePlot plot;
    plot.title = map + ", " + team_text(team);
    plot.x = {"step", 0.0, double(last), {}};
    plot.y = {"coverage of the observable space (%)", 0.0, 100.0, {}};
    for (const auto& strategy : strategies) {
      std::vector<const RunRecord*> mine;
      for (const auto* r : runs) {
        if (series_label(r->key) == strategy) mine.push_back(r);
      }
      if (mine.empty()) continue;
      viz::PlotSeries s;
      s.label = strategy;
      s.color = strategy_color(strategies, strategy);
      for (int step = 0; step <= last; ++step) {
        std::vector<double> v;
        for (const auto* r : mine) v.push_back(100.0 * coverage_at(*r, step));
        const SampleSummary sum = summarize(v);
        s.x.push_back(step);
        s.y.push_back(sum.mean);
        s.y_low.push_back(sum.n > 1 ? sum.ci_low : sum.mean);
        s.y_high.push_back(sum.n > 1 ? sum.ci_high : sum.mean);
      }
      plot.series.push_back(std::move(s));
    }
    panels.push_back(viz::line_plot(plot, {760, 500}));
  }
  return viz::tile(panels, 2);
}

// Steps to 99% against team size on `map`, a line per strategy, with the lower bound.
viz::Drawing time_plot(const std::vector<GroupSummary>& groups, const std::string& map, const std::vector<int>& teams,
                  const std::vector<std::string>& strategies) {
  const std::size_t steps99 = metric_index("steps_to_99");
  viz::LinePlot time;
  time.title = map + ": steps to 99% coverage (mean, 95% CI)";
  time.x = {"robots", std::nullopt, std::nullopt, {}};
  for (int team : teams) time.x.ticks.push_back(team);
  time.y = {"steps", 0.0, std::nullopt, {}};
  time.bands = false;
  for (const auto& strategy : strategies) {
    viz::PlotSeries s;
    s.label = strategy;
    s.color = strategy_color(strategies, strategy);
    s.markers = true;
    for (const auto& g : groups) {
      if (g.map != map || g.series() != strategy || g.metrics[steps99].n == 0) continue;
      const SampleSummary& m = g.metrics[steps99];
      s.x.push_back(g.robots);
      s.y.push_back(m.mean);
      s.y_low.push_back(m.n > 1 ? m.ci_low : m.mean);
      s.y_high.push_back(m.n > 1 ? m.ci_high : m.mean);
    }
    if (!s.x.empty()) time.series.push_back(std::move(s));
  }
  viz::PlotSeries bound;
  bound.label = "lower bound";
  bound.color = {90, 90, 90};
  bound.dashed = true;
  for (int team : teams) {
    int lb = -1;
    for (const auto& g : groups) {
      if (g.map == map && g.robots == team) lb = std::max(lb, g.lower_bound_max);
    }
    if (lb < 0) continue;
    bound.x.push_back(team);
    bound.y.push_back(lb);
  }
  time.series.push_back(std::move(bound));
  return viz::line_plot(time);
}

// Efficiency per strategy, on each map and on all maps.
viz::Drawing efficiency_chart(const std::vector<RunRecord>& records, const std::vector<std::string>& maps,
                         const std::vector<std::string>& strategies) {
  viz::BarChart bars;
  bars.title = "efficiency = lower bound / steps to 99% (mean over team sizes and seeds, 95% CI)";
  bars.y_label = "efficiency";
  bars.groups = maps;
  bars.groups.push_back("all maps");
  for (const auto& strategy : strategies) {
    bars.series_labels.push_back(strategy);
    bars.colors.push_back(strategy_color(strategies, strategy));
    std::vector<double> mean, low, high;
    for (std::size_t g = 0; g < bars.groups.size(); ++g) {
      std::vector<double> v;
      for (const auto& r : records) {
        if (series_label(r.key) == strategy && (g == maps.size() || r.key.map == maps[g]) && r.efficiency) {
          v.push_back(*r.efficiency);
        }
      }
      const SampleSummary s = summarize(v);
      mean.push_back(s.mean);
      low.push_back(s.ci_low);
      high.push_back(s.ci_high);
    }
    bars.values.push_back(mean);
    bars.low.push_back(low);
    bars.high.push_back(high);
  }
  return viz::bar_chart(bars, {std::max(900, 160 * int(bars.groups.size()) + 300), 560});
}

}  // namespace

std::vector<SweepPlot> sweep_plots(const std::vector<RunRecord>& records) {
  std::vector<SweepPlot> plots;
  if (records.empty()) return plots;
  const auto maps = maps_of(records);
  const auto strategies = series_of(records);
  const auto teams = teams_of(records);
  const auto groups = summarize_groups(records);
  for (const auto& map : maps) {
    plots.push_back({"coverage_" + map + ".png", coverage_plot(records, map, teams, strategies), {}});
    plots.push_back({"time_" + map + ".png", time_plot(groups, map, teams, strategies), {}});
  }
  plots.push_back({"efficiency.png", efficiency_chart(records, maps, strategies), {}});
  for (auto& p : plots) p.image = viz::rasterize(p.drawing);
  return plots;
}

std::vector<fs::path> write_sweep_reports(const fs::path& dir, const std::vector<RunRecord>& records) {
  io::ensure_directory(dir);
  std::vector<fs::path> written;
  const auto groups = summarize_groups(records);
  io::write_file_atomic(dir / "summary.csv", summary_csv(groups));
  written.push_back(dir / "summary.csv");
  io::write_file_atomic(dir / "summary.md", summary_markdown(records, groups));
  written.push_back(dir / "summary.md");
  const auto plots = sweep_plots(records);
  // A run's replay is linked when the folder holds it.
  const auto replay_of = [&](const RunKey& key) {
    const std::string name = replay_file_name(key);
    return io::is_regular_file(dir / name) ? name : std::string();
  };
  io::write_file_atomic(dir / "report.html", report_html(records, groups, plots, replay_of));
  written.push_back(dir / "report.html");
  for (const auto& plot : plots) {
    if (plot.image.empty()) continue;
    io::write_image(dir / plot.file, plot.image);
    written.push_back(dir / plot.file);
    const fs::path svg = (dir / plot.file).replace_extension(".svg");
    io::write_file_atomic(svg, viz::to_svg(plot.drawing));
    written.push_back(svg);
  }
  return written;
}

std::pair<std::string, std::string> sweep_definition(const fs::path& dir, const Sweep& sweep) {
  return {sweep_to_yaml(sweep, "scenario.yaml"), sim::scenario_to_yaml(sweep.base, dir)};
}

std::vector<fs::path> write_sweep_definition(const fs::path& dir, const Sweep& sweep) {
  const auto [sweep_yaml, scenario_yaml] = sweep_definition(dir, sweep);
  io::write_file_atomic(dir / "scenario.yaml", scenario_yaml);
  io::write_file_atomic(dir / "sweep.yaml", sweep_yaml);
  return {dir / "sweep.yaml", dir / "scenario.yaml"};
}

std::vector<std::string> sweep_folder_files(const std::vector<std::string>& map_labels,
                                            const std::vector<SweepRun>& replayed) {
  std::vector<std::string> files = {"results.csv", "summary.csv", "summary.md", "report.html", "sweep.yaml", "scenario.yaml"};
  for (const auto& r : replayed) files.push_back(replay_file_name(run_key(r)));
  std::vector<std::string> plots = {"efficiency"};
  for (const auto& m : map_labels) {
    plots.push_back("coverage_" + m);
    plots.push_back("time_" + m);
  }
  for (const auto& p : plots) {
    files.push_back(p + ".png");
    files.push_back(p + ".svg");
  }
  return files;
}

}  // namespace fleetmap::sweep
