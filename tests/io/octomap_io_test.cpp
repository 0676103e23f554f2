#include "io/octomap_io.h"

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <random>

#include "tests/test_support.h"

namespace fleetmap::io {
namespace {

using core::GridGeometry;
using mapping::CellState;
using mapping::OccupancyGrid;

TEST(OctomapIo, BinaryTreeReadsBackWithTheSameCells) {
  fleetmap::testing::TempDir dir;
  OccupancyGrid g(GridGeometry(0.1, 40, 30, core::Pose2(-2.0, -1.0, 0.0)));
  std::mt19937 rng(4);
  std::uniform_int_distribution<int> s(0, 2);
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 40; ++x) g.set_state({x, y}, static_cast<CellState>(s(rng)));
  save_octomap(g, dir / "map.bt");

  octomap::OcTree tree(0.1);
  ASSERT_TRUE(tree.readBinary((dir / "map.bt").string()));
  EXPECT_NEAR(tree.getResolution(), 0.1, 1e-9);
  int occupied = 0;
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 40; ++x) {
      const Eigen::Vector2d c = g.geometry().cell_center({x, y});
      const octomap::OcTreeNode* node = tree.search(c.x(), c.y(), 0.05);
      switch (g.state({x, y})) {
        case CellState::Unknown: EXPECT_EQ(node, nullptr) << x << "," << y; break;
        case CellState::Free:
          ASSERT_NE(node, nullptr);
          EXPECT_FALSE(tree.isNodeOccupied(node));
          break;
        case CellState::Occupied:
          ASSERT_NE(node, nullptr);
          EXPECT_TRUE(tree.isNodeOccupied(node));
          ++occupied;
          break;
      }
      // Nothing above the single layer.
      EXPECT_EQ(tree.search(c.x(), c.y(), 0.15), nullptr);
    }
  }
  EXPECT_EQ(occupied, g.count(CellState::Occupied));
}

}  // namespace
}  // namespace fleetmap::io
