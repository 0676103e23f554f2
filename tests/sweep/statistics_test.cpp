#include "sweep/statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace fleetmap::sweep {
namespace {

TEST(Statistics, StudentTCriticalValuesMatchTheTables) {
  // Two-sided 95%: t(0.975, dof) from any statistics table.
  EXPECT_NEAR(student_t_critical(1), 12.7062, 1e-4);
  EXPECT_NEAR(student_t_critical(4), 2.7764, 1e-4);
  EXPECT_NEAR(student_t_critical(9), 2.2622, 1e-4);
  EXPECT_NEAR(student_t_critical(19), 2.0930, 1e-4);
  EXPECT_NEAR(student_t_critical(100000), 1.95997, 1e-4);
  EXPECT_NEAR(student_t_critical(9, 0.99), 3.2498, 1e-4);
  EXPECT_THROW(student_t_critical(0), std::invalid_argument);
}

TEST(Statistics, SummaryHasTheMeanSampleDeviationAndTInterval) {
  const std::vector<double> v = {2, 4, 4, 4, 5, 5, 7, 9};
  const SampleSummary s = summarize(v);
  EXPECT_EQ(s.n, 8);
  EXPECT_DOUBLE_EQ(s.mean, 5.0);
  EXPECT_NEAR(s.sd, std::sqrt(32.0 / 7.0), 1e-12);  // n - 1 in the denominator
  const double half = 2.364624 * std::sqrt(32.0 / 7.0) / std::sqrt(8.0);  // t(0.975, 7)
  EXPECT_NEAR(s.ci_low, 5.0 - half, 1e-5);
  EXPECT_NEAR(s.ci_high, 5.0 + half, 1e-5);
  EXPECT_NEAR(s.half_width(), half, 1e-5);
}

TEST(Statistics, SmallAndNonFiniteSamples) {
  const SampleSummary none = summarize(std::vector<double>{});
  EXPECT_EQ(none.n, 0);
  EXPECT_TRUE(std::isnan(none.mean));
  const SampleSummary one = summarize(std::vector<double>{3.5, NAN});
  EXPECT_EQ(one.n, 1);
  EXPECT_DOUBLE_EQ(one.mean, 3.5);
  EXPECT_TRUE(std::isnan(one.sd));
  EXPECT_TRUE(std::isnan(one.ci_low));
  const SampleSummary same = summarize(std::vector<double>{2, 2, 2, INFINITY});
  EXPECT_EQ(same.n, 3);
  EXPECT_DOUBLE_EQ(same.sd, 0.0);
  EXPECT_DOUBLE_EQ(same.ci_low, 2.0);
  EXPECT_DOUBLE_EQ(same.ci_high, 2.0);
}

TEST(Statistics, PairedComparisonOfKnownDifferences) {
  // Differences 1..5: mean 3, sd sqrt(2.5), t = 3 / (sqrt(2.5) / sqrt(5)) = sqrt(18); with 4 degrees of
  // freedom the two-sided p is 2 * (1 - F(sqrt(18))) = 0.013243 (closed form of the t(4) CDF).
  const std::vector<double> a = {11, 12, 13, 14, 15}, b = {10, 10, 10, 10, 10};
  const PairedComparison c = compare_paired(a, b);
  EXPECT_EQ(c.difference.n, 5);
  EXPECT_DOUBLE_EQ(c.difference.mean, 3.0);
  EXPECT_NEAR(c.t, std::sqrt(18.0), 1e-12);
  EXPECT_NEAR(c.p_value, 0.013243, 1e-5);
  EXPECT_NEAR(c.difference.ci_low, 3.0 - 2.776445 * std::sqrt(2.5 / 5.0), 1e-5);
  EXPECT_EQ(c.a_lower, 0);
  EXPECT_EQ(c.b_lower, 5);
  EXPECT_EQ(c.ties, 0);
  // Swapping the methods flips the sign, not the p value.
  const PairedComparison back = compare_paired(b, a);
  EXPECT_DOUBLE_EQ(back.difference.mean, -3.0);
  EXPECT_NEAR(back.p_value, c.p_value, 1e-12);
  EXPECT_EQ(back.a_lower, 5);
}

TEST(Statistics, PairedComparisonLeavesOutIncompletePairs) {
  const std::vector<double> a = {1, 2, NAN, 4}, b = {1, 3, 5, NAN};
  const PairedComparison c = compare_paired(a, b);
  EXPECT_EQ(c.difference.n, 2);
  EXPECT_EQ(c.ties, 1);
  EXPECT_EQ(c.a_lower, 1);
  const PairedComparison constant = compare_paired(std::vector<double>{5, 6, 7}, std::vector<double>{4, 5, 6});
  EXPECT_DOUBLE_EQ(constant.difference.sd, 0.0);
  EXPECT_EQ(constant.p_value, 0.0);
  EXPECT_THROW(compare_paired(std::vector<double>{1}, std::vector<double>{1, 2}), std::invalid_argument);
}

}  // namespace
}  // namespace fleetmap::sweep
