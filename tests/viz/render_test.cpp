#include "viz/render.h"

#include "viz/drawing.h"

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
  const Picture pic = draw_picture(colorize(g), g.geometry(), o, r);
  ASSERT_EQ(pic.map_area.size(), cv::Size(100, 100));  // 10 cells * 10 px
  // The map, then the legend panel on the right.
  EXPECT_GT(pic.image.cols, pic.map_area.x + 100 + 100);
  const cv::Mat img = pic.image(pic.map_area).clone();
  // The path runs along y = 1.25 m = grid row 2.5 -> pixel row 75.
  EXPECT_EQ(at(img, 30, 75), cv::Vec3b(0, 0, 255));
  // The robot disc is centred at (2.5, 2.0) m -> pixel (50, 60), filled blue.
  EXPECT_EQ(at(img, 50, 63), cv::Vec3b(255, 0, 0));
  // The frontier cell (9, 4) -> pixels x 90..99, y 50..59.
  EXPECT_EQ(at(img, 95, 55), cv::Vec3b(0, 200, 0));
  // The legend shows the overlay colours in the panel.
  const int panel_x = pic.map_area.x + pic.map_area.width + 1;
  const cv::Mat panel = pic.image(cv::Rect(panel_x, 0, pic.image.cols - panel_x, pic.image.rows));
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
  const Picture pic = draw_picture(colorize(g), g.geometry(), {}, r);
  EXPECT_EQ(pic.map_area.width, 1500);
  EXPECT_EQ(pic.map_area.height, 500);
  r.axes = false;
  const cv::Mat bare = render_map(g, {}, r);
  EXPECT_EQ(bare.cols, 1500);
  EXPECT_EQ(bare.rows, 500);
}

// The columns of `img` that hold dark (text) pixels.
int rightmost_dark_column(const cv::Mat& img, cv::Rect where) {
  int right = -1;
  for (int y = where.y; y < where.y + where.height; ++y)
    for (int x = where.x; x < where.x + where.width; ++x)
      if (img.at<cv::Vec3b>(y, x)[0] < 128) right = std::max(right, x);
  return right;
}

TEST(Render, ALongTitleFitsInsideThePicture) {
  OccupancyGrid g(GridGeometry(0.1, 20, 20));
  for (int x = 0; x < 20; ++x)
    for (int y = 0; y < 20; ++y) g.set_state({x, y}, CellState::Free);
  RenderOptions r;
  r.target_size_px = 60;
  r.title = "office: robot 1's map, a title far longer than the map and its legend together";
  const Picture pic = draw_picture(colorize(g), g.geometry(), {}, r);
  const cv::Size text = text_size(r.title, 0.6);
  EXPECT_GT(pic.image.cols, text.width);
  // The title's ink ends before the right edge, above the map.
  const int right = rightmost_dark_column(pic.image, cv::Rect(0, 0, pic.image.cols, pic.map_area.y - 20));
  EXPECT_GT(right, text.width / 2);
  EXPECT_LT(right, pic.image.cols - 3);
}

TEST(Render, CropsToTheKnownCellsAndGrowsForOverlaysOffTheGrid) {
  // A 2 m x 1 m known patch in a 40 m grid: the picture covers the patch and a 1 m margin.
  OccupancyGrid g(GridGeometry(0.1, 400, 400));
  for (int x = 100; x < 120; ++x)
    for (int y = 50; y < 60; ++y) g.set_state({x, y}, CellState::Free);
  RenderOptions r;
  r.crop_margin_m = 1.0;
  r.target_size_px = 400;
  Picture pic = draw_picture(colorize(g), g.geometry(), {}, r);
  EXPECT_NEAR(pic.map_area.width / pic.px_per_cell, 40, 1);   // 20 cells + 2 x 10
  EXPECT_NEAR(pic.map_area.height / pic.px_per_cell, 30, 1);  // 10 cells + 2 x 10
  EXPECT_LT(pic.image.cols, 1000);
  // A trajectory that drifted below the grid (y < 0) stays in the picture.
  Overlays o;
  o.paths.push_back({{{11.0, 5.5}, {11.0, -2.0}}, Color{255, 0, 0}, "estimate"});
  pic = draw_picture(colorize(g), g.geometry(), o, r);
  EXPECT_LE(pic.grid_min.y(), -20.0);
  const int row_of_minus_1m = pic.map_area.y + int((pic.map_area.height / pic.px_per_cell + pic.grid_min.y() - (-10)) * pic.px_per_cell);
  const cv::Vec3b outside = pic.image.at<cv::Vec3b>(row_of_minus_1m, pic.map_area.x + 2);
  EXPECT_EQ(outside, cv::Vec3b(238, 238, 238));
}

TEST(Render, RobotMarkersStayVisibleOnLargeMapsAndStartsAreRings) {
  OccupancyGrid g(GridGeometry(0.05, 3000, 3000));  // 150 m, drawn at 4000 px
  for (int x = 0; x < 3000; x += 7) g.set_state({x, 10}, CellState::Free);
  Overlays o;
  const Color blue{0, 0, 255};
  o.poses.push_back({core::Pose2(75.0, 75.0, 0.0), 0.2, blue, "robot"});
  o.poses.push_back({core::Pose2(30.0, 30.0, 0.0), 0.2, blue, "start", true});
  RenderOptions r;
  const Picture pic = draw_picture(colorize(g), g.geometry(), o, r);
  const auto pixel = [&](double x_m, double y_m, double dx_px) {
    const double px = (x_m / 0.05 - pic.grid_min.x()) * pic.px_per_cell + dx_px;
    const double py = (pic.map_area.height / pic.px_per_cell - (y_m / 0.05 - pic.grid_min.y())) * pic.px_per_cell;
    return pic.image.at<cv::Vec3b>(pic.map_area.y + int(py), pic.map_area.x + int(px));
  };
  // A 0.2 m robot would be 3 px; the disc is at least 1/160 of the picture, 25 px.
  EXPECT_EQ(pixel(75.0, 75.0, -15), cv::Vec3b(255, 0, 0));
  // The start is a ring: its centre shows the map, its rim the colour.
  EXPECT_NE(pixel(30.0, 30.0, -5), cv::Vec3b(255, 0, 0));
  bool rim = false;
  for (int d = 15; d < 40; ++d) rim = rim || pixel(30.0, 30.0, -d) == cv::Vec3b(255, 0, 0);
  EXPECT_TRUE(rim);
}

}  // namespace
}  // namespace fleetmap::viz
