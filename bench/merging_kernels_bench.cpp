// An inner kernel of map merging against the OpenCV call it replaced, on the sizes a merge uses:
// the two nearest binary descriptors (feature matching: about 1400 ORB descriptors per map of
// 300 x 300 cells, 32 bytes each).
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include "merging/hamming.h"

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

}  // namespace

// n query descriptors against n.
BENCHMARK(nearest_two_opencv)->Arg(1400)->Unit(benchmark::kMillisecond);
BENCHMARK(nearest_two_popcount)->Arg(1400)->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
  cv::setNumThreads(1);  // one core, as the merges are timed
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
