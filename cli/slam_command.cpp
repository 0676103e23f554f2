// `fleetmap slam`: a SLAM experiment repeated over many runs (D'Alfonso et al., §4 with
// scenarios/dalfonso_3robots.yaml): Table 1 as Markdown and CSV, every run's numbers, and the maps
// of the first run as pictures. The scenario's `method` picks the SLAM method.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cli/command.h"
#include "cli/corridor_command.h"
#include "cli/landmark_command.h"
#include "cli/progress.h"
#include "cli/slam_log_command.h"
#include "cli/validators.h"
#include "core/format.h"
#include "core/parallel.h"
#include "io/file_io.h"
#include "core/error.h"
#include "experiments/log_slam.h"
#include "experiments/slam_experiment.h"
#include "experiments/slam_output.h"
#include "experiments/slam_scenario.h"
#include "sweep/sweep.h"

namespace fleetmap::cli {

namespace fs = std::filesystem;

namespace {

struct SlamFlags {
  std::string scenario;
  std::optional<int> runs;
  std::optional<std::uint64_t> seed;
  std::optional<int> jobs;
  std::string out;
  bool quiet = false;
  bool sampled_start = false;
  bool exact_start = false;
  SlamLogFlags log;  // --log mode
};

std::string method_names() { return core::join(experiments::slam_method_names()); }

// Refuses each of `unused` that was given: the scenario's experiment has no use for it.
void refuse_unused_flags(const SlamFlags& f, const std::string& experiment, const std::vector<std::string>& unused) {
  const std::pair<const char*, bool> given[] = {
      {"--runs", f.runs.has_value()}, {"--jobs", f.jobs.has_value()}, {"--sampled-start", f.sampled_start},
      {"--exact-start", f.exact_start}, {"--set", !f.log.set.empty()}};
  for (const auto& [flag, set] : given) {
    if (set && std::find(unused.begin(), unused.end(), flag) != unused.end()) {
      throw InputError(std::string(flag) + " does not apply to " +
                       (experiment == "--log" ? std::string("--log") : "the " + experiment + " experiment of " + f.scenario));
    }
  }
}

int run_slam(SlamFlags f) {
  if (!f.log.log.empty()) {
    refuse_unused_flags(f, "--log", {"--runs", "--jobs", "--sampled-start", "--exact-start"});
    f.log.seed = f.seed;
    f.log.out = f.out;
    f.log.quiet = f.quiet;
    return run_slam_log(f.log);
  }
  if (f.scenario.empty()) throw InputError("slam: give --scenario FILE (a paper's experiment) or --log FILE (a laser log)");
  const fs::path out = f.out.empty() ? fs::path("out") / ("slam_" + fs::path(f.scenario).stem().string()) : fs::path(f.out);
  // The corridor loop of León et al. (experiment: leon_corridor) has its own runner.
  if (is_corridor_scenario_file(f.scenario)) {
    refuse_unused_flags(f, "leon_corridor", {"--runs", "--jobs", "--sampled-start", "--exact-start", "--set"});
    return run_corridor_scenario(f.scenario, out, f.seed, f.quiet);
  }
  // The map-alignment paper's experiments (experiment: landmark_alignment) too.
  if (is_landmark_scenario_file(f.scenario)) {
    refuse_unused_flags(f, "landmark_alignment", {"--sampled-start", "--exact-start", "--set"});
    return run_landmark_scenario(f.scenario, out, f.runs, f.seed, f.jobs.value_or(1), f.quiet);
  }
  experiments::SlamScenario s = experiments::load_slam_scenario(f.scenario);
  if (f.runs) s.runs = *f.runs;
  if (f.seed) s.seed = *f.seed;
  if (f.sampled_start) s.sampled_start = true;
  if (f.exact_start) s.sampled_start = false;
  for (const auto& text : f.log.set) {
    const auto a = core::parse_param_assignment(text, "--set " + text);
    if (a.family != "method") {
      throw InputError("--set " + text + ": a SLAM scenario takes method.KEY=VALUE (the parameters of its method '" +
                       s.method + "'), not " + a.family + "." + a.key);
    }
    std::erase_if(s.method_settings, [&](const auto& kv) { return kv.first == a.key; });
    s.method_settings.emplace_back(a.key, a.value);
    try {
      experiments::make_slam_method(s.method, s.method_settings);
    } catch (const InputError& e) {
      throw InputError("--set " + text + ": " + e.what());
    }
  }
  io::OutputFolder folder(out, "slam", experiments::slam_output_files(s), {f.scenario}, "--out " + out.string());
  const experiments::SlamSetup setup = experiments::prepare_slam(s);
  folder.claim();

  int single = -1;
  for (std::size_t i = 0; i < s.robots.size(); ++i) {
    if (s.robots[i].name == s.single_robot) single = int(i);
  }
  // Jobs 0 .. runs-1 are the team runs; runs .. 2 runs-1 the single-robot runs (when asked for).
  const int total = s.runs * (single >= 0 ? 2 : 1);
  experiments::SlamCampaign campaign;
  campaign.team.resize(std::size_t(s.runs));
  if (single >= 0) campaign.alone.resize(std::size_t(s.runs));
  ProgressBar bar(!f.quiet);
  int done = 0;
  bar.update(0, total, "runs");
  core::parallel_for(
      total, f.jobs.value_or(1),
      [&](int job) {
        if (job < s.runs) {
          campaign.team[std::size_t(job)] = experiments::run_slam(setup, job, s.exchange);
        } else {
          campaign.alone[std::size_t(job - s.runs)] = experiments::run_slam(setup, job - s.runs, false, single);
        }
      },
      [&](int) { bar.update(++done, total, "runs"); });
  bar.finish();

  const auto written = experiments::write_slam_outputs(setup, campaign, out, s.paper_table);
  folder.finish(io::OutputFolder::names(written));
  if (f.quiet) {
    fmt::print("{}\n", (out / "table1.md").string());
    return 0;
  }
  fmt::print("{}", experiments::slam_table_markdown(setup, campaign, s.paper_table));
  std::string names;
  for (const auto& p : written) names += " " + p.filename().string();
  fmt::print("\nall outputs in {}/:{}\n", out.string(), names);
  return 0;
}

}  // namespace

Command add_slam_command(CLI::App& root) {
  CLI::App* app = root.add_subcommand("slam", "Reproduce a SLAM experiment: D'Alfonso et al., section 4 (Table 1) or León et al. corridor loop (Table I), with figures");
  app->footer(
      "Robots follow precomputed paths in a room, each maps it and localizes itself on its own, and robots that\n"
      "see each other exchange maps. Writes Table 1 (means and standard deviations over the runs) as table1.md and\n"
      "table1.csv, runs.csv, rendezvous.csv, and the first run's maps as map_<robot>.png (and map_<robot>_alone.png\n"
      "for the scenario's single_robot). Scenario keys: scenarios/dalfonso_3robots.yaml (commented) and README.md,\n\"Polynomial SLAM (D'Alfonso et al.)\".\n\n"
      "Methods (the scenario's `method`): " + method_names() +
      "\n  polynomial: D'Alfonso et al.'s polynomial EKF-SLAM with polynomial map exchange at rendezvous\n"
      "A method's parameters are set in the scenario (`method: {name: polynomial, order: 2}`, or the\n"
      "`polynomial:` block) or with --set method.order=2; `fleetmap plugins --family slam-method` lists them.\n\n"
      "Example: fleetmap slam --scenario scenarios/dalfonso_3robots.yaml --runs 100 --jobs 2 --out out/dalfonso\n\n"
      "Scenarios with `experiment: leon_corridor` (scenarios/leon_corridor.yaml) run León et al.'s corridor comparison\n"
      "and merging by detection instead (--runs, --jobs, --sampled-start and --exact-start do not apply);\n"
      "README.md, \"Grid SLAM and MCL (León et al.)\".\n\n"
      "Scenarios with `experiment: landmark_alignment` (scenarios/landmark_alignment.yaml) run the map-alignment paper's\n"
      "experiments: FastSLAM 2.0 landmark maps aligned by data association or inter-robot observations, Tables I-III,\n"
      "Fig. 2 and the leader/follower merges (--sampled-start and --exact-start do not apply); README.md,\n"
      "\"Landmark map alignment (map-alignment paper)\".\n\n" + slam_log_help());
  auto f = std::make_shared<SlamFlags>();
  auto* scenario = app->add_option("--scenario", f->scenario, "SLAM scenario YAML (see scenarios/dalfonso_3robots.yaml)")
                       ->check(CLI::ExistingFile);
  auto* log = app->add_option("--log", f->log.log, "A laser log (CARMEN or DP-SLAM, plain or .gz) to run one SLAM method over")
                  ->check(CLI::ExistingFile)
                  ->excludes(scenario);
  app->add_option("--method", f->log.method, "With --log: the SLAM method [default: graph-slam]")
      ->needs(log)
      ->check(one_of(experiments::log_slam_methods()));
  app->add_option("--set", f->log.set,
                  "A parameter of the method (repeat for more). With --log: localization.KEY=VALUE, e.g. --set "
                  "localization.scans_per_submap=40 (`fleetmap plugins --family localization` lists them); with a "
                  "SLAM scenario: method.KEY=VALUE, e.g. --set method.order=2 (`fleetmap plugins --family "
                  "slam-method`)")
      ->expected(1)
      ->take_all();
  app->add_option("--relations", f->log.relations,
                  "With --log: reference relations (`t1 t2 x y z roll pitch yaw`) to score the trajectory against")
      ->needs(log)
      ->check(CLI::ExistingFile);
  app->add_option("--runs", f->runs, "Number of runs [default: the scenario's runs, 100 if it has none]")
      ->check(in_range(experiments::kSlamRunsRange));
  app->add_option("--seed", f->seed, "Random seed; run k uses its own streams derived from it [default: the scenario's, 1; with --log 1]")
      ->check(seed_number());
  app->add_option("--jobs", f->jobs, "Runs computed in parallel, one thread each; results do not depend on it [default: 1]")
      ->check(in_range(sweep::kJobsRange));
  app->add_option("--out,-o", f->out,
                  "Output folder: new, empty, or of an earlier slam run (its files are replaced) "
                  "[default: out/slam_<scenario or log name>]");
  auto* sampled = app->add_flag("--sampled-start", f->sampled_start,
                                "Start each robot's estimate off its true start by a draw from P0, so that the NEES "
                                "measures consistency [default: the scenario's initial_sigma.sampled]");
  app->add_flag("--exact-start", f->exact_start,
                "Start each robot's estimate exactly at its true start, as D'Alfonso et al. do "
                "[default: the scenario's initial_sigma.sampled]")
      ->excludes(sampled);
  app->add_flag("--quiet,-q", f->quiet, "Print only the path of table1.md (with --log: of metrics.json); no progress bar");
  return {app, [f]() { return run_slam(*f); }};
}

}  // namespace fleetmap::cli
