#include "sweep/sweep_runner.h"

#include <chrono>
#include <optional>

#include "core/error.h"
#include "core/parallel.h"
#include "core/random.h"
#include "io/file_io.h"
#include "sim/run_replay.h"
#include "sim/simulation.h"
#include "sim/world.h"
#include "sweep/sweep_report.h"

namespace fleetmap::sweep {

namespace {

const mapping::OccupancyGrid& map_of(const SweepMaps& maps, const std::string& label) {
  const auto it = maps.find(label);
  if (it == maps.end()) throw Error("sweep: map '" + label + "' was not loaded");
  return it->second;
}

}  // namespace

RunRecord run_one(const Sweep& sweep, const SweepRun& run, const mapping::OccupancyGrid& truth,
                  const std::filesystem::path& replay_dir) {
  const auto t0 = std::chrono::steady_clock::now();
  const sim::Scenario scenario = run_scenario(sweep, run);
  sim::Simulation simulation(scenario, truth);
  std::optional<sim::RunReplay> replay;
  if (scenario.html_replay && !replay_dir.empty()) replay.emplace();
  const sim::RunResult result = simulation.run({}, [&](const sim::Simulation& s) {
    if (replay) replay->add_step(s);
  });
  if (replay) io::write_file_atomic(replay_dir / replay_file_name(run_key(run)), replay->html(result, run.map));
  RunRecord record = make_record(result, sim::World(truth, {}), run.map, settings_id(sweep.base), 0.0, run.variant);
  record.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return record;
}

void check_placements(const Sweep& sweep, const SweepMaps& maps) {
  for (const auto& source : sweep.maps) {
    const std::string label = map_label(source);
    const sim::World world(map_of(maps, label), {});
    for (int robots : sweep.robots) {
      SweepRun probe{0, label, source, sweep.strategies.front(), robots, sweep.first_seed, {}, {}};
      for (const auto& axis : sweep.axes) probe.values.push_back(axis.values.front());
      const sim::Scenario s = run_scenario(sweep, probe);
      core::Random rng = core::Random(s.seed).fork(1);
      try {
        sim::place_robots(s, world, rng);
      } catch (const InputError& e) {
        throw InputError("map '" + label + "' with " + std::to_string(robots) + " robots: " + e.what());
      }
    }
  }
}

void run_sweep(const Sweep& sweep, const std::vector<SweepRun>& runs, const SweepMaps& maps,
               const SweepRunOptions& options, const std::function<void(const RunRecord&)>& on_record) {
  for (const auto& r : runs) map_of(maps, r.map);
  std::vector<RunRecord> done(runs.size());
  core::parallel_for(
      int(runs.size()), options.jobs,
      [&](int i) {
        done[std::size_t(i)] = run_one(sweep, runs[std::size_t(i)], maps.at(runs[std::size_t(i)].map), options.replay_dir);
      },
      [&](int i) {
        on_record(done[std::size_t(i)]);
        done[std::size_t(i)] = {};  // a finished run's record is not kept
      });
}

}  // namespace fleetmap::sweep
