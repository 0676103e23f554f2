#include "merging/prepared_grid.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "tests/merging/merging_test_support.h"

namespace fleetmap::merging {
namespace {

using testing::grid_from_text;

TEST(PreparedGrid, WallsAreOccupiedCellsNextToFreeOnes) {
  const auto g = grid_from_text({".....", ".###.", ".###.", ".###.", "....."});
  const PreparedGrid p(g);
  // The 3 x 3 block has 8 boundary cells; its centre is interior.
  EXPECT_EQ(p.walls().size(), 8u);
  EXPECT_EQ(p.level(0).interior_points.size(), 1u);  // (2, 2): both coordinates even
  EXPECT_FLOAT_EQ(p.level(0).distance_at(0.0f, 2.0f, -1.0f), 1.0f);
  EXPECT_FLOAT_EQ(p.level(0).distance_at(1.0f, 2.0f, -1.0f), 0.0f);
}

TEST(PreparedGrid, SpecksAreNoise) {
  std::vector<std::string> rows(20, std::string(20, '.'));
  rows[3][3] = '#';                             // a one-cell speck
  rows[10] = std::string(4, '.') + std::string(12, '#') + std::string(4, '.');  // a wall
  const PreparedGrid p(grid_from_text(rows));
  EXPECT_EQ(p.walls().size(), 12u);
  PrepareOptions keep;
  keep.min_obstacle_cells = 1;
  EXPECT_EQ(PreparedGrid(grid_from_text(rows), keep).walls().size(), 13u);
}

TEST(PreparedGrid, PyramidKeepsThinWalls) {
  std::vector<std::string> rows(64, std::string(64, '.'));
  for (auto& r : rows) r[31] = '#';  // a one-cell wall
  PrepareOptions o;
  o.min_level_size = 8;
  const PreparedGrid p(grid_from_text(rows), o);
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
  const PreparedGrid p(grid_from_text(rows));
  for (const auto& w : p.walls()) {
    if (w.position.x() < 4 || w.position.x() > 16) continue;  // away from the ends
    EXPECT_NEAR(w.structure(1, 1), 1.0f, 1e-5) << w.position.transpose();  // normal is y
    EXPECT_NEAR(w.structure(0, 0), 0.0f, 1e-5);
  }
}

}  // namespace
}  // namespace fleetmap::merging
