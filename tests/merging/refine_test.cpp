#include "merging/refine.h"

#include <gtest/gtest.h>

#include <functional>

#include "core/angle.h"
#include "merging/evaluation.h"
#include "tests/merging/merging_test_support.h"

namespace fleetmap::merging {
namespace {

// Half-overlapping crops of three built-in maps, and three starts a few cells and degrees off the
// truth for each: `check(name, pair, a, b, start)`.
void for_each_nudged_start(
    std::uint64_t seed,
    const std::function<void(const char*, const CropPair&, const PreparedGrid&, const PreparedGrid&, const core::Transform2&)>&
        check) {
  core::Random random(seed);
  for (const char* name : {"office", "cave", "maze"}) {
    const auto source = testing::source_map(name);
    const CropPair pair = make_crop_pair(source, testing::half_overlap_crops(source), random);
    const PreparedGrid a(pair.a), b(pair.b);
    for (int trial = 0; trial < 3; ++trial) {
      const core::Transform2 nudge(random.uniform(-3, 3), random.uniform(-3, 3), core::deg2rad(random.uniform(-2, 2)));
      check(name, pair, a, b, nudge * pair.b_to_a);
    }
  }
}

// From a start a few cells and degrees off, refinement reaches the truth to a fraction of a cell:
// the crops are exact copies of one map, so only resampling of the turned crop limits it.
TEST(Refine, ConvergesFromAFewCellsOffToSubCellAccuracy) {
  for_each_nudged_start(11, [](const char* name, const CropPair& pair, const PreparedGrid& a, const PreparedGrid& b,
                               const core::Transform2& start) {
    const LevelFit fit = refine_alignment(a, b, start, 2);
    const TransformError e = transform_error(fit.b_to_a, pair.b_to_a, pair.overlap_centre_b);
    EXPECT_LT(e.rotation_deg, 0.5) << name;
    EXPECT_LT(e.translation_cells, 0.5) << name;
    EXPECT_GT(fit.inliers, 100) << name;
    EXPECT_LE(fit.outliers, fit.inliers / 100) << name;
  });
}

// The coarse levels stop once a step moves the points less than RefineOptions::coarse_converged_cells;
// the finest level, run to converged_cells, ends where it would end after coarse levels run to
// converged_cells too: the same answer to a few hundredths of a cell.
TEST(Refine, CoarseLevelsStoppingEarlierEndAtTheSameAnswer) {
  RefineOptions strict;
  strict.coarse_converged_cells = strict.converged_cells;
  for_each_nudged_start(12, [&](const char* name, const CropPair& pair, const PreparedGrid& a, const PreparedGrid& b,
                                const core::Transform2& start) {
    const LevelFit early = refine_alignment(a, b, start, 2);
    const LevelFit full = refine_alignment(a, b, start, 2, strict);
    EXPECT_LT(mean_displacement(early.b_to_a, full.b_to_a, pair.b), 0.05) << name;
    EXPECT_NEAR(early.inliers, full.inliers, 0.01 * full.inliers) << name;
  });
}

}  // namespace
}  // namespace fleetmap::merging
