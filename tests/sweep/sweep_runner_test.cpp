#include "sweep/sweep_runner.h"

#include <gtest/gtest.h>

#include <map>

#include "core/error.h"
#include "tests/sim/sim_test_maps.h"
#include "tests/test_support.h"

namespace fleetmap::sweep {
namespace {

using fleetmap::testing::expect_input_error;

// Two small rooms as the sweep's maps; each run is short.
struct TinySweep {
  Sweep sweep;
  SweepMaps maps;
  TinySweep() {
    core::Random rng(3);
    maps.emplace("roomA", sim::testing::random_room(rng, 60, 40, 5));
    maps.emplace("roomB", sim::testing::walled_room(50, 50));
    sweep.maps = {"roomA", "roomB"};
    sweep.strategies = {"uncoordinated", "coordinated"};
    sweep.robots = {1, 2};
    sweep.seeds = 2;
    sweep.base.steps = 120;
  }
};

SweepRunOptions jobs_only(int jobs) {
  SweepRunOptions options;
  options.jobs = jobs;
  return options;
}

std::map<RunKey, std::string> run_all(const TinySweep& t, int jobs, int* calls = nullptr) {
  std::map<RunKey, std::string> rows;
  run_sweep(t.sweep, sweep_runs(t.sweep), t.maps, jobs_only(jobs), [&](const RunRecord& r) {
    rows[r.key] = record_without_wall_time(r);
    if (calls) ++*calls;
  });
  return rows;
}

TEST(SweepRunner, SameRecordsWhateverTheNumberOfThreads) {
  const TinySweep t;
  int calls = 0;
  const auto one = run_all(t, 1, &calls);
  EXPECT_EQ(calls, 16);
  ASSERT_EQ(one.size(), 16u);
  const auto two = run_all(t, 2);
  EXPECT_EQ(one, two);
  // Different seeds are different runs.
  EXPECT_NE(one.at({"roomA", "coordinated", 2, 1, ""}), one.at({"roomA", "coordinated", 2, 2, ""}));
}

TEST(SweepRunner, RunOneIsTheRunOfItsScenario) {
  const TinySweep t;
  const auto runs = sweep_runs(t.sweep);
  const SweepRun& run = runs[5];
  const RunRecord r = run_one(t.sweep, run, t.maps.at(run.map));
  const sim::RunResult direct = sim::Simulation(run_scenario(t.sweep, run), t.maps.at(run.map)).run();
  EXPECT_EQ(r.key, (RunKey{run.map, run.strategy, run.robots, run.seed, ""}));
  EXPECT_EQ(r.steps, direct.steps);
  EXPECT_EQ(r.steps_to_95, direct.steps_to_95);
  EXPECT_EQ(r.bytes_sent, direct.bytes_sent);
  EXPECT_EQ(r.settings, settings_id(t.sweep.base));
  EXPECT_GT(r.wall_time_s, 0.0);
}

TEST(SweepRunner, ATeamThatDoesNotFitIsRefusedBeforeAnyRun) {
  TinySweep t;
  t.maps["roomB"] = sim::testing::walled_room(12, 12);
  t.sweep.robots = {1, 9};
  expect_input_error([&] { check_placements(t.sweep, t.maps); }, {"map 'roomB'", "9 robots", "fit"});
}

TEST(SweepRunner, AFailingRunStopsTheSweepAndIsRethrown) {
  TinySweep t;
  t.maps["roomB"] = sim::testing::walled_room(12, 12);
  t.sweep.robots = {9};
  t.sweep.maps = {"roomB", "roomA"};
  int records = 0;
  EXPECT_THROW(run_sweep(t.sweep, sweep_runs(t.sweep), t.maps, jobs_only(2), [&](const RunRecord&) { ++records; }), InputError);
  EXPECT_EQ(records, 0);  // the runs on roomA, after the failing ones, never started
  // An error in the callback (e.g. a full disk) stops the sweep too.
  t.sweep.maps = {"roomA"};
  EXPECT_THROW(run_sweep(t.sweep, sweep_runs(t.sweep), t.maps, jobs_only(2), [](const RunRecord&) { throw Error("disk full"); }),
               Error);
}

}  // namespace
}  // namespace fleetmap::sweep
