// `fleetmap explore`: one exploration run, from flags or a scenario file, with its outputs.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>

#include "cli/command.h"
#include "cli/progress.h"
#include "core/error.h"
#include "exploration/strategy.h"
#include "localization/localizer.h"
#include "maps/builtin_maps.h"
#include "sim/run_output.h"
#include "sim/scenario.h"
#include "sim/simulation.h"

namespace fleetmap::cli {

namespace fs = std::filesystem;

namespace {

struct ExploreFlags {
  std::string scenario;
  std::optional<std::string> map, strategy, localization, comm_range;
  std::optional<int> robots, steps, beams;
  std::optional<std::uint64_t> seed;
  std::optional<double> sensor_range;
  std::string out;
  bool animate = false;
  bool quiet = false;
  long long max_cells = 64'000'000;
};

double parse_range(const std::string& text) {
  if (text == "inf" || text == "infinite" || text == "unlimited") return std::numeric_limits<double>::infinity();
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size() && v >= 0.0 && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  throw InputError("--comm-range: expected metres >= 0 or 'inf', got '" + text + "'");
}

// A scenario map given as a relative path is relative to the scenario file.
std::string resolve_map(const sim::Scenario& s) {
  if (maps::is_builtin_map(s.map) && !fs::exists(s.map)) return s.map;
  const fs::path p = s.map;
  if (p.is_relative() && !s.base_dir.empty() && fs::exists(s.base_dir / p)) return (s.base_dir / p).string();
  return s.map;
}

int run_explore(const ExploreFlags& f) {
  sim::Scenario s;
  if (!f.scenario.empty()) s = sim::load_scenario(f.scenario);
  if (f.map) s.map = *f.map, s.base_dir.clear();
  if (f.robots) {
    s.robot_count = *f.robots;
    if (s.placement == sim::Placement::List) s.placement = sim::Placement::Cluster, s.starts.clear();
  }
  if (f.strategy) s.exploration.strategy = *f.strategy;
  if (f.localization) s.localization = *f.localization;
  if (f.comm_range) s.communication.range_m = parse_range(*f.comm_range);
  if (f.steps) s.steps = *f.steps;
  if (f.seed) s.seed = *f.seed;
  if (f.sensor_range) s.range.max_range_m = *f.sensor_range;
  if (f.beams) s.range.beams = *f.beams, s.range.angles_rad.clear();
  sim::validate_scenario(s);

  mapping::MapLoadOptions load;
  load.max_cells = f.max_cells;
  const std::string map_source = resolve_map(s);
  auto truth = maps::load_map_source(map_source, load);
  const std::string label = maps::is_builtin_map(s.map) ? s.map : fs::path(s.map).stem().string();
  const fs::path out = f.out.empty() ? fs::path("out") / label : fs::path(f.out);

  sim::Simulation simulation(s, std::move(truth));
  ProgressBar bar(!f.quiet);
  std::unique_ptr<sim::RunVideo> video;
  if (f.animate) video = std::make_unique<sim::RunVideo>(out / "run.mp4");
  const sim::RunResult result = simulation.run(
      [&](int step, int limit, double coverage) { bar.update(step, limit, "coverage " + format_percent(coverage)); },
      [&](const sim::Simulation& sim) {
        if (video) video->add_frame(sim, label);
      });
  bar.finish();

  auto written = sim::write_run_outputs(result, label, out);
  if (video) {
    video->finish();
    written.push_back(out / "run.mp4");
  }
  if (f.quiet) {
    std::printf("%s\n", (out / "merged.png").c_str());
    return 0;
  }
  const auto& sc = result.scenario;
  double distance = 0.0;
  for (const auto& t : result.robots) distance += t.distance_m;
  const auto step_text = [](const std::optional<int>& v) { return v ? std::to_string(*v) : std::string("not reached"); };
  char range[64];
  if (std::isinf(sc.communication.range_m)) std::snprintf(range, sizeof range, "unlimited");
  else if (sc.communication.range_m == 0.0) std::snprintf(range, sizeof range, "only at rendezvous");
  else std::snprintf(range, sizeof range, "%g m", sc.communication.range_m);
  std::printf("%s: %d robots, strategy %s, localization %s, communication %s, seed %llu\n", label.c_str(),
              sc.robot_count, sc.exploration.strategy.c_str(), sc.localization.c_str(), range,
              static_cast<unsigned long long>(sc.seed));
  std::printf("explored %s of the reachable free space in %d steps (%s); 95%% at step %s, 99%% at step %s\n",
              format_percent(result.coverage.back()).c_str(), result.steps,
              result.finished ? "no reachable frontier left" : "step limit reached", step_text(result.steps_to_95).c_str(),
              step_text(result.steps_to_99).c_str());
  std::printf("travelled %.1f m in all, redundancy %.2f, %lld bytes sent in %d meetings, %.2f s\n", distance,
              result.redundancy, static_cast<long long>(result.bytes_sent), result.meetings, result.timing.total);
  std::printf("merged map: %s\n", (out / "merged.png").c_str());
  std::printf("all outputs in %s/:", out.c_str());
  for (const auto& p : written) std::printf(" %s", p.filename().c_str());
  std::printf("\n");
  return 0;
}

}  // namespace

Command add_explore_command(CLI::App& root) {
  CLI::App* app = root.add_subcommand(
      "explore",
      "Explore a map with a team of simulated robots; writes the merged map, each robot's map, metrics and map files.\n\n"
      "Strategies (--strategy):\n" +
          exploration::strategy_help() + "\nLocalization (--localization):\n" + localization::localizer_help() +
          "\nFlags override the scenario file; without one, the defaults below apply.");
  auto f = std::make_shared<ExploreFlags>();
  app->add_option("--scenario", f->scenario, "Scenario YAML file (see scenarios/); flags below override it")
      ->check(CLI::ExistingFile);
  app->add_option("--map", f->map, "Built-in map name, image or map_server YAML [default: office]");
  app->add_option("--robots", f->robots, "Number of robots, placed together near the map centre [default: 4]")
      ->check(CLI::Range(1, 64));
  app->add_option("--strategy", f->strategy, "Coordination strategy [default: directional]");
  app->add_option("--localization", f->localization, "How robots know their pose [default: ideal]");
  app->add_option("--comm-range", f->comm_range,
                  "Communication range in metres; 0 = only when robots see each other; inf = always [default: inf]");
  app->add_option("--steps", f->steps, "Step limit [default: 2000]")->check(CLI::PositiveNumber);
  app->add_option("--seed", f->seed, "Random seed: the same seed gives the same run [default: 1]");
  app->add_option("--sensor-range", f->sensor_range, "Laser range in metres [default: 4]")->check(CLI::PositiveNumber);
  app->add_option("--beams", f->beams, "Laser beams over 360 degrees [default: 360]")->check(CLI::PositiveNumber);
  app->add_option("--out", f->out, "Output folder, created if missing [default: out/<map>]");
  app->add_flag("--animate", f->animate, "Also write run.mp4, a frame per step");
  app->add_flag("--quiet,-q", f->quiet, "Print only the merged map's path; no progress bar");
  app->add_option("--max-cells", f->max_cells, "Refuse maps with more cells than this")->capture_default_str()->check(CLI::PositiveNumber);
  return {app, [f]() { return run_explore(*f); }};
}

}  // namespace fleetmap::cli
