#include "localization/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "core/error.h"

namespace fleetmap::localization {
namespace {

// Printed chi-square tables (e.g. NIST/SEMATECH e-Handbook, table 1.3.6.7.4), 3 decimals.
struct Tabulated {
  double dof, p, value;
};
constexpr Tabulated kTable[] = {
    {1, 0.975, 5.024},   {2, 0.025, 0.051},   {2, 0.975, 7.378},   {2, 0.99, 9.210},    {2, 0.999, 13.816},
    {3, 0.025, 0.216},   {3, 0.975, 9.348},   {5, 0.025, 0.831},   {5, 0.975, 12.833},  {10, 0.025, 3.247},
    {10, 0.975, 20.483}, {20, 0.025, 9.591},  {20, 0.975, 34.170}, {30, 0.025, 16.791}, {30, 0.975, 46.979},
    {50, 0.025, 32.357}, {50, 0.975, 71.420}, {100, 0.025, 74.222}, {100, 0.975, 129.561},
};

TEST(ChiSquareQuantile, MatchesPrintedTables) {
  for (const auto& t : kTable) {
    EXPECT_NEAR(chi_square_quantile(t.dof, t.p), t.value, 6e-4) << "dof " << t.dof << " p " << t.p;
  }
  EXPECT_NEAR(chi_square_quantile(1, 0.025), 0.000982, 1e-6);
  EXPECT_THROW(chi_square_quantile(0, 0.5), std::domain_error);
  EXPECT_THROW(chi_square_quantile(3, 1.0), std::domain_error);
}

TEST(AverageChiSquareBand, IsTheChiSquareBandOfTheSumDividedByTheCount) {
  // One 3-dof NEES value: the chi2(3) band itself.
  const ChiSquareBand one = average_chi_square_band(3, 1);
  EXPECT_NEAR(one.lower, 0.216, 6e-4);
  EXPECT_NEAR(one.upper, 9.348, 6e-4);
  // 10 steps of a 3-dof state: chi2(30) / 10.
  const ChiSquareBand ten = average_chi_square_band(3, 10);
  EXPECT_NEAR(ten.lower, 1.6791, 6e-5);
  EXPECT_NEAR(ten.upper, 4.6979, 6e-5);
  // 100 samples of 1 dof: chi2(100) / 100.
  const ChiSquareBand hundred = average_chi_square_band(1, 100);
  EXPECT_NEAR(hundred.lower, 0.74222, 6e-6);
  EXPECT_NEAR(hundred.upper, 1.29561, 6e-6);
  // A long run: the band narrows around the dof, roughly +-1.96 sqrt(2 dof / K).
  const ChiSquareBand long_run = average_chi_square_band(3, 100000);
  EXPECT_NEAR(long_run.lower, 3.0 - 1.96 * std::sqrt(6.0 / 100000), 1e-3);
  EXPECT_NEAR(long_run.upper, 3.0 + 1.96 * std::sqrt(6.0 / 100000), 1e-3);
  EXPECT_TRUE(long_run.contains(3.0));
  EXPECT_FALSE(long_run.contains(3.1));
  EXPECT_THROW(average_chi_square_band(3, 0), std::domain_error);
  EXPECT_THROW(average_chi_square_band(3, 10, 1.0), std::domain_error);
}

TEST(PoseError, WrapsTheHeading) {
  const Eigen::Vector3d e = pose_error({1.0, 2.0, 3.1}, {0.5, 2.5, -3.1});
  EXPECT_NEAR(e(0), 0.5, 1e-12);
  EXPECT_NEAR(e(1), -0.5, 1e-12);
  EXPECT_NEAR(e(2), 6.2 - 2.0 * std::numbers::pi, 1e-12);
}

TEST(Nees, UsesTheInverseCovarianceAndRefusesASingularOne) {
  const Eigen::Vector3d e(0.2, -0.1, 0.05);
  const Eigen::Matrix3d p = Eigen::Vector3d(0.04, 0.01, 0.0025).asDiagonal();
  EXPECT_NEAR(*nees(e, p), 1.0 + 1.0 + 1.0, 1e-12);
  EXPECT_NEAR(dalfonso_mu_term(e, p), 0.04 * 0.04 + 0.01 * 0.01 + 0.0025 * 0.0025, 1e-15);
  EXPECT_FALSE(nees(e, Eigen::Matrix3d::Zero()).has_value());
  Eigen::Matrix3d indefinite = p;
  indefinite(2, 2) = -1.0;
  EXPECT_FALSE(nees(e, indefinite).has_value());
}

TEST(LocalizationMetrics, SummarisesARun) {
  LocalizationMetrics m;
  const Eigen::Matrix3d p = Eigen::Vector3d(0.01, 0.01, 0.0001).asDiagonal();
  m.add({0, 0, 0}, {0.1, 0.0, 0.0}, p);    // e = (-0.1, 0, 0): NEES 1, mu 1e-4
  m.add({1, 1, 0}, {1.0, 1.2, 0.01}, p);   // e = (0, -0.2, -0.01): NEES 4 + 1 = 5
  m.add({2, 2, 0.5}, {2.0, 2.0, 0.5}, p);  // e = 0
  const LocalizationSummary s = m.summary();
  EXPECT_EQ(s.steps, 3);
  EXPECT_NEAR(s.position_rmse, std::sqrt((0.01 + 0.04) / 3.0), 1e-12);
  EXPECT_NEAR(s.heading_rmse, std::sqrt(1e-4 / 3.0), 1e-12);
  ASSERT_TRUE(s.average_nees.has_value());
  EXPECT_NEAR(*s.average_nees, 2.0, 1e-9);
  EXPECT_EQ(s.nees_steps, 3);
  EXPECT_NEAR(s.nees_band.lower, average_chi_square_band(3, 3).lower, 1e-12);
  EXPECT_TRUE(s.nees_inside_band);
  EXPECT_NEAR(s.dalfonso_mu, (0.01 * 0.01 + 0.04 * 0.01 + 1e-4 * 1e-4) / 3.0, 1e-15);
}

TEST(LocalizationMetrics, ReportsNoNeesForAZeroCovarianceAndNeedsASample) {
  LocalizationMetrics m;
  EXPECT_THROW(m.summary(), Error);
  m.add({0, 0, 0}, {0, 0, 0}, Eigen::Matrix3d::Zero());  // the `ideal` localizer
  const LocalizationSummary s = m.summary();
  EXPECT_FALSE(s.average_nees.has_value());
  EXPECT_FALSE(s.nees_inside_band);
  EXPECT_EQ(s.position_rmse, 0.0);
  EXPECT_EQ(s.dalfonso_mu, 0.0);
  EXPECT_EQ(s.nees_steps, 0);
}

// A start known exactly (P0 = 0) has no NEES; the steps after it still do.
TEST(LocalizationMetrics, AveragesTheNeesOverTheStepsWithAPositiveDefiniteCovariance) {
  LocalizationMetrics m;
  m.add({0, 0, 0}, {0, 0, 0}, Eigen::Matrix3d::Zero());
  const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() * 0.01;
  m.add({0, 0, 0}, {0.1, 0.0, 0.0}, p);  // NEES 1
  m.add({0, 0, 0}, {0.0, 0.2, 0.0}, p);  // NEES 4
  const LocalizationSummary s = m.summary();
  EXPECT_EQ(s.steps, 3);
  EXPECT_EQ(s.nees_steps, 2);
  ASSERT_TRUE(s.average_nees.has_value());
  EXPECT_NEAR(*s.average_nees, 2.5, 1e-12);
  EXPECT_NEAR(s.nees_band.upper, average_chi_square_band(3, 2).upper, 1e-12);
  EXPECT_NEAR(s.position_rmse, std::sqrt(0.05 / 3.0), 1e-12);
}

TEST(LocalizationMetrics, FlagsAnOverconfidentRun) {
  LocalizationMetrics m;
  const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() * 1e-4;  // claims 1 cm
  for (int k = 0; k < 100; ++k) m.add({0, 0, 0}, {0.1, 0.1, 0.0}, p);  // off by 14 cm
  const LocalizationSummary s = m.summary();
  ASSERT_TRUE(s.average_nees.has_value());
  EXPECT_NEAR(*s.average_nees, 200.0, 1e-9);
  EXPECT_FALSE(s.nees_inside_band);
}

}  // namespace
}  // namespace fleetmap::localization
