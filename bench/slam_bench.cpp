// D'Alfonso et al.'s polynomial EKF-SLAM: time per step per robot (predict, extraction and association,
// update, received maps), on one run of scenarios/dalfonso_3robots.yaml (3 robots, 200 steps, map
// exchange at rendezvous), and on a single robot's step alone. Results: bench/README.md,
// "## Polynomial SLAM".
#include <benchmark/benchmark.h>

#include <string>

#include "experiments/slam_experiment.h"
#include "experiments/slam_scenario.h"

namespace fleetmap::experiments {
namespace {

const SlamSetup& dalfonso() {
  static const SlamSetup kSetup =
      prepare_slam(load_slam_scenario(std::string(FLEETMAP_SOURCE_DIR) + "/scenarios/dalfonso_3robots.yaml"));
  return kSetup;
}

// One whole run; the counters are per robot and step, and the run's mean nu and mu beside them.
void BM_PolynomialSlamRun(benchmark::State& state) {
  const SlamSetup& setup = dalfonso();
  const bool exchange = state.range(0) != 0;
  int run = 0;
  double tau = 0.0, nu = 0.0, mu = 0.0;
  long robot_steps = 0;
  for (auto _ : state) {
    const SlamRunResult r = run_slam(setup, run++, exchange);
    for (const auto& robot : r.robots) {
      tau += robot.tau_s * double(robot.truth.size());
      nu += robot.mapping.nu;
      mu += robot.localization.dalfonso_mu;
      robot_steps += long(robot.truth.size());
    }
    benchmark::DoNotOptimize(r);
  }
  const double robots = double(setup.scenario.robots.size()) * double(state.iterations());
  state.counters["slam_ms_per_robot_step"] = 1e3 * tau / double(robot_steps);
  state.counters["nu_m"] = nu / robots;
  state.counters["mu"] = mu / robots;
}
BENCHMARK(BM_PolynomialSlamRun)->ArgName("exchange")->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->Iterations(5);

}  // namespace
}  // namespace fleetmap::experiments

BENCHMARK_MAIN();
