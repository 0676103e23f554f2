#include "cli/sweep_flags.h"

#include <algorithm>

#include "core/format.h"
#include "core/error.h"
#include "core/suggest.h"
#include "io/file_io.h"
#include "sim/scenario.h"

namespace fleetmap::cli {

void apply_sweep_flags(sweep::Sweep& sweep, const SweepFlags& f) {
  if (f.scenario) {
    if (!io::is_regular_file(*f.scenario)) throw InputError("--scenario: no scenario file '" + *f.scenario + "'");
    sweep::use_base(sweep, sim::load_scenario(*f.scenario));
  }
  if (f.maps) sweep.maps = sweep::parse_map_list(*f.maps, "--maps");
  if (f.strategies) sweep.strategies = sweep::parse_strategy_list(*f.strategies, "--strategies");
  if (f.robots) sweep.robots = sweep::parse_team_sizes(*f.robots, "--robots");
  if (f.seeds) sweep.seeds = *f.seeds;
  if (f.first_seed) sweep.first_seed = *f.first_seed;
  if (f.steps) sweep.base.steps = *f.steps;
  if (f.localization) sweep.base.localization = *f.localization;
  if (f.merging) {
    const auto names = sim::merging_names();
    if (std::find(names.begin(), names.end(), *f.merging) == names.end()) {
      throw InputError("--merging: unknown mode '" + *f.merging + "'" + core::did_you_mean(*f.merging, names) +
                       " (valid: " + core::join(names) + ")");
    }
    sweep.base.merging = *f.merging;
  }
  if (f.comm_range) sweep.base.communication.range_m = sweep::parse_comm_range(*f.comm_range, "--comm-range");
  if (f.sensor_range) sweep.base.range.max_range_m = *f.sensor_range;
  if (f.resolution) sweep.base.map_resolution_m = *f.resolution;
  for (const auto& text : f.set) sim::set_parameter(sweep.base, text, "--set " + text);
  if (!f.vary.empty()) {
    sweep.axes.clear();
    for (const auto& text : f.vary) sweep.axes.push_back(sweep::parse_axis(text, "--vary " + text));
  }
}

sweep::Shard parse_shard(const std::string& text) {
  const auto slash = text.find('/');
  const auto number = [](const std::string& part) {
    if (part.empty() || part.size() > 6 || !std::all_of(part.begin(), part.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      return -1;
    }
    return std::stoi(part);
  };
  const int k = slash == std::string::npos ? -1 : number(text.substr(0, slash));
  const int n = slash == std::string::npos ? -1 : number(text.substr(slash + 1));
  if (k < 1 || n < 1 || k > n) {
    throw InputError("--shard '" + text + "': expected K/N with 1 <= K <= N, e.g. 2/4 (the second of four slices)");
  }
  return {k, n};
}

}  // namespace fleetmap::cli
