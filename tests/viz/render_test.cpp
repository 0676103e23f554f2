#include "viz/render.h"

#include <gtest/gtest.h>

namespace fleetmap::viz {
namespace {

using core::GridGeometry;
using mapping::CellState;
using mapping::OccupancyGrid;

cv::Vec3b at(const cv::Mat& img, int x, int y) { return img.at<cv::Vec3b>(y, x); }

OccupancyGrid three_state_grid() {
  OccupancyGrid g(GridGeometry(0.5, 10, 10));
  for (int x = 0; x < 10; ++x) {
    g.set_state({x, 0}, CellState::Occupied);
    for (int y = 1; y < 5; ++y) g.set_state({x, y}, CellState::Free);
  }
  return g;
}

TEST(Render, MapColoursAtEveryCell) {
  const auto g = three_state_grid();
  const cv::Mat c = colorize(g);
  ASSERT_EQ(c.size(), cv::Size(10, 10));
  EXPECT_EQ(at(c, 3, 9), cv::Vec3b(0, 0, 0));        // cell (3, 0): bottom row, occupied
  EXPECT_EQ(at(c, 3, 7), cv::Vec3b(255, 255, 255));  // cell (3, 2): free
  EXPECT_EQ(at(c, 3, 2), cv::Vec3b(205, 205, 205));  // cell (3, 7): unknown
}

TEST(Render, ScalesUpAddsLegendPanelAndDrawsOverlays) {
  const auto g = three_state_grid();
  Overlays o;
  o.paths.push_back({{{0.25, 1.25}, {4.75, 1.25}}, Color{255, 0, 0}, "robot 1 path"});
  o.poses.push_back({core::Pose2(2.5, 2.0, 0.0), 0.25, Color{0, 0, 255}, "robot 1"});
  o.cells.push_back({{{9, 4}}, Color{0, 200, 0}, "frontier", 1.0});
  RenderOptions r;
  r.target_size_px = 100;
  r.title = "test";
  const cv::Mat img = render_map(g, o, r);
  // 10 cells * 10 px, plus the legend panel on the right.
  EXPECT_GE(img.rows, 100);
  EXPECT_GT(img.cols, 100 + 100);
  // The path runs along y = 1.25 m = grid row 2.5 -> pixel row 75.
  EXPECT_EQ(at(img, 30, 75), cv::Vec3b(0, 0, 255));
  // The robot disc is centred at (2.5, 2.0) m -> pixel (50, 60), filled blue.
  EXPECT_EQ(at(img, 50, 63), cv::Vec3b(255, 0, 0));
  // The frontier cell (9, 4) -> pixels x 90..99, y 50..59.
  EXPECT_EQ(at(img, 95, 55), cv::Vec3b(0, 200, 0));
  // The legend shows the overlay colours in the panel.
  const cv::Mat panel = img(cv::Rect(101, 0, img.cols - 101, img.rows));
  int red = 0, blue = 0;
  for (int y = 0; y < panel.rows; ++y)
    for (int x = 0; x < panel.cols; ++x) {
      red += at(panel, x, y) == cv::Vec3b(0, 0, 255);
      blue += at(panel, x, y) == cv::Vec3b(255, 0, 0);
    }
  EXPECT_GT(red, 5);
  EXPECT_GT(blue, 5);
}

TEST(Render, LargeMapsAreScaledDown) {
  OccupancyGrid g(GridGeometry(0.1, 3000, 1000));
  RenderOptions r;
  r.max_size_px = 1500;
  r.legend = false;
  const cv::Mat img = render_map(g, {}, r);
  EXPECT_EQ(img.cols, 1500);
  EXPECT_EQ(img.rows, 500);
}

}  // namespace
}  // namespace fleetmap::viz
