#include "merging/overlap_search.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>

#include "core/angle.h"
#include "merging/evaluation.h"
#include "merging/grid_level.h"
#include "tests/merging/merging_test_support.h"

namespace fleetmap::merging {
namespace {

double angle_gap_deg(double a, double b) { return std::abs(core::rad2deg(core::normalize_angle(a - b))); }

// On maps with straight walls the spectra give the true rotation among few candidates, and the
// FFT correlation then puts a candidate within a few cells of the truth.
TEST(OverlapSearch, SpectralCandidatesAndCorrelationFindTheTruthOnWalledMaps) {
  core::Random random(21);
  for (const char* name : {"office", "corridor", "maze", "campus"}) {
    const auto source = testing::source_map(name);
    const CropPair pair = make_crop_pair(source, testing::half_overlap_crops(source), random);
    const PreparedGrid a(pair.a), b(pair.b);
    OverlapSearchOptions o;
    const auto rotations = spectral_rotation_candidates(a, b, o);
    EXPECT_LE(rotations.size(), std::size_t(2 * o.spectrum_peaks));
    double best_gap = 180.0;
    for (double r : rotations) best_gap = std::min(best_gap, angle_gap_deg(r, pair.b_to_a.rotation()));
    EXPECT_LT(best_gap, 1.5) << name;
    const auto hypotheses = overlap_hypotheses(a, b, o);
    double best_error = 1e9;
    for (const auto& h : hypotheses) {
      const TransformError e = transform_error(h.b_to_a, pair.b_to_a, pair.overlap_centre_b);
      if (e.rotation_deg < 1.5) best_error = std::min(best_error, e.translation_cells);
    }
    // One cell of the search level, plus the rotation error over the crop.
    const double level_cell = a.level(hypotheses.front().level).factor;
    EXPECT_LT(best_error, 2.0 * level_cell + 3.0) << name;
  }
}

TEST(OverlapSearch, TheSweepCoversEveryRotation) {
  const auto source = testing::source_map("cave");
  core::Random random(4);
  const CropPair pair = make_crop_pair(source, testing::half_overlap_crops(source), random);
  const PreparedGrid a(pair.a), b(pair.b);
  OverlapSearchOptions o;
  o.sweep_step_deg = 10.0;
  o.translation_peaks = 1;
  o.max_hypotheses = 1000;
  std::set<double> degrees;
  for (const auto& h : overlap_hypotheses(a, b, o)) degrees.insert(core::rad2deg(h.b_to_a.rotation()));
  ASSERT_GE(degrees.size(), 30u);
  // Sweep angles near a spectral candidate are left out: gaps stay under two steps.
  double previous = *degrees.rbegin() - 360.0, widest = 0.0;
  for (double d : degrees) widest = std::max(widest, d - previous), previous = d;
  EXPECT_LT(widest, 2.0 * o.sweep_step_deg);
}

// Rotations a half turn apart share b's transforms (the second is a convolution with the first's
// turned map): searched together they find the translations each finds alone, with the same
// scores up to the resampling of the turned map (a 32nd of a cell).
TEST(OverlapSearch, RotationsAHalfTurnApartFindWhatEachFindsAlone) {
  core::Random random(8);
  const auto source = testing::source_map("office");
  const CropPair pair = make_crop_pair(source, testing::half_overlap_crops(source), random);
  const PreparedGrid a(pair.a), b(pair.b);
  OverlapSearchOptions o;
  o.translation_peaks = 3;
  const double theta = pair.b_to_a.rotation() + 0.3;  // one at the truth's turn + pi (after the 0.3)
  const std::vector<double> both{theta, core::normalize_angle(theta + std::numbers::pi), pair.b_to_a.rotation()};
  const auto together = overlap_hypotheses_at(a, b, both, o);
  std::vector<Hypothesis> alone;
  for (double r : both) {
    const auto one = overlap_hypotheses_at(a, b, {r}, o);
    alone.insert(alone.end(), one.begin(), one.end());
  }
  ASSERT_EQ(together.size(), alone.size());
  double best = 0.0;
  for (const auto& h : alone) best = std::max(best, h.score);
  for (const auto& h : alone) {
    // The same translation at the same rotation, scored within 2% of the best score.
    bool seen = false;
    for (const auto& t : together) {
      seen = seen || (angle_gap_deg(t.b_to_a.rotation(), h.b_to_a.rotation()) < 1e-6 &&
                      (t.b_to_a.translation() - h.b_to_a.translation()).norm() < 1e-6 &&
                      std::abs(t.score - h.score) < 0.02 * best);
    }
    EXPECT_TRUE(seen) << core::rad2deg(h.b_to_a.rotation()) << " deg at " << h.b_to_a.translation().transpose()
                      << ", score " << h.score;
  }
}

}  // namespace
}  // namespace fleetmap::merging
