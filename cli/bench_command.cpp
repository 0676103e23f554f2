// `fleetmap bench`: the coordination-strategy benchmark. Runs a sweep (maps x strategies x team
// sizes x seeds) on a pool of threads, appending each run's row to results.csv; resumes an
// interrupted sweep; runs one shard of it; combines shards; compares two strategies run by run.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "cli/command.h"
#include "cli/map_notes.h"
#include "cli/progress.h"
#include "cli/sweep_flags.h"
#include "cli/validators.h"
#include "core/format.h"
#include "core/error.h"
#include "io/file_io.h"
#include "io/yaml_reader.h"
#include "io/map_io.h"
#include "exploration/strategy.h"
#include "localization/localizer.h"
#include "maps/builtin_maps.h"
#include "sim/scenario.h"
#include "sweep/sweep.h"
#include "sweep/sweep_report.h"
#include "sweep/sweep_results.h"
#include "sweep/sweep_runner.h"

namespace fleetmap::cli {

namespace fs = std::filesystem;

namespace {

constexpr const char* kCompareMetric = "steps_to_99";

struct BenchFlags {
  std::string sweep_file;
  SweepFlags sweep;
  int jobs = std::max(1u, std::thread::hardware_concurrency());
  std::string shard;
  std::string out;
  std::vector<std::string> combine;
  std::vector<std::string> compare;
  std::optional<std::string> metric;  // of --compare
  bool quiet = false;
  bool html = false;
};

// "1 map", "4 maps".
std::string counted(std::size_t n, const std::string& one, const std::string& many = "") {
  return std::to_string(n) + " " + (n == 1 ? one : many.empty() ? one + "s" : many);
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

bool any_sweep_flag(const BenchFlags& f) {
  return !f.sweep_file.empty() || !f.shard.empty() || f.sweep.any();
}

fs::path results_of(const std::string& dir, const std::string& flag) {
  const fs::path d = dir;
  if (!io::is_folder(d)) throw InputError(flag + ": '" + dir + "' is not a folder");
  if (!io::is_regular_file(d / "results.csv")) {
    throw InputError(flag + ": '" + dir + "' holds no results.csv (not an output folder of fleetmap bench)");
  }
  return d / "results.csv";
}

// The sweep a results folder was made by (its sweep.yaml), if it has one that loads here. One that
// does not (a strategy registered by the program that ran it, e.g. in Python; a map file moved
// since) is named in a note on stderr, and the results combine without it.
std::optional<sweep::Sweep> sweep_of(const fs::path& dir) {
  if (!io::is_regular_file(dir / "sweep.yaml")) return std::nullopt;
  try {
    return sweep::load_sweep(dir / "sweep.yaml");
  } catch (const InputError& e) {
    fmt::print(stderr, "fleetmap: note: {}; combining without it (runs in key order, missing runs not counted)\n",
               e.what());
    return std::nullopt;
  }
}

// The first top-level key whose value differs between two YAML texts, with both values as
// flow YAML ("(none)" where a text lacks the key); nullopt when every key is the same.
struct KeyDifference {
  std::string key, a, b;
};
std::optional<KeyDifference> first_differing_key(const std::string& a_text, const std::string& a_source,
                                                 const std::string& b_text, const std::string& b_source) {
  const YAML::Node a = io::parse_yaml(a_text, a_source), b = io::parse_yaml(b_text, b_source);
  const auto flow = [](const YAML::Node& root, const std::string& key) {
    if (!root.IsMap() || !root[key]) return std::string("(none)");
    YAML::Emitter out;
    out << YAML::Flow << root[key];
    return std::string(out.c_str());
  };
  std::vector<std::string> keys;
  for (const auto& root : {a, b}) {
    if (!root.IsMap()) continue;
    for (const auto& kv : root) {
      if (std::find(keys.begin(), keys.end(), kv.first.Scalar()) == keys.end()) keys.push_back(kv.first.Scalar());
    }
  }
  for (const auto& key : keys) {
    if (flow(a, key) != flow(b, key)) return KeyDifference{key, flow(a, key), flow(b, key)};
  }
  return std::nullopt;
}

// The first line where two texts differ, for messages: "seeds: 6" against "seeds: 4".
std::pair<std::string, std::string> first_difference(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i <= a.size() || j <= b.size()) {
    const std::size_t ie = std::min(a.find('\n', i), a.size()), je = std::min(b.find('\n', j), b.size());
    std::string la = i <= a.size() ? a.substr(i, ie - i) : "", lb = j <= b.size() ? b.substr(j, je - j) : "";
    if (la != lb) return {la.empty() ? "(nothing)" : la, lb.empty() ? "(nothing)" : lb};
    i = ie + 1;
    j = je + 1;
  }
  return {"", ""};
}

// A results folder is resumed only by the very same sweep (and shard): its sweep.yaml and
// scenario.yaml must be what this sweep writes, and every row must be a run of this sweep.
void check_same_sweep(const fs::path& out, const sweep::Sweep& sweep, const std::vector<sweep::SweepRun>& runs,
                      const std::vector<sweep::RunRecord>& records) {
  const std::string where = "--out " + out.string() + ": ";
  const auto [sweep_yaml, scenario_yaml] = sweep::sweep_definition(out, sweep);
  for (const auto& [name, now] : {std::pair{std::string("sweep.yaml"), sweep_yaml}, std::pair{std::string("scenario.yaml"), scenario_yaml}}) {
    if (!io::is_regular_file(out / name)) {
      throw InputError(where + "holds results.csv but no " + name + ", so its sweep is unknown; choose another --out");
    }
    const std::string before = io::read_file(out / name, std::size_t{1} << 20);
    if (before != now) {
      const auto [was, is] = first_difference(before, now);
      throw InputError(where + "holds the results of another sweep (" + name + " there has '" + io::printable(was) +
                       "', this sweep '" + io::printable(is) +
                       "'); resume only with the same sweep, or choose another --out");
    }
  }
  std::set<sweep::RunKey> ours;
  for (const auto& r : runs) ours.insert(sweep::run_key(r));
  for (const auto& r : records) {
    if (ours.count(r.key)) continue;
    throw InputError(where + "holds a run that is not part of this sweep" + std::string(runs.size() < sweep::sweep_runs(sweep).size() ? " (shard)" : "") +
                     " (" + sweep::run_key_text(r.key) + "); resume only with the same sweep and shard, or choose another --out");
  }
}

void print_outputs(const fs::path& out, const std::vector<fs::path>& reports) {
  fmt::print("results: {}\nsummary: {} (and report.html, with the plots)\n", (out / "results.csv").string(),
             (out / "summary.md").string());
  fmt::print("plots (PNG, and SVG beside each):");
  for (const auto& p : reports) {
    if (p.extension() == ".png") fmt::print(" {}", p.filename().string());
  }
  fmt::print("\n");
}

int run_compare(const BenchFlags& f) {
  if (any_sweep_flag(f) || !f.combine.empty()) throw InputError("--compare A B DIR takes no sweep flags and no --combine");
  if (f.metric) sweep::find_report_metric(*f.metric, "--metric");
  const fs::path path = results_of(f.compare[2], "--compare");
  const auto table = sweep::read_results(path);
  const auto comparison = [&] {
    try {
      return sweep::compare_strategies(table.records, f.compare[0], f.compare[1], f.metric.value_or(kCompareMetric));
    } catch (const InputError& e) {
      throw InputError(std::string(e.what()).rfind("metric", 0) == 0 ? "--" + std::string(e.what())
                                                                     : "--compare: " + std::string(e.what()));
    }
  }();
  fmt::print("{}", sweep::comparison_text(comparison));
  return 0;
}

int run_combine(const BenchFlags& f) {
  if (any_sweep_flag(f)) throw InputError("--combine DIR... takes only folders and --out (no sweep flags)");
  if (f.out.empty()) throw InputError("--combine needs --out DIR: the folder for the combined results");
  std::vector<sweep::RunRecord> records;
  std::map<sweep::RunKey, std::pair<std::size_t, fs::path>> seen;
  std::string settings;
  fs::path settings_from;
  // Shards of one sweep have the same sweep.yaml, compared as text (so that one a strategy
  // registered in Python wrote, which does not load here, is compared too).
  std::string definition;
  std::optional<fs::path> definition_from;
  for (const auto& dir : f.combine) {
    const fs::path path = results_of(dir, "--combine");
    auto table = sweep::read_results(path);
    if (settings.empty() && !table.records.empty()) settings = table.records.front().settings, settings_from = path;
    sweep::check_settings(table.records, settings, path);
    const fs::path yaml = fs::path(dir) / "sweep.yaml";
    const std::optional<std::string> text =
        io::is_regular_file(yaml) ? std::optional(io::read_file(yaml, std::size_t{1} << 20)) : std::nullopt;
    if (dir == f.combine.front()) {
      definition_from = text ? std::optional(fs::path(dir)) : std::nullopt;
      definition = text.value_or("");
    } else if (text.has_value() != definition_from.has_value()) {
      const std::string with = text ? dir : f.combine.front(), without = text ? f.combine.front() : dir;
      throw InputError("--combine: " + with + " has a sweep.yaml and " + without +
                       " none, so they cannot be shards of one sweep; combine the shards of one sweep only");
    } else if (text) {
      if (const auto d = first_differing_key(definition, (*definition_from / "sweep.yaml").string(), *text, yaml.string())) {
        throw InputError("--combine: " + definition_from->string() + " and " + dir + " are results of different sweeps (" +
                         "their sweep.yaml has '" + d->key + ": " + io::printable(d->a) + "' against '" + d->key + ": " +
                         io::printable(d->b) + "'); combine the shards of one sweep only");
      }
    }
    for (auto& r : table.records) {
      if (const auto it = seen.find(r.key); it != seen.end()) {
        if (sweep::record_without_wall_time(records[it->second.first]) != sweep::record_without_wall_time(r)) {
          throw InputError("--combine: the run " + sweep::run_key_text(r.key) + " differs between " + it->second.second.string() +
                           " and " + path.string());
        }
        continue;
      }
      seen.emplace(r.key, std::make_pair(records.size(), path));
      records.push_back(std::move(r));
    }
  }
  const std::optional<sweep::Sweep> sweep = definition_from ? sweep_of(*definition_from) : std::nullopt;
  const fs::path out = f.out;
  std::vector<fs::path> inputs;
  for (const auto& dir : f.combine) inputs.push_back(fs::path(dir) / "results.csv");
  std::vector<std::string> labels;
  for (const auto& r : records) {
    if (std::find(labels.begin(), labels.end(), r.key.map) == labels.end()) labels.push_back(r.key.map);
  }
  io::OutputFolder folder(out, "bench", sweep::sweep_folder_files(labels), inputs, "--out " + out.string());
  folder.claim();
  std::vector<fs::path> written;
  std::size_t expected = 0;
  if (sweep) {
    const auto runs = sweep::sweep_runs(*sweep);
    expected = runs.size();
    sweep::sort_records(records, runs);
    written = sweep::write_sweep_definition(out, *sweep);
  } else {
    sweep::sort_records(records, {});
  }
  sweep::write_results(out / "results.csv", records);
  written.push_back(out / "results.csv");
  const auto reports = sweep::write_sweep_reports(out, records);
  written.insert(written.end(), reports.begin(), reports.end());
  folder.finish(io::OutputFolder::names(written));
  fmt::print("combined {} runs from {} folders into {}\n", records.size(), f.combine.size(), out.string());
  if (expected > records.size()) {
    fmt::print("note: {} of the sweep's {} runs are missing (shards not finished or not given)\n",
               expected - records.size(), expected);
  }
  print_outputs(out, reports);
  return 0;
}

int run_bench(const BenchFlags& f) {
  if (f.metric && f.compare.empty()) throw InputError("--metric goes with --compare A B DIR: it names the metric compared");
  if (f.compare.size() == 3) return run_compare(f);
  if (!f.combine.empty()) return run_combine(f);

  sweep::Sweep sweep;
  if (!f.sweep_file.empty()) sweep = sweep::load_sweep(f.sweep_file);
  apply_sweep_flags(sweep, f.sweep);
  if (f.html) sweep.base.html_replay = true;
  sweep::validate_sweep(sweep);
  const std::optional<sweep::Shard> shard = f.shard.empty() ? std::nullopt : std::optional(parse_shard(f.shard));
  const auto all_runs = sweep::sweep_runs(sweep);
  const auto runs = shard ? sweep::shard_runs(all_runs, *shard) : all_runs;

  // Every output is checked before the maps are read or a run starts.
  const fs::path out = f.out.empty() ? fs::path("out/bench") : fs::path(f.out);
  std::vector<fs::path> inputs;
  if (!f.sweep_file.empty()) inputs.push_back(f.sweep_file);
  if (f.sweep.scenario) inputs.push_back(*f.sweep.scenario);
  std::vector<std::string> labels;
  for (const auto& source : sweep.maps) {
    labels.push_back(sweep::map_label(source));
    for (auto& file : maps::map_source_files(source)) inputs.push_back(std::move(file));
  }
  io::OutputFolder folder(out, "bench", sweep::sweep_folder_files(labels, sweep.base.html_replay ? runs : std::vector<sweep::SweepRun>{}),
                          inputs, "--out " + out.string());

  sweep::SweepMaps maps;
  for (const auto& source : sweep.maps) {
    try {
      io::MapLoadOptions load;
      load.default_resolution = sweep.base.map_resolution_m;
      maps.emplace(sweep::map_label(source), maps::load_map_source(source, load));
    } catch (const InputError& e) {
      throw InputError(std::string(f.sweep.maps || f.sweep_file.empty() ? "--maps" : f.sweep_file + ": maps") + ": " + e.what());
    }
  }
  sweep::check_placements(sweep, maps);

  const fs::path results = out / "results.csv";
  const std::string settings = sweep::settings_id(sweep.base);

  std::set<sweep::RunKey> done;
  if (io::path_exists(results)) {
    const auto table = sweep::read_results(results);
    check_same_sweep(out, sweep, runs, table.records);
    sweep::check_settings(table.records, settings, results);
    for (const auto& r : table.records) done.insert(r.key);
  }
  std::vector<sweep::SweepRun> todo;
  for (const auto& r : runs) {
    if (!done.count(sweep::run_key(r))) todo.push_back(r);
  }
  for (const auto& source : sweep.maps) {  // the inputs are good: how each map file was read
    io::MapLoadOptions load;
    load.default_resolution = sweep.base.map_resolution_m;
    print_map_notes(source, load, f.sweep.resolution || f.sweep.scenario || !f.sweep_file.empty());
  }
  folder.claim();
  sweep::write_sweep_definition(out, sweep);

  const auto t0 = std::chrono::steady_clock::now();
  {
    sweep::ResultsAppender appender(results);
    ProgressBar bar(!f.quiet);
    long finished = 0;
    bar.update(0, long(todo.size()));
    sweep::run_sweep(sweep, todo, maps, {f.jobs, out}, [&](const sweep::RunRecord& r) {
      appender.append(r);
      bar.update(++finished, long(todo.size()),
                 r.key.map + " " + r.key.strategy + " " + std::to_string(r.key.robots) + "r seed " + std::to_string(r.key.seed));
    });
    bar.finish();
  }
  const double elapsed = seconds_since(t0);

  // The final tables: every row of results.csv, in the sweep's order.
  auto records = sweep::read_results(results).records;
  sweep::sort_records(records, all_runs);
  sweep::write_results(results, records);
  const auto reports = sweep::write_sweep_reports(out, records);
  std::vector<fs::path> written = {out / "sweep.yaml", out / "scenario.yaml", results};
  written.insert(written.end(), reports.begin(), reports.end());
  // The replays of this run and of the earlier run this one resumed.
  for (const auto& r : runs) {
    const fs::path replay = out / sweep::replay_file_name(sweep::run_key(r));
    if (sweep.base.html_replay && io::is_regular_file(replay)) written.push_back(replay);
  }
  folder.finish(io::OutputFolder::names(written));

  if (f.quiet) {
    fmt::print("{}\n", results.string());
    return 0;
  }
  std::size_t variants = 1;
  for (const auto& axis : sweep.axes) variants *= axis.values.size();
  fmt::print("{} runs of {} x {} x {}{} x {}", all_runs.size(), counted(sweep.maps.size(), "map"),
             counted(sweep.strategies.size(), "strategy", "strategies"), counted(sweep.robots.size(), "team size"),
             sweep.axes.empty() ? "" : " x " + counted(variants, "variant"), counted(std::size_t(sweep.seeds), "seed"));
  if (shard) fmt::print("; shard {}/{}: {} runs", shard->index, shard->count, runs.size());
  fmt::print("\nran {} in {:.1f} s with {} job{}; {} already in results.csv\n", counted(todo.size(), "run"), elapsed,
             std::max(1, std::min<int>(f.jobs, int(std::max<std::size_t>(1, todo.size())))),
             std::min<int>(f.jobs, int(std::max<std::size_t>(1, todo.size()))) > 1 ? "s" : "",
             counted(runs.size() - todo.size(), "run"));
  print_outputs(out, reports);
  return 0;
}

}  // namespace

Command add_bench_command(CLI::App& root) {
  CLI::App* app = root.add_subcommand(
      "bench", "Benchmark coordination strategies over maps x strategies x team sizes x seeds: tables and plots");
  app->footer(
      "Runs every combination in parallel (--jobs), with a progress bar and ETA on stderr when it is a terminal,\n"
      "and writes into --out: results.csv (a row per run, appended whole and flushed), summary.csv and summary.md\n"
      "(mean, standard deviation and 95% confidence interval per map x strategy x team size (x --vary values), best marked),\n"
      "coverage_<map>.png, time_<map>.png, efficiency.png (each also as .svg), report.html (the tables and plots in one page,\n"
      "with tooltips; each run linked to its replay with --html), and sweep.yaml. efficiency = lower bound / steps to 99% (README.md, \"Benchmarking\n"
      "strategies\"). Run it again with the same --out after an interruption and it finishes the sweep without\n"
      "redoing finished runs. The same flags give the same rows whatever --jobs (only wall_time_s differs).\n\n"
      "Examples:\n"
      "  fleetmap bench --maps office,cave --strategies all --robots 1,2,4,9 --seeds 20 --jobs 2 --out DIR\n"
      "  fleetmap bench --sweep scenarios/sweeps/wave_paper.yaml --shard 2/4 --out DIR/shard_2\n"
      "  fleetmap bench --combine DIR/shard_1 DIR/shard_2 DIR/shard_3 DIR/shard_4 --out DIR/all\n"
      "  fleetmap bench --compare coordinated uncoordinated DIR\n"
      "  fleetmap bench --maps office --strategies coordinated --vary beams=45,360 --seeds 10 --out DIR\n"
      "  fleetmap bench --compare beams=45 beams=360 DIR\n"
      "  bench/slurm/submit.sh 16 OUT --sweep scenarios/sweeps/wave_paper.yaml     (a Slurm job array)\n\n"
      "Strategies (--strategies):\n" +
      exploration::strategy_help());
  auto f = std::make_shared<BenchFlags>();
  auto& s = f->sweep;
  app->add_option("--sweep", f->sweep_file, "Sweep YAML file (see scenarios/sweeps/); flags below override it")
      ->check(CLI::ExistingFile);
  app->add_option("--maps", s.maps,
                  "Comma-separated built-in maps or map files [default: empty,unstructured,office,corridor]");
  app->add_option("--strategies", s.strategies, "Comma-separated strategies, or all [default: all]");
  app->add_option("--robots", s.robots, "Team sizes, e.g. 1,2,4,9 or 1-9 [default: 1,2,4,9]");
  app->add_option("--seeds", s.seeds, "Seeds per combination [default: 20]")->check(in_range(sweep::kSeedCountRange));
  app->add_option("--first-seed", s.first_seed, "The first seed; runs use first-seed, first-seed + 1, ... [default: 1]")
      ->check(seed_number());
  app->add_option("--scenario", s.scenario,
                  "Scenario file every run starts from (its map, strategy, robots and seed are replaced) "
                  "[default: the scenario defaults of `fleetmap explore`]");
  app->add_option("--steps", s.steps, "Step limit of each run [default: 2000]")->check(in_range(sim::limits::kSteps));
  app->add_option("--localization", s.localization,
                  "How robots know their pose: " + core::join(localization::localizer_names()) + " (see `fleetmap explore --help`) [default: ideal]");
  app->add_option("--merging", s.merging,
                  "How robots bring teammates' maps into their frame: " + core::join(sim::merging_names()) +
                      " (see `fleetmap explore --help`) [default: known]");
  app->add_option("--comm-range", s.comm_range, "Communication range in metres, or inf [default: inf]")
      ->check(in_range(sim::limits::kCommRange));
  app->add_option("--sensor-range", s.sensor_range, "Laser range in metres [default: 4]")
      ->check(in_range(sim::limits::kSensorRange));
  app->add_option("--resolution", s.resolution,
                  "Metres per cell of bare image maps (PNG/PGM without YAML; a map_server YAML has its own) [default: 0.05]")
      ->check(in_range(io::kResolutionRange));
  app->add_option("--vary", s.vary,
                  "A further sweep axis, SETTING=V1,V2,... (repeat for more): a scenario key such as "
                  "sensors.range.beams or communication.range, or beams, sensor_range, comm_range, localization, merging, "
                  "path_planner, steps, noise_position, or a member's parameter strategy.KEY, localization.KEY, planner.KEY or merging.KEY (the members "
                  "that do not declare it run once per value unchanged); e.g. --vary beams=90,360 --vary strategy.beta=0.5,2")
      ->expected(1)
      ->take_all();
  app->add_option("--set", s.set,
                  "A member's parameter in every run, FAMILY.KEY=VALUE with FAMILY strategy, localization, planner, merging "
                  "or a merge method (merging.grid, merging.features) (repeat for more), e.g. --set strategy.beta=0.5 --set "
                  "localization.particles=50 --set merging.features.ratio=0.7; it applies to the members that declare it "
                  "(see `fleetmap plugins`)")
      ->expected(1)
      ->take_all();
  app->add_option("--jobs,-j", f->jobs, "Runs at once (threads) [default: the number of cores]")
      ->check(in_range(sweep::kJobsRange));
  app->add_option("--shard", f->shard, "Run only the K-th of N slices of the sweep, K/N (for clusters; see bench/slurm/)");
  app->add_option("--out,-o", f->out,
                  "Output folder: new, empty, or of an earlier run of the very same sweep, which is resumed "
                  "[default: out/bench]");
  app->add_option("--combine", f->combine, "Join the results of these output folders (shards) into --out")->expected(1, -1);
  app->add_option("--compare", f->compare,
                  "A B DIR: paired comparison on the runs in DIR of strategies A and B, or of two values of one setting "
                  "(robots=2 robots=4, beams=90 beams=360: any --vary axis); runs pair when all else is equal")
      ->expected(3);
  app->add_option("--metric", f->metric,
                  std::string("Metric of --compare: steps_to_95, steps_to_99, distance_m, redundancy, bytes_sent, efficiency, "
                              "coverage [default: ") + kCompareMetric + "]");
  app->add_flag("--quiet,-q", f->quiet, "Print only the path of results.csv; no progress bar");
  app->add_flag("--html", f->html,
                "Also write each run's replay page (replay_<map>_<strategy>_<robots>r_s<seed>.html, as explore --html), "
                "linked from report.html; a sweep's scenario asks for them with outputs: {html: true}");
  return {app, [f]() { return run_bench(*f); }};
}

}  // namespace fleetmap::cli
