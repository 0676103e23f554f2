#include "merging/hough_spectrum.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/angle.h"
#include "core/random.h"
#include "core/transform2.h"

namespace fleetmap::merging {
namespace {

// An L of two walls and a slanted one, as points.
std::vector<Eigen::Vector2f> shape(const core::Transform2& t) {
  std::vector<Eigen::Vector2f> pts;
  for (int i = 0; i < 80; ++i) {
    pts.push_back(t.apply(Eigen::Vector2d(i, 0)).cast<float>());
    pts.push_back(t.apply(Eigen::Vector2d(0, i * 0.6)).cast<float>());
  }
  for (int i = 0; i < 40; ++i) pts.push_back(t.apply(Eigen::Vector2d(20 + i * 0.6, 30 + i * 0.4)).cast<float>());
  return pts;
}

double angle_gap_mod_pi(double a, double b) {
  const double d = std::fmod(std::abs(a - b), std::numbers::pi);
  return std::min(d, std::numbers::pi - d);
}

TEST(HoughSpectrum, IsNormalisedAndPeaksAtTheWallNormals) {
  const auto hs = hough_spectrum(shape(core::Transform2::identity()), 180);
  ASSERT_EQ(hs.size(), 180u);
  double mean = 0.0, norm = 0.0;
  for (double v : hs) mean += v, norm += v * v;
  EXPECT_NEAR(mean, 0.0, 1e-9);
  EXPECT_NEAR(norm, 1.0, 1e-9);
  // Walls along x and y: normals at 90 and 0 degrees are the two highest bins.
  std::vector<int> order(180);
  for (int i = 0; i < 180; ++i) order[std::size_t(i)] = i;
  std::sort(order.begin(), order.end(), [&](int x, int y) { return hs[std::size_t(x)] > hs[std::size_t(y)]; });
  EXPECT_TRUE((order[0] == 0 && order[1] == 90) || (order[0] == 90 && order[1] == 0)) << order[0] << " " << order[1];
}

TEST(HoughSpectrum, CrossCorrelationRecoversTheRotationModuloPi) {
  core::Random random(5);
  for (int trial = 0; trial < 20; ++trial) {
    const double theta = random.uniform(-std::numbers::pi, std::numbers::pi);
    const core::Transform2 turn(random.uniform(-50, 50), random.uniform(-50, 50), theta);
    const auto a = hough_spectrum(shape(turn), 360);
    const auto b = hough_spectrum(shape(core::Transform2::identity()), 360);
    const auto peaks = correlation_peaks(circular_cross_correlation(a, b), 1, 6);
    ASSERT_EQ(peaks.size(), 1u);
    // One bin is half a degree; the peak is refined to a fraction of that.
    EXPECT_LT(core::rad2deg(angle_gap_mod_pi(peaks[0], theta)), 0.5) << core::rad2deg(theta);
  }
}

TEST(HoughSpectrum, PeaksAreSeparatedAndSorted) {
  std::vector<double> cc(36, 0.0);
  cc[3] = 5.0, cc[4] = 4.9, cc[20] = 3.0, cc[30] = 1.0;
  const auto peaks = correlation_peaks(cc, 3, 3);
  ASSERT_EQ(peaks.size(), 3u);
  EXPECT_NEAR(peaks[0], (3.0 + 0.5 * (0.0 - 4.9) / (0.0 - 10.0 + 4.9)) * std::numbers::pi / 36, 1e-9);
  EXPECT_NEAR(peaks[1], 20 * std::numbers::pi / 36, 1e-9);
  EXPECT_NEAR(peaks[2], 30 * std::numbers::pi / 36, 1e-9);
}

}  // namespace
}  // namespace fleetmap::merging
