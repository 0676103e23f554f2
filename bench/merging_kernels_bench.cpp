// The two inner kernels of map merging against the OpenCV calls they replaced, on the sizes a
// merge uses: real 2-D DFTs (the overlap search's translation correlations: a few hundred per
// merge, 128 to 400 cells square) and the two nearest binary descriptors (feature matching: about
// 1400 ORB descriptors per map of 300 x 300 cells, 32 bytes each).
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include "merging/hamming.h"
#include "merging/real_dft.h"

namespace {

using namespace fleetmap;

// A map-like image: the top-left two thirds filled, the rest zero padding, as the search pads.
cv::Mat padded_image(int n) {
  cv::Mat img = cv::Mat::zeros(n, n, CV_32F);
  cv::RNG rng(1);
  rng.fill(img(cv::Rect(0, 0, 2 * n / 3, 2 * n / 3)), cv::RNG::UNIFORM, 0.0, 1.0);
  return img;
}

void dft_opencv(benchmark::State& state) {
  const int n = int(state.range(0));
  const cv::Mat img = padded_image(n);
  cv::Mat spectrum, back;
  for (auto _ : state) {
    cv::dft(img, spectrum, 0, 2 * n / 3);  // rows past the image are zero (as the search called it)
    cv::idft(spectrum, back, cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);
    benchmark::DoNotOptimize(back.data);
  }
}

void dft_fftw(benchmark::State& state) {
  const int n = int(state.range(0));
  const cv::Mat img = padded_image(n);
  merging::RealDft dft(cv::Size(n, n));
  merging::HalfSpectrum spectrum;
  cv::Mat back;
  for (auto _ : state) {
    dft.forward(img(cv::Rect(0, 0, 2 * n / 3, 2 * n / 3)), spectrum);
    dft.inverse(spectrum, back);
    benchmark::DoNotOptimize(back.data);
  }
}

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

// A forward and an inverse transform of an n x n image.
BENCHMARK(dft_opencv)->Arg(128)->Arg(160)->Arg(256)->Arg(400)->Unit(benchmark::kMicrosecond);
BENCHMARK(dft_fftw)->Arg(128)->Arg(160)->Arg(256)->Arg(400)->Unit(benchmark::kMicrosecond);
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
