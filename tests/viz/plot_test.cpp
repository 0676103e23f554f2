#include "viz/plot.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <cmath>
#include <map>
#include <string>

#include <expat.h>

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

// Element counts per "name" and "name.class" of an XML document; nullopt when it is not well formed.
std::optional<std::map<std::string, int>> parse_xml(const std::string& text) {
  std::map<std::string, int> counts;
  XML_Parser parser = XML_ParserCreate("UTF-8");
  XML_SetUserData(parser, &counts);
  XML_SetStartElementHandler(parser, [](void* data, const XML_Char* name, const XML_Char** attrs) {
    auto& c = *static_cast<std::map<std::string, int>*>(data);
    ++c[name];
    for (int i = 0; attrs[i]; i += 2) {
      if (std::string(attrs[i]) == "class") ++c[std::string(name) + "." + attrs[i + 1]];
    }
  });
  const bool ok = XML_Parse(parser, text.data(), int(text.size()), 1) == XML_STATUS_OK;
  XML_ParserFree(parser);
  if (!ok) return std::nullopt;
  return counts;
}

LinePlot two_crossing_series() {
  LinePlot p;
  p.title = "coverage & <speed>";
  p.x.label = "step";
  p.y.label = "percent";
  for (const Color& c : {Color{31, 119, 180}, Color{255, 127, 14}}) {
    PlotSeries s;
    s.label = c.r == 31 ? "first" : "second";
    s.color = c;
    for (int i = 0; i <= 50; ++i) {
      s.x.push_back(i);
      s.y.push_back(c.r == 31 ? i : 50 - i);
      s.y_low.push_back(s.y.back() - 10);
      s.y_high.push_back(s.y.back() + 10);
    }
    p.series.push_back(s);
  }
  return p;
}

TEST(Plot, TheSvgIsWellFormedXmlWithOneElementPerSeriesAndBand) {
  const Drawing d = line_plot(two_crossing_series(), {700, 450});
  const std::string svg = to_svg(d);
  const auto counts = parse_xml(svg);
  ASSERT_TRUE(counts) << svg.substr(0, 400);
  EXPECT_EQ(counts->at("svg"), 1);
  EXPECT_EQ(counts->at("polyline.series"), 2);
  EXPECT_EQ(counts->at("polygon.band"), 2);
  // Bands are translucent in the SVG too, and the title's special characters are escaped.
  EXPECT_NE(svg.find("fill-opacity=\"0.2\""), std::string::npos);
  EXPECT_NE(svg.find("coverage &amp; &lt;speed&gt;"), std::string::npos);
  // The raster and the SVG have one size.
  const cv::Mat img = rasterize(d);
  EXPECT_NE(svg.find("width=\"" + std::to_string(img.cols) + "\" height=\"" + std::to_string(img.rows) + "\""), std::string::npos);
}

TEST(Plot, TheSvgCarriesTooltipsAndTheRasterShowsNoneOfThem) {
  const Drawing d = line_plot(two_crossing_series(), {700, 450});
  const std::string svg = to_svg(d);
  const auto counts = parse_xml(svg);
  ASSERT_TRUE(counts);
  // A hover spot with its numbers at every point of both series (51 points each, under 60).
  EXPECT_EQ(counts->at("circle.tip"), 2 * 51);
  EXPECT_EQ(counts->at("title"), 2 * 51);
  EXPECT_NE(svg.find("<title>first\nstep 10: percent 10 [0, 20]</title>"), std::string::npos);
  // The raster shows nothing of a hover spot.
  Drawing spot(40, 40);
  spot.hover_spot({20, 20}, 15, "invisible");
  const cv::Mat img = rasterize(spot);
  EXPECT_EQ(cv::countNonZero(cv::Mat(img != cv::Scalar(255, 255, 255)).reshape(1)), 0);
  // Bars tell their value.
  BarChart chart;
  chart.groups = {"office"};
  chart.series_labels = {"coordinated"};
  chart.values = {{0.75}};
  chart.low = {{0.5}};
  chart.high = {{1.0}};
  EXPECT_NE(to_svg(bar_chart(chart)).find("<title>coordinated, office: 0.75 [0.5, 1]</title>"), std::string::npos);
}

TEST(Plot, OverlappingBandsShowBothColours) {
  // The two series cross at x = 25, y = 25: there both bands cover the background.
  LinePlot p = two_crossing_series();
  p.x.min = 0.0;
  p.x.max = 50.0;
  p.y.min = -10.0;
  p.y.max = 60.0;
  const Drawing d = line_plot(p, {700, 450});
  const cv::Mat img = rasterize(d);
  const cv::Rect area = d.clips().front();
  // Just above the crossing, clear of both lines (which are 2 px wide).
  const int x = area.x + int(std::lround(25.0 / 50.0 * area.width));
  const int y = area.y + int(std::lround((1.0 - (25.0 + 6.0 + 10.0) / 70.0) * area.height));
  const cv::Vec3b px = img.at<cv::Vec3b>(y, x);
  // White blended with 20% blue (31, 119, 180) then 20% orange (255, 127, 14), in BGR.
  const auto blend = [](double white, double a, double b) { return (white * 0.8 + a * 0.2) * 0.8 + b * 0.2; };
  EXPECT_NEAR(px[0], blend(255, 180, 14), 3) << px;
  EXPECT_NEAR(px[1], blend(255, 119, 127), 3) << px;
  EXPECT_NEAR(px[2], blend(255, 31, 255), 3) << px;
}

TEST(Plot, ASinglePointSeriesIsDrawnAndCoincidingLinesStayVisible) {
  LinePlot p;
  p.x.ticks = {1};
  const Color grey{90, 90, 90}, blue{31, 119, 180}, orange{255, 127, 14};
  p.series.push_back({"bound", grey, {1}, {40}, {}, {}, false, true});
  // Two series with the same values: the first is drawn wider, so its colour shows beside the second.
  for (const Color& c : {blue, orange}) p.series.push_back({c.r == 31 ? "a" : "b", c, {0, 1, 2}, {80, 80, 80}, {}, {}});
  p.x.ticks = {0, 1, 2};
  const cv::Mat img = draw_line_plot(p, {600, 400});
  EXPECT_GT(pixels_of(img, grey), 10);
  EXPECT_GT(pixels_of(img, blue), 100);
  EXPECT_GT(pixels_of(img, orange), 100);
}

}  // namespace
}  // namespace fleetmap::viz
