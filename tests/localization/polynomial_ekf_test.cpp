#include "localization/polynomial_ekf.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "core/random.h"

namespace fleetmap::localization {
namespace {

Eigen::Matrix3d p0() { return Eigen::Vector3d(0.05 * 0.05, 0.05 * 0.05, 0.0175 * 0.0175).asDiagonal(); }

void expect_symmetric_psd(const Eigen::MatrixXd& p) {
  EXPECT_LT((p - p.transpose()).cwiseAbs().maxCoeff(), 1e-15) << "not symmetric";
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(p);
  EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-12 * std::max(1.0, eig.eigenvalues().maxCoeff())) << "not PSD";
}

TEST(PolynomialEkf, AugmentationIsEq4WithFullMatrices) {
  PolynomialEkf f(core::Pose2(1.0, 2.0, 0.3), p0());
  LandmarkGeneration g1;
  g1.value = 3.0;
  g1.g_pose << 0.1, 1.0, -0.4;
  g1.noise_variance = 1e-4;
  f.augment(g1);
  const Eigen::MatrixXd before = f.covariance();
  LandmarkGeneration g2;
  g2.value = -1.0;
  g2.g_pose << 1.0, -0.2, 0.7;
  g2.g_slots = {{0, 0.5}};
  g2.noise_variance = 4e-4;
  EXPECT_EQ(f.augment(g2), 1);
  // P~ = G_x P G_x^T + G_y V G_y^T with G_x = [I; g_x], G_y V G_y^T = diag(0, ..., noise).
  Eigen::MatrixXd gx = Eigen::MatrixXd::Zero(5, 4);
  gx.topLeftCorner(4, 4).setIdentity();
  gx.row(4) << 1.0, -0.2, 0.7, 0.5;
  Eigen::MatrixXd expected = gx * before * gx.transpose();
  expected(4, 4) += 4e-4;
  EXPECT_TRUE(f.covariance().isApprox(expected, 1e-12));
  EXPECT_DOUBLE_EQ(f.position(1), -1.0);
}

TEST(PolynomialEkf, AugmentedCovarianceStaysSymmetricPositiveSemiDefinite) {
  // Random predicts, scalar updates, augmentations (from the pose and from other slots) and removals.
  core::Random rng(21);
  PolynomialEkf f(core::Pose2(), p0());
  const Eigen::Matrix3d q = Eigen::Vector3d(1e-6, 1e-6, 3e-8).asDiagonal();
  for (int step = 0; step < 400; ++step) {
    f.predict({rng.uniform(0.0, 0.5), rng.uniform(-0.5, 0.5), 1.0}, q);
    if (f.slots() < 30 && rng.bernoulli(0.3)) {
      LandmarkGeneration g;
      g.value = rng.uniform(-5.0, 5.0);
      g.g_pose << rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-3.0, 3.0);
      if (f.slots() > 1 && rng.bernoulli(0.5)) {
        g.g_slots = {{rng.uniform_int(0, f.slots() - 1), rng.uniform(0.2, 0.8)}};
      }
      g.noise_variance = rng.uniform(0.0, 1e-3);
      f.augment(g);
    }
    if (f.slots() > 3 && rng.bernoulli(0.1)) f.remove({rng.uniform_int(0, f.slots() - 1)});
    for (int r = 0; r < 5 && f.slots() > 0; ++r) {
      ScalarReading z;
      z.slot = rng.uniform_int(0, f.slots() - 1);
      z.h_pose << rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-2.0, 2.0);
      z.h_slot = rng.uniform(0.5, 1.5);
      z.predicted = 1.0;
      z.noise = 4e-4;
      f.update(1.0 + rng.normal(0.0, 0.02), z);
    }
    expect_symmetric_psd(f.covariance());
    if (::testing::Test::HasFailure()) break;
  }
}

TEST(PolynomialEkf, JosephUpdateMatchesTheKalmanFormula) {
  PolynomialEkf f(core::Pose2(0.5, -0.5, 0.1), p0());
  LandmarkGeneration g;
  g.value = 2.0;
  g.g_pose << 0.0, 1.0, 0.8;
  g.noise_variance = 2e-4;
  f.augment(g);
  const Eigen::MatrixXd p = f.covariance();
  const Eigen::VectorXd x = f.mean();
  ScalarReading z;
  z.predicted = 1.4;
  z.h_pose << 0.1, -1.0, 0.3;
  z.slot = 0;
  z.h_slot = 1.0;
  z.noise = 4e-4;
  Eigen::RowVectorXd h(4);
  h << 0.1, -1.0, 0.3, 1.0;
  const double s = (h * p * h.transpose())(0) + z.noise;
  EXPECT_NEAR(f.innovation_variance(z), s, 1e-15);
  const Eigen::VectorXd k = p * h.transpose() / s;
  f.update(1.45, z);
  EXPECT_TRUE(f.mean().isApprox(x + k * 0.05, 1e-12));
  EXPECT_TRUE(f.covariance().isApprox(p - k * s * k.transpose(), 1e-12));
}

// The update through a reading model: the same step as update(z, r) when the reading still sees
// its landmark at the updated state; nothing changes when the innovation fails the gate, or when
// the step takes the state where the reading no longer sees its landmark (here: beyond x = 0.03).
TEST(PolynomialEkf, AModelledReadingUpdatesOnlyWhenItStillSeesItsLandmarkAfterTheStep) {
  const auto model = [](const Eigen::VectorXd& x) -> std::optional<ScalarReading> {
    if (x(0) > 0.03) return std::nullopt;
    ScalarReading r;
    r.predicted = 1.0 - x(0);
    r.h_pose << -1.0, 0.0, 0.0;
    r.noise = 4e-4;
    return r;
  };
  PolynomialEkf plain(core::Pose2(), p0()), modelled(core::Pose2(), p0());
  plain.update(0.98, *model(plain.mean()));
  EXPECT_EQ(modelled.update(0.98, model, 3.84), PolynomialEkf::UpdateOutcome::Updated);
  EXPECT_TRUE(modelled.mean().isApprox(plain.mean(), 1e-15));
  EXPECT_TRUE(modelled.covariance().isApprox(plain.covariance(), 1e-15));
  // nu = -0.09 against S = 0.0029: nu^2 / S = 2.8 passes the gate, but the step goes to x = 0.078.
  PolynomialEkf lost(core::Pose2(), p0());
  EXPECT_EQ(lost.update(0.91, model, 3.84), PolynomialEkf::UpdateOutcome::Lost);
  EXPECT_TRUE(lost.mean().isZero());
  EXPECT_TRUE(lost.covariance().isApprox(p0()));
  EXPECT_EQ(lost.update(0.91, model, 2.0), PolynomialEkf::UpdateOutcome::Gated);
  EXPECT_TRUE(lost.covariance().isApprox(p0()));
}

TEST(PolynomialEkf, RemovalDropsRowsAndColumns) {
  PolynomialEkf f(core::Pose2(), p0());
  for (int i = 0; i < 4; ++i) {
    LandmarkGeneration g;
    g.value = i;
    g.g_pose << 0.0, 1.0, 0.0;
    g.noise_variance = 1e-4 * (i + 1);
    f.augment(g);
  }
  const Eigen::MatrixXd before = f.covariance();
  f.remove({1, 2});
  ASSERT_EQ(f.slots(), 2);
  EXPECT_DOUBLE_EQ(f.position(0), 0.0);
  EXPECT_DOUBLE_EQ(f.position(1), 3.0);
  EXPECT_DOUBLE_EQ(f.covariance()(4, 4), before(6, 6));
  EXPECT_DOUBLE_EQ(f.covariance()(3, 4), before(3, 6));
}

TEST(PolynomialEkf, DivergenceTestIsPAboveKP0) {
  EXPECT_FALSE(is_diverging(p0(), 150.0, p0()));
  EXPECT_FALSE(is_diverging(149.0 * p0(), 150.0, p0()));
  Eigen::Matrix3d p = p0();
  p(2, 2) *= 151.0;  // one direction beyond K P0 is enough
  EXPECT_TRUE(is_diverging(p, 150.0, p0()));
}

}  // namespace
}  // namespace fleetmap::localization
