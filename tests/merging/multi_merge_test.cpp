#include "merging/multi_merge.h"

#include <gtest/gtest.h>

#include "merging/acceptance.h"
#include "merging/evaluation.h"
#include "tests/merging/merging_test_support.h"

namespace fleetmap::merging {
namespace {

// Four robots' views of one map: each a 260 x 260 window of a 500 x 500 part of the campus, turned
// and shifted. Every one must land within a degree and a cell of the truth in the first one's
// frame, and the fused map must agree with the source map everywhere it claims to know.
TEST(MultiMerge, FourCropsOfOneMapMergeIntoOneConsistentMap) {
  const auto source = testing::source_map("campus");
  core::Random random(8);
  struct View { core::Transform2 to_source; mapping::OccupancyGrid grid; };
  std::vector<View> views;
  const int size = 260;
  const core::Transform2 centre_shift(-(size - 1) / 2.0, -(size - 1) / 2.0, 0.0);
  for (const auto& [cx, cy] : std::vector<std::pair<double, double>>{{150, 150}, {340, 160}, {160, 345}, {330, 330}}) {
    const core::Transform2 to_source = core::Transform2(cx, cy, random.uniform(-3.1, 3.1)) * centre_shift;
    views.push_back({to_source, resample_grid(source, to_source, size, size)});
  }
  std::vector<const mapping::OccupancyGrid*> grids;
  for (const auto& v : views) grids.push_back(&v.grid);
  int calls = 0;
  const MultiMergeResult r = merge_maps(grids, {}, [&](int done, int total) {
    ++calls;
    EXPECT_EQ(total, 6);
    EXPECT_EQ(done, calls);
  });
  EXPECT_EQ(calls, 6);
  EXPECT_EQ(r.pairs.size(), 6u);
  EXPECT_EQ(r.parent[0], -1);
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(r.to_first[std::size_t(i)].has_value()) << "view " << i << ": " << r.reason[std::size_t(i)];
    const core::Transform2 truth = views[0].to_source.inverse() * views[std::size_t(i)].to_source;
    const Eigen::Vector2d centre((size - 1) / 2.0, (size - 1) / 2.0);
    const TransformError e = transform_error(*r.to_first[std::size_t(i)], truth, centre);
    EXPECT_LT(e.rotation_deg, 1.0) << "view " << i;
    EXPECT_LT(e.translation_cells, 1.0) << "view " << i;
    if (i > 0) {
      EXPECT_GE(r.parent[std::size_t(i)], 0);
      EXPECT_GE(r.confidence[std::size_t(i)], MergeOptions{}.min_confidence);
    }
  }
  EXPECT_LT(r.max_loop_gap, 1.0);
  // Every placement has a covariance; one placed through another map is no surer than that one.
  ASSERT_TRUE(r.covariance[0].has_value());
  EXPECT_EQ(*r.covariance[0], Eigen::Matrix3d::Zero());
  for (int i = 1; i < 4; ++i) {
    ASSERT_TRUE(r.covariance[std::size_t(i)].has_value()) << "view " << i;
    const int parent = r.parent[std::size_t(i)];
    EXPECT_GE((*r.covariance[std::size_t(i)])(2, 2), (*r.covariance[std::size_t(parent)])(2, 2)) << "view " << i;
    EXPECT_GT((*r.covariance[std::size_t(i)])(2, 2), 0.0) << "view " << i;
  }
  // The fused map, put back on the source map, agrees with it.
  const FusedMap fused = fuse_merged(grids, r);
  EXPECT_EQ(fused.inputs, (std::vector<int>{0, 1, 2, 3}));
  const core::Transform2 fused_to_source =
      views[0].to_source * core::Transform2(-fused.offset.x, -fused.offset.y, 0.0);
  const Acceptance acc = acceptance_index(source, fused.grid, fused_to_source);
  EXPECT_GT(acc.omega(), 0.99);
  EXPECT_GT(acc.common(), 4 * 260 * 260 / 2);
  // The views are nearest-cell samples of turned windows: a wall's edge may fall one cell apart in
  // two of them. So conflicts may only sit on the source's wall edges, never in open space.
  ASSERT_GT(fused.conflict_cells, 0);
  int off_edge = 0;
  for (int y = 0; y < fused.grid.height(); ++y) {
    for (int x = 0; x < fused.grid.width(); ++x) {
      if (!fused.conflicts[std::size_t(y * fused.grid.width() + x)]) continue;
      const Eigen::Vector2d p = fused_to_source.apply(Eigen::Vector2d(x, y));
      bool near_occupied = false, near_free = false;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const auto s = source.state({int(std::lround(p.x())) + dx, int(std::lround(p.y())) + dy});
          near_occupied = near_occupied || s == mapping::CellState::Occupied;
          near_free = near_free || s == mapping::CellState::Free;
        }
      }
      off_edge += !(near_occupied && near_free);
    }
  }
  EXPECT_EQ(off_edge, 0) << "of " << fused.conflict_cells << " conflicts";
}

// The same two maps said to have cells of 0.05 m and of 0.1 m: the placement's covariance is in
// metres and radians, so its translation's variances grow four times and theta's stays.
TEST(MultiMerge, ThePlacementsCovarianceIsInMetresWhateverTheCellSize) {
  const auto source = testing::source_map("office");
  core::Random random(21);
  const CropPair pair = make_crop_pair(source, testing::half_overlap_crops(source), random);
  const auto relabelled = [](const mapping::OccupancyGrid& g, double resolution) {
    mapping::OccupancyGrid out(core::GridGeometry(resolution, g.width(), g.height()));
    for (int y = 0; y < g.height(); ++y)
      for (int x = 0; x < g.width(); ++x) out.set_state({x, y}, g.state({x, y}));
    return out;
  };
  std::vector<Eigen::Matrix3d> covariances;
  for (const double resolution : {0.05, 0.1}) {
    const auto a = relabelled(pair.a, resolution), b = relabelled(pair.b, resolution);
    const MergedMaps m = merge_and_fuse({&a, &b});
    ASSERT_TRUE(m.placements[1].has_value()) << resolution << ": " << m.merge.reason[1];
    ASSERT_TRUE(m.placements[1]->covariance.has_value()) << resolution;
    covariances.push_back(*m.placements[1]->covariance);
  }
  EXPECT_NEAR(covariances[1](0, 0), 4.0 * covariances[0](0, 0), 0.02 * covariances[1](0, 0));
  EXPECT_NEAR(covariances[1](1, 1), 4.0 * covariances[0](1, 1), 0.02 * covariances[1](1, 1));
  EXPECT_NEAR(covariances[1](2, 2), covariances[0](2, 2), 0.02 * covariances[0](2, 2));
  // A fraction of a cell, in metres, at 0.05 m.
  EXPECT_LT(std::sqrt(covariances[0](0, 0)), 0.05);
}

TEST(MultiMerge, AMapThatOverlapsNothingIsLeftOutWithAReason) {
  const auto source = testing::source_map("office");
  const auto a = crop_grid(source, 0, 0, 140, 140);
  const auto b = crop_grid(source, 60, 60, 140, 140);
  const auto other = resample_grid(testing::source_map("cave"), core::Transform2(20, 20, 1.0), 120, 120);
  const MultiMergeResult r = merge_maps({&a, &other, &b});
  ASSERT_TRUE(r.to_first[2].has_value()) << r.reason[2];
  EXPECT_TRUE(r.to_first[2]->is_approx(core::Transform2(60, 60, 0.0), 0.5)) << *r.to_first[2];
  EXPECT_FALSE(r.to_first[1].has_value());
  EXPECT_NE(r.reason[1].find("no reliable overlap"), std::string::npos) << r.reason[1];
  EXPECT_EQ(r.parent[1], -1);
  const FusedMap fused = fuse_merged({&a, &other, &b}, r);
  EXPECT_EQ(fused.inputs, (std::vector<int>{0, 2}));
}

}  // namespace
}  // namespace fleetmap::merging
