#pragma once
// A benchmark sweep: every combination of map x strategy x team size x seed, each run from one base
// scenario with those four replaced. Defined by flags or a YAML sweep file (every key checked,
// errors name the file, line and key); listed in a fixed order, and cut into shards for clusters.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/range.h"
#include "exploration/strategy.h"
#include "sim/scenario.h"

namespace fleetmap::sweep {

// Seeds per combination, and parallel runs, that a sweep accepts (the file and the flags alike).
inline constexpr core::Range kSeedCountRange{1, 1'000'000, true};
inline constexpr core::Range kJobsRange{1, 1024, true};

// A further axis of a sweep: one setting of the scenario and the values it takes. The key is a
// scenario file's key, dotted ("sensors.range.beams", "communication.range"), or a short name
// (beams, sensor_range, comm_range, localization, merging, path_planner, steps, noise_position).
struct SweepAxis {
  std::string name;                 // as given: results name the variant by it
  std::string scenario_key;         // the dotted key in a scenario file
  std::vector<std::string> values;  // as written in a scenario file
};

struct Sweep {
  // Built-in map names or map files (PNG/PGM/map_server YAML); a run's `map` is the label.
  std::vector<std::string> maps = {"empty", "unstructured", "office", "corridor"};
  std::vector<std::string> strategies = exploration::strategy_names();
  std::vector<int> robots = {1, 2, 4, 9};
  std::vector<SweepAxis> axes;    // more axes: every combination of their values (first slowest)
  int seeds = 20;                 // seeds first_seed, first_seed + 1, ...
  std::uint64_t first_seed = 1;
  // Everything else: steps, sensors, localization, communication, ... Its map, strategy, robot
  // count and seed are replaced per run; listed starts become a cluster of the run's team size.
  sim::Scenario base;
};

// The name a map goes by in results: a built-in name as is, a file by its stem ("maps/lab.png": "lab").
std::string map_label(const std::string& source);

// "a,b,c" lists; `what` names the input in errors ("--maps", "sweep.yaml:3: key 'maps'").
std::vector<std::string> parse_map_list(const std::string& text, const std::string& what);
// Strategy names or "all"; unknown names are errors listing the valid ones.
std::vector<std::string> parse_strategy_list(const std::string& text, const std::string& what);
// Team sizes: "1,2,4,9" or ranges "1-9"; each 1..64.
std::vector<int> parse_team_sizes(const std::string& text, const std::string& what);
// Metres >= 0, or "inf".
double parse_comm_range(const std::string& text, const std::string& what);

// An axis from "key=v1,v2,..." (`what` names the input in errors). The key may not be one of the
// sweep's own axes (map, seed, robots, strategy); values are distinct, without spaces or quotes.
SweepAxis parse_axis(const std::string& text, const std::string& what);
SweepAxis make_axis(const std::string& key, const std::vector<std::string>& values, const std::string& what);

// Parses a sweep file. Keys: maps, strategies, robots, seeds, first_seed, scenario (a scenario file,
// relative to the sweep file), steps, localization, merging, comm_range, sensor_range, and vary (a
// mapping from setting to its list of values, each an axis). Relative map files are relative to
// `base_dir` (the sweep file's folder).
Sweep parse_sweep(const std::string& text, const std::string& source, const std::filesystem::path& base_dir);
Sweep load_sweep(const std::filesystem::path& path);
// The base scenario of a sweep: listed starts become a cluster of each run's team size.
void use_base(Sweep& sweep, sim::Scenario base);
// Non-empty lists without repeats, distinct map labels, seeds >= 1, and a valid base scenario.
void validate_sweep(const Sweep& sweep);
// The sweep file that defines `sweep` with its base scenario in `scenario_file` (scenario_to_yaml;
// "" for none: then only the base settings a sweep file has keys for are kept);
// map files are written with absolute paths. Two sweeps are the same sweep when these texts are.
std::string sweep_to_yaml(const Sweep& sweep, const std::string& scenario_file);

struct SweepRun {
  std::size_t index = 0;   // place in the sweep's order
  std::string map;         // label
  std::string map_source;  // as loaded
  std::string strategy;
  int robots = 1;
  std::uint64_t seed = 1;
  std::vector<std::string> values;  // one per axis of the sweep
  std::string variant;              // "name=value name=value", empty without axes
};

// "beams=90 comm_range=5": the variant label of one value per axis.
std::string variant_label(const std::vector<SweepAxis>& axes, const std::vector<std::string>& values);
// The value `name` takes in a variant label, or nullopt.
std::optional<std::string> variant_value(const std::string& variant, const std::string& name);
// The label without `name=...`.
std::string variant_without(const std::string& variant, const std::string& name);
// The setting names of a variant label, in order ("beams", "comm_range").
std::vector<std::string> variant_names(const std::string& variant);

// Every run, in the fixed order map, strategy, team size, axes, seed (seed varies fastest).
std::vector<SweepRun> sweep_runs(const Sweep& sweep);
// The scenario of one run: the base with each axis's setting, then map, strategy, robot count and
// seed replaced. Throws InputError naming the axis and value when the scenario refuses a value.
sim::Scenario run_scenario(const Sweep& sweep, const SweepRun& run);

// K-th of N slices (1 <= K <= N): runs whose index % N == K - 1, so every shard gets a similar mix.
struct Shard {
  int index = 1;
  int count = 1;
};
std::vector<SweepRun> shard_runs(const std::vector<SweepRun>& runs, const Shard& shard);

// 16 hex digits identifying every setting of the base but the map, strategy, robot count and seed:
// runs with equal ids were run alike and may share one results table.
std::string settings_id(const sim::Scenario& base);

}  // namespace fleetmap::sweep
