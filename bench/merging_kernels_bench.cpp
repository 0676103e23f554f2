// Inner kernels of map merging on the sizes a merge uses: the two nearest binary descriptors
// against the OpenCV call they replaced (feature matching: about 1400 ORB descriptors per map of
// 300 x 300 cells, 32 bytes each), and fusing two maps of n x n cells, the second turned by 30
// degrees (every cell of the fused map looks up its cell in each input: `fleetmap merge`'s last
// step), and preparing one map of n x n cells for the comparisons (merging::PreparedGrid: masks,
// seams, standing obstacles, the pyramid, wall distances; every merge prepares its two maps).
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include "core/angle.h"
#include "merging/fusion.h"
#include "merging/hamming.h"
#include "merging/prepared_grid.h"

namespace {

using namespace fleetmap;

cv::Mat descriptors(int rows, std::uint64_t seed) {
  cv::Mat d(rows, 32, CV_8U);
  cv::RNG rng(seed);
  rng.fill(d, cv::RNG::UNIFORM, 0, 256);
  return d;
}

void nearest_two_opencv(benchmark::State& state) {
  const cv::Mat q = descriptors(int(state.range(0)), 1), t = descriptors(int(state.range(0)), 2);
  for (auto _ : state) {
    std::vector<std::vector<cv::DMatch>> knn;
    cv::BFMatcher(cv::NORM_HAMMING).knnMatch(q, t, knn, 2);
    benchmark::DoNotOptimize(knn.data());
  }
}

void nearest_two_popcount(benchmark::State& state) {
  const cv::Mat q = descriptors(int(state.range(0)), 1), t = descriptors(int(state.range(0)), 2);
  for (auto _ : state) benchmark::DoNotOptimize(merging::nearest_two_hamming(q, t).data());
}

// An n x n map: free, with a wall every 20 cells and the rest of every tenth row unknown.
mapping::OccupancyGrid room_map(int n) {
  mapping::OccupancyGrid g(core::GridGeometry(0.05, n, n, core::Pose2()));
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      if (x % 20 == 0) g.set_log_odds({x, y}, g.max_log_odds());
      else if (y % 10 != 0) g.set_log_odds({x, y}, g.min_log_odds());
    }
  }
  return g;
}

void fuse_pair_turned(benchmark::State& state) {
  const int n = int(state.range(0));
  const mapping::OccupancyGrid a = room_map(n), b = room_map(n);
  const core::Transform2 b_to_a(0.3 * n, 0.1 * n, core::deg2rad(30.0));
  for (auto _ : state) benchmark::DoNotOptimize(merging::fuse_pair(a, b, b_to_a).conflict_cells);
}

void prepare_grid(benchmark::State& state) {
  const mapping::OccupancyGrid g = room_map(int(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(merging::PreparedGrid(g).walls().size());
}

}  // namespace

// n query descriptors against n.
BENCHMARK(nearest_two_opencv)->Arg(1400)->Unit(benchmark::kMillisecond);
BENCHMARK(nearest_two_popcount)->Arg(1400)->Unit(benchmark::kMillisecond);
// Two maps of n x n cells.
BENCHMARK(fuse_pair_turned)->Arg(300)->Arg(1000)->Unit(benchmark::kMillisecond);
// One map of n x n cells.
BENCHMARK(prepare_grid)->Arg(300)->Arg(1000)->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
  cv::setNumThreads(1);  // one core, as the merges are timed
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
