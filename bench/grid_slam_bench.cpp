// Grid SLAM and MCL (León et al.): the time of one scan match (`scan-matching`'s update), of one
// `rbpf` step (predict + update) with 30 particles on a 1000 x 1000 map and the memory its
// particle maps hold, and of one `mcl` update. Results: bench/README.md, "## Grid SLAM and MCL".
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "mapping/range_scan.h"
#include "localization/cow_grid.h"
#include "localization/localizer.h"
#include "localization/rbpf_localizer.h"
#include "localization/scan_matcher.h"
#include "mapping/ray_cast.h"

namespace fleetmap::localization {
namespace {

// A 20 m x 14 m room with a few pillars, drawn on a grid of `cells` x `cells` at 0.05 m.
mapping::OccupancyGrid room(int cells) {
  mapping::OccupancyGrid g(core::GridGeometry(0.05, cells, cells));
  for (int y = 0; y < std::min(cells, 300); ++y) {
    for (int x = 0; x < std::min(cells, 420); ++x) {
      const Eigen::Vector2d p = g.geometry().cell_center({x, y});
      bool wall = p.x() < 0.2 || p.y() < 0.2 || p.x() > 20.8 || p.y() > 14.8;
      for (const Eigen::Vector2d& c : {Eigen::Vector2d(5, 4), Eigen::Vector2d(12, 9), Eigen::Vector2d(16, 3)}) {
        wall = wall || (p - c).cwiseAbs().maxCoeff() < 0.4;
      }
      g.set_state({x, y}, wall ? mapping::CellState::Occupied : mapping::CellState::Free);
    }
  }
  return g;
}

RangeScan scan_at(const mapping::OccupancyGrid& truth, const core::Pose2& pose) {
  RangeScan s;
  s.max_range = 8.0;
  for (int b = 0; b < 360; ++b) {
    const double a = -std::numbers::pi + 2.0 * std::numbers::pi * b / 360.0;
    s.angles.push_back(a);
    s.ranges.push_back(mapping::cast_ray(truth, pose.position(), pose.theta + a, s.max_range));
  }
  return s;
}

// One scan matched to a map built from five earlier scans, from a guess 0.1 m and 3 degrees off:
// the likelihood field of the window in reach, the correlative search and the refinement.
void BM_ScanMatchPerScan(benchmark::State& state) {
  const auto truth = room(420);
  CowGrid map(truth.geometry());
  for (double x : {4.0, 6.0, 8.0, 10.0, 12.0}) mapping::insert_scan(map, {x, 7.0, 0.0}, scan_at(truth, {x, 7.0, 0.0}));
  const core::Pose2 at(9.0, 7.2, 0.1);
  const RangeScan scan = scan_at(truth, at);
  LocalizerOptions lo;
  lo.process_noise_xy = 0.05;
  lo.process_noise_theta = 0.03;
  const ScanMatcherOptions o = scan_matcher_options(lo, scan.max_range, truth.resolution());
  for (auto _ : state) {
    const ScanMatch m = match_scan_to_grid(map, scan, {at.x + 0.1, at.y, at.theta + 0.05}, o);
    benchmark::DoNotOptimize(m.pose);
  }
}
BENCHMARK(BM_ScanMatchPerScan)->Unit(benchmark::kMillisecond);

// `rbpf` with 30 particles (or the argument) on a 1000 x 1000 map: one predict + update_scan per
// iteration while driving through the room; counters: the particle maps' memory (shared tiles
// counted once) against dense copies.
void BM_RbpfStep(benchmark::State& state) {
  const auto truth = room(1000);
  mapping::OccupancyGrid own(truth.geometry());
  LocalizerContext c;
  c.initial_pose = {3.0, 7.0, 0.0};
  c.options.process_noise_xy = 0.02;
  c.options.process_noise_theta = 0.01;
  c.params = localizer_options("rbpf", {{"particles", std::to_string(state.range(0))}});
  c.seed = 1;
  RbpfLocalizer pf(c);
  core::Pose2 truth_pose = c.initial_pose;
  pf.update_scan(scan_at(truth, truth_pose), own);
  int k = 0;
  for (auto _ : state) {
    state.PauseTiming();
    // Back and forth along the room, turning at its ends.
    const Odometry u{0.2, (k++ / 40) % 2 == 0 ? 0.0 : std::numbers::pi / 40.0, 1.0};
    truth_pose = integrate_motion(truth_pose, u);
    const RangeScan scan = scan_at(truth, truth_pose);
    state.ResumeTiming();
    pf.predict(u);
    pf.update_scan(scan, own);
  }
  const auto m = pf.memory();
  state.counters["map_MB_shared"] = double(m.shared_bytes) / 1e6;
  state.counters["map_MB_dense"] = double(m.unshared_bytes) / 1e6;
  state.counters["resamplings"] = pf.resamplings();
}
BENCHMARK(BM_RbpfStep)->Arg(30)->Unit(benchmark::kMillisecond)->Iterations(60);

// `mcl` with 2000 particles spread over the room (global localization): one update_scan.
void BM_MclUpdate(benchmark::State& state) {
  const auto truth = std::make_shared<const mapping::OccupancyGrid>(room(420));
  LocalizerContext c;
  c.known_map = truth;
  c.global_localization = true;
  c.params = localizer_options("mcl", {{"particles", std::to_string(state.range(0))}});
  c.seed = 1;
  auto mcl = make_localizer("mcl", c);
  const RangeScan scan = scan_at(*truth, {9.0, 7.2, 0.1});
  for (auto _ : state) mcl->update_scan(scan, *truth);
}
BENCHMARK(BM_MclUpdate)->Arg(2000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace fleetmap::localization

BENCHMARK_MAIN();
