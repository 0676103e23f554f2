#include "merging/prepared_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/random.h"
#include "merging/acceptance.h"
#include "merging/grid_level.h"
#include "tests/merging/merging_test_support.h"

namespace fleetmap::merging {
namespace {

using testing::grid_from_text;

TEST(PreparedGrid, WallsAreOccupiedCellsNextToFreeOnes) {
  const auto g = grid_from_text({".....", ".###.", ".###.", ".###.", "....."});
  PrepareOptions no_clutter;  // the block is small enough to be clutter: here it is structure
  no_clutter.clutter_size_m = 0.0;
  const PreparedGrid p(g, no_clutter);
  // The 3 x 3 block has 8 boundary cells; its centre is interior.
  EXPECT_EQ(p.walls().size(), 8u);
  EXPECT_EQ(p.level(0).interior_points.size(), 1u);  // (2, 2): both coordinates even
  EXPECT_FLOAT_EQ(p.level(0).distance_at(0.0f, 2.0f, -1.0f), 1.0f);
  EXPECT_FLOAT_EQ(p.level(0).distance_at(1.0f, 2.0f, -1.0f), 0.0f);
}

// The part under a mask is b's own prepared data, cut at a cell boundary of every level: the same
// walls, cells and distances, moved by the cut's origin, and nothing outside the mask.
TEST(PreparedGrid, MaskedPartIsTheSourcesDataMovedByTheCutsOrigin) {
  std::vector<std::string> rows(120, std::string(100, '.'));
  for (int r = 10; r < 110; r += 20) rows[std::size_t(r)].replace(5, 90, std::string(90, '#'));  // five walls
  const auto g = grid_from_text(rows);
  const PreparedGrid source(g);
  cv::Mat mask = cv::Mat::zeros(source.height(), source.width(), CV_8U);
  mask(cv::Rect(37, 43, 40, 50)).setTo(255);
  Eigen::Vector2i origin;
  const PreparedGrid part = prepared_part(source, mask, PrepareOptions{}, origin);
  const int coarsest = source.level(source.level_count() - 1).factor;
  EXPECT_EQ(origin.x() % coarsest, 0);
  EXPECT_EQ(origin.y() % coarsest, 0);
  std::size_t inside = 0;
  for (const auto& w : source.walls())
    inside += mask.at<std::uint8_t>(int(w.position.y()), int(w.position.x())) != 0;
  ASSERT_GT(inside, 0u);
  EXPECT_EQ(part.walls().size(), inside);
  for (const auto& w : part.walls()) {
    const Eigen::Vector2f at = w.position + origin.cast<float>();
    EXPECT_NE(mask.at<std::uint8_t>(int(at.y()), int(at.x())), 0);
    EXPECT_NE(source.level(0).walls.at<std::uint8_t>(int(at.y()), int(at.x())), 0);
  }
  // A free cell inside: its distance to the walls is the source's.
  const Eigen::Vector2i cell(50, 55);
  const Eigen::Vector2i moved = cell - origin;
  EXPECT_TRUE(part.level(0).is_free(moved.x(), moved.y()));
  EXPECT_FLOAT_EQ(part.level(0).distance_at(float(moved.x()), float(moved.y()), -1.0f),
                  source.level(0).distance_at(float(cell.x()), float(cell.y()), -1.0f));
  // Outside the mask (inside the cut's box) nothing is known.
  EXPECT_FALSE(part.level(0).known(0, 0));
  EXPECT_EQ(part.level_count() <= source.level_count(), true);
}

// A real laser map often leaves the cells just in front of a wall unknown (middling probability,
// read as unknown by map_server's thresholds): a one-cell seam between the wall and the free space.
// Closed, the wall is a wall to align; a gap of two cells is what the robot did not see, and stays.
TEST(PreparedGrid, AOneCellUnknownSeamBeforeAWallIsFreeSpace) {
  std::vector<std::string> rows(12, std::string(20, ' '));
  rows[2] = std::string(20, '#');  // a wall behind a one-cell seam (row 3)
  for (int r = 4; r < 8; ++r) rows[std::size_t(r)] = std::string(20, '.');
  rows[10] = std::string(20, '#');  // a second wall, behind a two-cell gap (rows 8 and 9)
  const auto g = grid_from_text(rows);
  const PreparedGrid closed(g);
  EXPECT_EQ(closed.walls().size(), 20u);  // the first wall only
  const int seam_y = 12 - 1 - 3, gap_y = 12 - 1 - 8;  // cell rows count from the bottom
  for (int x = 0; x < 20; ++x) {
    EXPECT_TRUE(closed.level(0).is_free(x, seam_y)) << x;
    EXPECT_FALSE(closed.level(0).known(x, gap_y)) << x;
  }
  PrepareOptions as_read;
  as_read.close_seams = false;
  const PreparedGrid open(g, as_read);
  EXPECT_EQ(open.walls().size(), 0u);
  EXPECT_EQ(closed.known_cells(), open.known_cells() + 20);
}

TEST(PreparedGrid, SpecksAreNoise) {
  std::vector<std::string> rows(20, std::string(20, '.'));
  rows[3][3] = '#';                             // a one-cell speck
  rows[10] = std::string(4, '.') + std::string(12, '#') + std::string(4, '.');  // a wall
  const auto p_map = grid_from_text(rows);  // outlives the prepared grid
  const PreparedGrid p(p_map);
  EXPECT_EQ(p.walls().size(), 12u);
  PrepareOptions keep;
  keep.min_obstacle_cells = 1;
  EXPECT_EQ(PreparedGrid(p_map, keep).walls().size(), 13u);
}

// Specks are the occupied components (8-connected) smaller than min_obstacle_cells, whatever their
// shape; the ones of one or two cells are told apart without labelling: the same cells either way.
TEST(PreparedGrid, SpecksAreTheSmallComponentsWhateverTheirShape) {
  // Random occupied cells, about one in six: components of every small shape, touching diagonally.
  const int w = 61, h = 47;
  std::vector<std::string> rows(std::size_t(h), std::string(std::size_t(w), '.'));
  core::Random random(12345);
  cv::Mat occupied_text = cv::Mat::zeros(h, w, CV_8U);  // text rows, top first
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (random.bernoulli(1.0 / 6.0)) rows[std::size_t(y)][std::size_t(x)] = '#', occupied_text.at<std::uint8_t>(y, x) = 255;
  // Each component's size, from OpenCV's statistics (the code under test labels without them).
  cv::Mat labels, stats, centroids;
  const int components = cv::connectedComponentsWithStats(occupied_text, labels, stats, centroids, 8, CV_32S);
  std::vector<int> label(std::size_t(w * h), -1), size;
  for (int i = 1; i < components; ++i) size.push_back(stats.at<int>(i, cv::CC_STAT_AREA));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) label[std::size_t(y * w + x)] = labels.at<int>(y, x) - 1;
  const auto g = grid_from_text(rows);
  for (const int min_cells : {1, 2, 3, 4, 6}) {
    PrepareOptions o;
    o.min_obstacle_cells = min_cells;
    o.clutter_size_m = 0.0;
    const PreparedGrid p(g, o);
    int kept_by_size = 0, wrong = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const int l = label[std::size_t(y * w + x)];
        const bool kept = l >= 0 && size[std::size_t(l)] >= min_cells;
        kept_by_size += kept;
        wrong += kept != (p.level(0).occupied.at<std::uint8_t>(h - 1 - y, x) != 0);
      }
    EXPECT_EQ(wrong, 0) << "min_obstacle_cells " << min_cells;
    // Every cell of the text is known; a speck's cells become unknown.
    const auto occupied = std::count_if(label.begin(), label.end(), [](int l) { return l >= 0; });
    EXPECT_EQ(p.known_cells(), std::int64_t(w * h) - (occupied - kept_by_size)) << "min_obstacle_cells " << min_cells;
  }
  // The random map has components of one, two and three cells (so that each rule is tried).
  for (const int n : {1, 2, 3}) EXPECT_GT(std::count(size.begin(), size.end(), n), 3) << n;
}

// A chair or a person (a blob of 0.15 m standing alone) is clutter; a wall, and a blob touching
// it, are not. Clutter walls never contradict the other map: it may have moved between visits.
TEST(PreparedGrid, SmallLoneObstaclesAreClutterAndNeverContradict) {
  std::vector<std::string> rows(40, std::string(40, '.'));
  rows[30] = std::string(40, '#');                          // a wall, 2 m long
  for (int r = 10; r < 13; ++r) rows[std::size_t(r)].replace(10, 3, "###");  // a chair in the open
  for (int r = 27; r < 30; ++r) rows[std::size_t(r)].replace(25, 3, "###");  // a cupboard against the wall
  const auto with = grid_from_text(rows);
  const PreparedGrid p(with);
  const GridLevel& l0 = p.level(0);
  const auto clutter_at = [&](int x, int row) { return l0.clutter.at<std::uint8_t>(39 - row, x) != 0; };
  EXPECT_TRUE(clutter_at(11, 11));
  EXPECT_FALSE(clutter_at(5, 30));
  EXPECT_FALSE(clutter_at(26, 28));
  // The same room without the chair: the chair lies on its clear free space.
  for (int r = 10; r < 13; ++r) rows[std::size_t(r)].replace(10, 3, "...");
  const auto empty_map = grid_from_text(rows);  // outlives the prepared grid
  const PreparedGrid empty(empty_map);
  const AlignmentQuality q = evaluate_alignment(empty, p, core::Transform2::identity());
  EXPECT_EQ(q.contradicted, 0);
  EXPECT_GT(q.matched, 60);
  // Without the clutter rule the chair contradicts.
  PrepareOptions no_clutter;
  no_clutter.clutter_size_m = 0.0;
  const PreparedGrid strict(with, no_clutter);
  EXPECT_GT(evaluate_alignment(empty, strict, core::Transform2::identity()).contradicted, 0);
}

TEST(PreparedGrid, PyramidKeepsThinWalls) {
  std::vector<std::string> rows(64, std::string(64, '.'));
  for (auto& r : rows) r[31] = '#';  // a one-cell wall
  PrepareOptions o;
  o.min_level_size = 8;
  const auto p_map = grid_from_text(rows);  // outlives the prepared grid
  const PreparedGrid p(p_map, o);
  ASSERT_GE(p.level_count(), 4);
  for (int k = 1; k < p.level_count(); ++k) {
    const GridLevel& l = p.level(k);
    EXPECT_EQ(l.factor, 1 << k);
    EXPECT_EQ(cv::countNonZero(l.occupied), l.height()) << "level " << k;  // still one column
  }
  EXPECT_EQ(p.level_for_size(16), 2);   // 64 -> 32 -> 16
  EXPECT_EQ(p.level_for_size(1000), 0);
  EXPECT_EQ(p.level_for_size(1), p.level_count() - 1);
}

TEST(PreparedGrid, LevelTransformsRoundTripAndAgreeWithCellCentres) {
  const core::Transform2 fine(12.5, -3.25, 0.4);
  for (int factor : {1, 2, 4, 8}) {
    EXPECT_TRUE(from_level(to_level(fine, factor), factor).is_approx(fine, 1e-9));
    // Coarse cell X has its centre at fine factor * X + (factor - 1) / 2.
    const core::Transform2 coarse = to_level(fine, factor);
    const Eigen::Vector2d x(3.0, 5.0), c((factor - 1) / 2.0, (factor - 1) / 2.0);
    const Eigen::Vector2d via_fine = (fine.apply(factor * x + c) - c) / factor;
    EXPECT_TRUE(coarse.apply(x).isApprox(via_fine, 1e-9));
  }
}

TEST(PreparedGrid, WallStructureIsTheNormalOnAStraightWall) {
  std::vector<std::string> rows(21, std::string(21, '.'));
  rows[10] = std::string(21, '#');
  const auto p_map = grid_from_text(rows);  // outlives the prepared grid
  const PreparedGrid p(p_map);
  for (const auto& w : p.walls()) {
    if (w.position.x() < 4 || w.position.x() > 16) continue;  // away from the ends
    EXPECT_NEAR(w.structure(1, 1), 1.0f, 1e-5) << w.position.transpose();  // normal is y
    EXPECT_NEAR(w.structure(0, 0), 0.0f, 1e-5);
  }
}


// The distance to the walls is the Euclidean one (not a chamfer approximation: 1.4 for a diagonal
// step, 2.2 for a knight's move) at every level, up to max_wall_distance and that value beyond:
// refinement and scoring read it as cells.
TEST(PreparedGrid, WallDistanceIsEuclideanAtEveryLevel) {
  std::vector<std::string> rows(48, std::string(48, '.'));
  rows[20].replace(20, 6, "######");  // a short wall
  rows[30][10] = rows[31][10] = rows[31][11] = '#';  // a small obstacle
  PrepareOptions o;
  o.min_level_size = 12;
  o.max_wall_distance = 7.5;  // the map's far corners are farther
  const auto p_map = grid_from_text(rows);  // outlives the prepared grid
  const PreparedGrid p(p_map, o);
  ASSERT_GE(p.level_count(), 2);
  for (int k = 0; k < 2; ++k) {
    const GridLevel& l = p.level(k);
    std::vector<cv::Point> walls;
    cv::findNonZero(l.walls, walls);
    ASSERT_FALSE(walls.empty());
    for (int y = 0; y < l.height(); ++y) {
      for (int x = 0; x < l.width(); ++x) {
        double exact = 1e9;
        for (const auto& w : walls) exact = std::min(exact, std::hypot(double(x - w.x), double(y - w.y)));
        EXPECT_NEAR(l.wall_distance.at<float>(y, x), std::min(exact, 7.5), 1e-3) << "level " << k << " at " << x << ", " << y;
      }
    }
  }
}

// Obstacles touching the map's edge are judged by their own size as elsewhere: a chair in a
// corner is clutter, a wall along the edge is not; specks at the edge are noise.
TEST(PreparedGrid, ClutterAndSpecksAtTheMapsEdge) {
  std::vector<std::string> rows(40, std::string(40, '.'));
  for (int r = 0; r < 3; ++r) rows[std::size_t(r)].replace(0, 3, "###");  // a chair in the top-left corner
  rows[39] = std::string(40, '#');                                      // a wall along the bottom edge
  rows[20][39] = '#';                                                   // a one-cell speck on the right edge
  const auto p_map = grid_from_text(rows);  // outlives the prepared grid
  const PreparedGrid p(p_map);
  const GridLevel& l0 = p.level(0);
  const auto at = [&](const cv::Mat& m, int x, int row) { return m.at<std::uint8_t>(39 - row, x) != 0; };
  EXPECT_TRUE(at(l0.clutter, 1, 1));
  EXPECT_FALSE(at(l0.clutter, 20, 39));
  EXPECT_TRUE(at(l0.occupied, 20, 39));
  EXPECT_FALSE(at(l0.occupied, 39, 20));  // the speck is left out
}

}  // namespace
}  // namespace fleetmap::merging
