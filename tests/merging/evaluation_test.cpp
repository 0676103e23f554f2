#include "merging/evaluation.h"

#include <gtest/gtest.h>

#include <array>

#include "core/error.h"

#include "core/angle.h"
#include "merging/acceptance.h"
#include "tests/merging/merging_test_support.h"

namespace fleetmap::merging {
namespace {

TEST(TransformError, RotationWrapsAndTranslationIsMeasuredAtTheReference) {
  const core::Transform2 truth(10.0, 0.0, core::deg2rad(179.5));
  const core::Transform2 estimate(10.0, 0.0, core::deg2rad(-179.5));
  const TransformError e = transform_error(estimate, truth, Eigen::Vector2d::Zero());
  EXPECT_NEAR(e.rotation_deg, 1.0, 1e-9);
  EXPECT_NEAR(e.translation_cells, 0.0, 1e-9);
  // One degree off, 100 cells from the origin: 1.745 cells apart there.
  const TransformError far = transform_error(estimate, truth, Eigen::Vector2d(100.0, 0.0));
  EXPECT_NEAR(far.translation_cells, 200.0 * std::sin(core::deg2rad(0.5)), 1e-9);
}

TEST(CropPair, TheTruthPlacesBOnA) {
  core::Random random(2);
  for (const char* name : {"office", "cave"}) {
    const auto source = testing::source_map(name);
    for (const double overlap : {0.3, 0.5, 0.8}) {
      CropPairOptions o;
      o.width = o.height = 100;
      o.overlap = overlap;
      o.max_rotation_deg = overlap > 0.7 ? 20.0 : 180.0;  // a square turned 45 degrees covers at most 83% of another
      const CropPair pair = make_crop_pair(source, o, random);
      EXPECT_NEAR(pair.overlap, overlap, 0.01);
      EXPECT_EQ(pair.a.width(), o.width);
      EXPECT_EQ(pair.b.height(), o.height);
      const Acceptance acc = acceptance_index(pair.a, pair.b, pair.b_to_a);
      // Nearest-cell resampling of the turned crop moves a few wall cells by one.
      EXPECT_GT(acc.omega(), 0.97) << name;
      // The common known area is about the requested share of a crop.
      EXPECT_NEAR(double(acc.common()) / (o.width * o.height), overlap, 0.1) << name;
    }
  }
}

TEST(CropPair, DisjointCropsShareNoCell) {
  core::Random random(3);
  const auto source = testing::source_map("maze");
  CropPairOptions o;
  o.width = o.height = 80;
  o.overlap = 0.0;
  o.min_inside = 0.8;
  for (int i = 0; i < 5; ++i) {
    const CropPair pair = make_crop_pair(source, o, random);
    EXPECT_EQ(acceptance_index(pair.a, pair.b, pair.b_to_a).common(), 0);
  }
  o.width = o.height = 190;
  EXPECT_THROW(make_crop_pair(source, o, random), Error);
}

TEST(CropGrid, IsTheUnturnedResampling) {
  const auto source = testing::source_map("office");
  // Inside, across each edge, and wholly outside.
  for (const auto& [x0, y0, w, h] : {std::array{10, 20, 50, 40}, std::array{-15, -7, 60, 30},
                                     std::array{source.width() - 20, source.height() - 5, 45, 25},
                                     std::array{source.width() + 3, 0, 10, 10}}) {
    const auto crop = crop_grid(source, x0, y0, w, h);
    const auto resampled = resample_grid(source, core::Transform2(x0, y0, 0.0), w, h);
    ASSERT_EQ(crop.width(), w);
    ASSERT_EQ(crop.height(), h);
    EXPECT_EQ(crop.log_odds_data(), resampled.log_odds_data()) << x0 << ", " << y0;
    EXPECT_EQ(crop.observed_count(), resampled.observed_count());
  }
}

TEST(SyntheticWorld, ViewsOfOnePlaceAgree) {
  core::Random random(4);
  SyntheticWorldOptions wo;
  wo.width = wo.height = 600;
  const SyntheticWorld world(wo, random);
  CropPairOptions o;
  o.width = o.height = 300;
  o.overlap = 0.4;
  const CropPair pair = make_world_pair(world, o, random);
  EXPECT_GT(pair.a.count(mapping::CellState::Occupied), 1000);
  EXPECT_GT(pair.a.count(mapping::CellState::Free), 40000);
  EXPECT_GT(pair.a.count(mapping::CellState::Unknown), 0);  // inside furniture
  EXPECT_GT(acceptance_index(pair.a, pair.b, pair.b_to_a).omega(), 0.97);
  // Deterministic: the same seed draws the same world and views.
  core::Random again(4);
  const SyntheticWorld world2(wo, again);
  const CropPair pair2 = make_world_pair(world2, o, again);
  EXPECT_TRUE(pair2.a.same_states(pair.a));
  EXPECT_TRUE(pair2.b_to_a.is_approx(pair.b_to_a, 0.0));
}

}  // namespace
}  // namespace fleetmap::merging
