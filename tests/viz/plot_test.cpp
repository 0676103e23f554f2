#include "viz/plot.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <cmath>

namespace fleetmap::viz {
namespace {

int pixels_of(const cv::Mat& img, const Color& c) {
  cv::Mat mask;
  cv::inRange(img, cv::Scalar(c.b, c.g, c.r), cv::Scalar(c.b, c.g, c.r), mask);
  return cv::countNonZero(mask);
}

TEST(Plot, NiceTicks) {
  EXPECT_EQ(nice_ticks(0, 100), (std::vector<double>{0, 20, 40, 60, 80, 100}));
  const auto fifths = nice_ticks(0, 1, 5);
  ASSERT_EQ(fifths.size(), 6u);
  for (std::size_t i = 0; i < fifths.size(); ++i) EXPECT_NEAR(fifths[i], 0.2 * double(i), 1e-12);
  const auto t = nice_ticks(3, 1234);
  EXPECT_EQ(t, (std::vector<double>{200, 400, 600, 800, 1000, 1200}));
  EXPECT_EQ(nice_ticks(5, 5), (std::vector<double>{5}));
  EXPECT_TRUE(nice_ticks(0, NAN).empty());
}

TEST(Plot, LinePlotDrawsSeriesBandsAndLegend) {
  LinePlot p;
  p.title = "coverage";
  p.x.label = "step";
  p.y.label = "percent";
  const Color blue{31, 119, 180}, orange{255, 127, 14};
  for (const Color& c : {blue, orange}) {
    PlotSeries s;
    s.label = c == blue ? "first" : "second";
    s.color = c;
    for (int i = 0; i <= 50; ++i) {
      s.x.push_back(i);
      s.y.push_back(c == blue ? i : 50 - i);
      s.y_low.push_back(s.y.back() - 5);
      s.y_high.push_back(s.y.back() + 5);
    }
    p.series.push_back(s);
  }
  const cv::Mat img = draw_line_plot(p, {700, 450});
  ASSERT_EQ(img.type(), CV_8UC3);
  EXPECT_EQ(img.cols, 700);
  EXPECT_EQ(img.rows, 450);
  EXPECT_GT(pixels_of(img, blue), 100);
  EXPECT_GT(pixels_of(img, orange), 100);
  // The bands are translucent: light tints of the colours, neither white nor the full colour.
  cv::Mat tint;
  cv::inRange(img, cv::Scalar(220, 200, 170), cv::Scalar(245, 235, 215), tint);
  EXPECT_GT(cv::countNonZero(tint), 500);
  // A NaN leaves a gap instead of a line to nowhere.
  p.series[0].y[25] = NAN;
  EXPECT_FALSE(draw_line_plot(p).empty());
}

TEST(Plot, BarChartAndTiles) {
  BarChart b;
  b.title = "efficiency";
  b.groups = {"empty", "office", "all maps"};
  b.series_labels = {"a", "b"};
  b.colors = {{44, 160, 44}, {214, 39, 40}};
  b.values = {{0.5, 0.25, NAN}, {0.4, 0.3, 0.35}};
  b.low = {{0.4, 0.2, NAN}, {0.3, 0.2, 0.3}};
  b.high = {{0.6, 0.3, NAN}, {0.5, 0.4, 0.4}};
  const cv::Mat img = draw_bar_chart(b, {800, 500});
  EXPECT_EQ(img.cols, 800);
  // Bars are areas of their colour.
  EXPECT_GT(pixels_of(img, b.colors[0]), 3000);
  EXPECT_GT(pixels_of(img, b.colors[1]), 3000);
  const cv::Mat tiled = tile_images({img, img, img}, 2);
  EXPECT_EQ(tiled.cols, 1600);
  EXPECT_EQ(tiled.rows, 1000);
  EXPECT_TRUE(tile_images({}, 2).empty());
}

}  // namespace
}  // namespace fleetmap::viz
