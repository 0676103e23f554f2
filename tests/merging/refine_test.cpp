#include "merging/refine.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "core/angle.h"
#include "merging/evaluation.h"
#include "merging/multi_merge.h"
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

// --- the covariance of the fit ------------------------------------------------------------------

// A window of 12 m of a corridor 1.2 m wide (0.05 m cells) whose axis runs at `axis_deg` to the x
// axis, `shift` cells along it from the window's centre: two walls a cell thick, free between
// them, unknown beyond. With `pillars`, two square pillars in it and a wall across one end:
// something that pins the placement along the axis.
mapping::OccupancyGrid corridor(double axis_deg, bool pillars, double shift = 0.0) {
  constexpr int kSide = 300;
  mapping::OccupancyGrid g(core::GridGeometry(0.05, kSide, kSide));
  const double c = std::cos(core::deg2rad(axis_deg)), s = std::sin(core::deg2rad(axis_deg));
  const Eigen::Vector2d centre(kSide / 2.0, kSide / 2.0);
  for (int y = 0; y < kSide; ++y) {
    for (int x = 0; x < kSide; ++x) {
      const Eigen::Vector2d d = Eigen::Vector2d(x, y) - centre;
      const double along = c * d.x() + s * d.y() + shift, across = -s * d.x() + c * d.y();
      if (std::abs(along - shift) > 120.0) continue;
      const bool end_wall = pillars && along < -118.5;
      const bool pillar = pillars && std::abs(across) < 3.0 && (std::abs(along - 40.0) < 3.0 || std::abs(along + 60.0) < 3.0);
      if (std::abs(across) < 12.5 && !end_wall && !pillar) g.set_state({x, y}, mapping::CellState::Free);
      else if (std::abs(across) < 13.5 || (pillar && !end_wall) || (end_wall && std::abs(across) < 13.5))
        g.set_state({x, y}, mapping::CellState::Occupied);
    }
  }
  return g;
}

// A corridor's walls pin its placement across it and not along it: the largest standard deviation
// of where b's points land lies along the corridor's axis (to a few degrees, at any axis angle) and
// is many times the smallest. b is a window 40 cells farther along (its walls' ends lie on a's
// walls, as two robots' windows' do). With pillars and an end wall both are small and within a
// factor of a few of each other, and the translation is known to a fraction of a cell.
TEST(FitCovariance, ACorridorLeavesItsAxisUncertainAndPillarsPinIt) {
  for (const double axis : {0.0, 30.0, 115.0}) {
    const auto bare = corridor(axis, false), farther = corridor(axis, false, 40.0);
    const PreparedGrid a(bare), b(farther);
    const core::Transform2 truth(40.0 * std::cos(core::deg2rad(axis)), 40.0 * std::sin(core::deg2rad(axis)), 0.0);
    const auto cov = fit_covariance(a, b, truth);
    ASSERT_TRUE(cov.has_value()) << axis;
    const Uncertainty u = describe_uncertainty(*cov, truth, Eigen::Vector2d(150.0, 150.0));
    EXPECT_NEAR(std::remainder(u.major_deg - axis, 180.0), 0.0, 3.0) << axis;
    EXPECT_GT(u.std_major, 10.0 * u.std_minor) << axis;
    EXPECT_LT(u.std_minor, 0.3) << axis;

    const auto fixed = corridor(axis, true);
    const PreparedGrid fa(fixed), fb(fixed);
    const auto pinned = fit_covariance(fa, fb, core::Transform2::identity());
    ASSERT_TRUE(pinned.has_value()) << axis;
    const Uncertainty p = describe_uncertainty(*pinned, core::Transform2::identity(), Eigen::Vector2d(150.0, 150.0));
    EXPECT_LT(p.std_major, 4.0 * p.std_minor) << axis;
    EXPECT_LT(p.std_major, 0.3) << axis;
  }
}

// The covariance follows the transform between frames: the same fit moved by fixed transforms
// (as a cut map's result is moved to the full map's cells) gives the covariance of the moved
// parameters, which for a pure shift before the transform turns theta's variance into translation.
TEST(FitCovariance, PropagatesThroughAFixedShiftAsItsJacobianSays) {
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  cov(2, 2) = 1e-4;  // theta only
  const core::Transform2 t(5.0, -2.0, 0.3);
  const core::Transform2 shift(100.0, 0.0, 0.0);
  // T' = T * shift: t' = t + R(theta) (100, 0), so d t' / d theta = 100 (-sin, cos).
  const Eigen::Matrix3d moved = propagate_covariance(cov, t, [&](const core::Transform2& x) { return x * shift; });
  EXPECT_NEAR(moved(0, 0), 1e-4 * std::pow(100.0 * std::sin(0.3), 2), 1e-6);
  EXPECT_NEAR(moved(1, 1), 1e-4 * std::pow(100.0 * std::cos(0.3), 2), 1e-6);
  EXPECT_NEAR(moved(2, 2), 1e-4, 1e-10);
}

}  // namespace
}  // namespace fleetmap::merging
