#pragma once
// Runs a sweep's runs on a pool of threads. Every run is independent: its own simulation, seeded by
// its scenario, on its own copy of the map, so a run gives the same record (but its wall time)
// whatever the number of threads and whichever thread runs it.
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "mapping/occupancy_grid.h"
#include "sweep/sweep.h"
#include "sweep/sweep_results.h"

namespace fleetmap::sweep {

// Map label -> ground-truth grid, for every map of the sweep.
using SweepMaps = std::map<std::string, mapping::OccupancyGrid>;

// One run: simulate, then measure (metrics.json's numbers, the lower bound, efficiency, wall time).
// When the sweep's scenario asks for replays (outputs: {html: true}) and `replay_dir` is given, the
// run's replay page is written there too (replay_file_name).
RunRecord run_one(const Sweep& sweep, const SweepRun& run, const mapping::OccupancyGrid& truth,
                  const std::filesystem::path& replay_dir = {});

// Places every team size of the sweep on every map (with the first seed) so a team that does not
// fit is refused before any run starts. Throws InputError naming the map and the team size.
void check_placements(const Sweep& sweep, const SweepMaps& maps);

struct SweepRunOptions {
  int jobs = 1;  // threads; each takes the next run in order
  std::filesystem::path replay_dir;  // where run_one writes replays, when the sweep asks for them
};

// Runs `runs` and calls `on_record` once per finished run, one call at a time, in completion order.
// When a run or `on_record` throws, no further run starts, the runs under way finish (their records
// are still passed on), and the first exception is rethrown.
void run_sweep(const Sweep& sweep, const std::vector<SweepRun>& runs, const SweepMaps& maps,
               const SweepRunOptions& options, const std::function<void(const RunRecord&)>& on_record);

}  // namespace fleetmap::sweep
