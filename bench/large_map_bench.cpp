// Size: a 4000x4000-cell map explored by 16 robots, to completion. Results: bench/README.md, "## Size".
//
// large/office_4000/16: the built-in "office" (200x200 cells of 0.1 m) scaled up 20 times with
// nearest-neighbour sampling: 4000x4000 cells of 5 mm, the same 20 m x 20 m building, so that every
// per-cell cost (maps, waves, frontiers, exchange, coverage) is paid on 16 M cells while the run stays
// as long in metres as on the small map. 16 robots, the default scenario otherwise (directional, 4 m
// = 800 cells of range), but 2880 beams: with 360 beams, 7 cm apart at 4 m, the scans leave unseen
// spokes between beams wider than the cells and no robot finds room to move. Step limit 2000. One iteration (a run is deterministic for its seed).
// large/campus/16: the built-in "campus" (1200x1200 cells of 0.1 m, 120 m x 120 m) with 16 robots.
// Counters: steps run, steps to 99% (-1: never), final coverage, whether the run finished, and the
// process's peak resident memory so far (getrusage ru_maxrss; each case runs in its own process when
// filtered with --benchmark_filter).
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <opencv2/imgproc.hpp>

#include "maps/builtin_maps.h"
#include "io/map_image.h"
#include "io/map_io.h"
#include "sim/scenario.h"
#include "sim/simulation.h"

namespace fleetmap::sim {
namespace {

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

mapping::OccupancyGrid scaled(const std::string& name, int factor) {
  const mapping::OccupancyGrid small = maps::load_map_source(name);
  cv::Mat image;
  cv::resize(io::grid_to_image(small), image, {}, factor, factor, cv::INTER_NEAREST);
  io::MapYaml meta;
  meta.resolution = small.resolution() / factor;
  return io::grid_from_image(image, meta);
}

void run(benchmark::State& state, const mapping::OccupancyGrid& truth, int beams) {
  Scenario s;
  s.range.beams = beams;
  s.robot_count = 16;
  s.steps = 2000;
  for (auto _ : state) {
    Simulation simulation(s, truth);
    const RunResult r = simulation.run();
    state.counters["steps"] = r.steps;
    state.counters["steps_to_99"] = r.steps_to_99 ? *r.steps_to_99 : -1;
    state.counters["coverage"] = r.coverage.back();
    state.counters["finished"] = r.finished ? 1 : 0;
  }
  state.counters["peak_rss_mb"] = peak_rss_mb();
}

void BM_Office4000(benchmark::State& state) { run(state, scaled("office", 20), 2880); }
void BM_Campus(benchmark::State& state) { run(state, maps::load_map_source("campus"), 360); }

BENCHMARK(BM_Office4000)->Name("large/office_4000/16")->Iterations(1)->UseRealTime()->Unit(benchmark::kSecond);
BENCHMARK(BM_Campus)->Name("large/campus/16")->Iterations(1)->UseRealTime()->Unit(benchmark::kSecond);

}  // namespace
}  // namespace fleetmap::sim

BENCHMARK_MAIN();
