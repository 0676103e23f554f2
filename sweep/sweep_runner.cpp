#include "sweep/sweep_runner.h"

#include <atomic>
#include <chrono>
#include <exception>
#include <mutex>
#include <thread>

#include "core/error.h"
#include "core/random.h"
#include "sim/simulation.h"
#include "sim/world.h"

namespace fleetmap::sweep {

namespace {

const mapping::OccupancyGrid& map_of(const SweepMaps& maps, const std::string& label) {
  const auto it = maps.find(label);
  if (it == maps.end()) throw Error("sweep: map '" + label + "' was not loaded");
  return it->second;
}

}  // namespace

RunRecord run_one(const Sweep& sweep, const SweepRun& run, const mapping::OccupancyGrid& truth) {
  const auto t0 = std::chrono::steady_clock::now();
  sim::Simulation simulation(run_scenario(sweep, run), truth);
  const sim::RunResult result = simulation.run();
  RunRecord record = make_record(result, sim::World(truth, {}), run.map, settings_id(sweep.base), 0.0);
  record.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return record;
}

void check_placements(const Sweep& sweep, const SweepMaps& maps) {
  for (const auto& source : sweep.maps) {
    const std::string label = map_label(source);
    const sim::World world(map_of(maps, label), {});
    for (int robots : sweep.robots) {
      const SweepRun probe{0, label, source, sweep.strategies.front(), robots, sweep.first_seed};
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
  std::atomic<std::size_t> next{0};
  std::atomic<bool> stop{false};
  std::mutex mutex;  // guards on_record and `failure`
  std::exception_ptr failure;
  const auto worker = [&]() {
    while (!stop) {
      const std::size_t i = next++;
      if (i >= runs.size()) return;
      try {
        const RunRecord record = run_one(sweep, runs[i], maps.at(runs[i].map));
        const std::lock_guard lock(mutex);
        on_record(record);
      } catch (...) {
        const std::lock_guard lock(mutex);
        if (!failure) failure = std::current_exception();
        stop = true;
      }
    }
  };
  const int jobs = std::max(1, std::min<int>(options.jobs, int(runs.size())));
  {
    std::vector<std::jthread> threads;
    for (int j = 1; j < jobs; ++j) threads.emplace_back(worker);
    worker();
  }
  if (failure) std::rethrow_exception(failure);
}

}  // namespace fleetmap::sweep
