#include "mapping/polynomial.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/random.h"

namespace fleetmap::mapping {
namespace {

// x2 = 0.5 x1^3 - x1^2 + 0.25 x1 + 2 over [-1, 2].
Polynomial cubic(PolynomialAxis axis = PolynomialAxis::X1) { return {axis, {0.5, -1.0, 0.25}, 2.0, -1.0, 2.0}; }

TEST(PolynomialLandmark, ValueSlopeAndPointsOfBothVariates) {
  const Polynomial p = cubic();
  EXPECT_DOUBLE_EQ(p.value(2.0), 0.5 * 8 - 4 + 0.5 + 2);
  EXPECT_DOUBLE_EQ(p.slope(2.0), 1.5 * 4 - 4 + 0.25);
  EXPECT_TRUE(p.point(1.0).isApprox(Eigen::Vector2d(1.0, 1.75)));
  const Polynomial q = cubic(PolynomialAxis::X2);  // x1 = p(x2)
  EXPECT_TRUE(q.point(1.0).isApprox(Eigen::Vector2d(1.75, 1.0)));
  EXPECT_TRUE(q.local(Eigen::Vector2d(3.0, 4.0)).isApprox(Eigen::Vector2d(4.0, 3.0)));
  EXPECT_TRUE(q.dependent_direction().isApprox(Eigen::Vector2d(1.0, 0.0)));
  // A straight line's length is exact.
  const Polynomial line{PolynomialAxis::X1, {0.0, 0.0, 0.75}, 1.0, 0.0, 4.0};
  EXPECT_NEAR(line.length(), 5.0, 1e-12);
}

TEST(PolynomialLandmark, LmsFitRecoversAKnownCubicFromNoisyPoints) {
  core::Random rng(11);
  for (const PolynomialAxis axis : {PolynomialAxis::X1, PolynomialAxis::X2}) {
    const Polynomial truth = cubic(axis);
    std::vector<WeightedPoint> points;
    constexpr double kNoise = 0.01;
    constexpr int kPoints = 400;
    for (int k = 0; k < kPoints; ++k) {
      const double xi = rng.uniform(truth.lo, truth.hi);
      const Eigen::Vector2d local(xi, truth.value(xi) + rng.normal(0.0, kNoise));
      points.push_back({truth.world(local), 1.0});
    }
    const auto fit = fit_polynomial(points, 3, axis);
    ASSERT_TRUE(fit.has_value());
    EXPECT_EQ(fit->polynomial.axis, axis);
    // The residual is the noise; the curve is within a few standard errors (sigma / sqrt(n) scale).
    EXPECT_NEAR(fit->rms_residual, kNoise, 0.15 * kNoise);
    for (double xi = -1.0; xi <= 2.0; xi += 0.05) EXPECT_NEAR(fit->polynomial.value(xi), truth.value(xi), 0.006) << xi;
    for (std::size_t i = 0; i < truth.shape.size(); ++i) EXPECT_NEAR(fit->polynomial.shape[i], truth.shape[i], 0.02) << i;
    EXPECT_NEAR(fit->polynomial.position, truth.position, 0.01);
    EXPECT_NEAR(fit->polynomial.lo, -1.0, 0.05);
    EXPECT_NEAR(fit->polynomial.hi, 2.0, 0.05);
  }
}

TEST(PolynomialLandmark, FitFarFromTheOriginKeepsItsPrecision) {
  // Centring and scaling: a cubic over [100, 101] is recovered from exact points.
  const Polynomial truth{PolynomialAxis::X1, {0.3, -90.0, 9000.5}, -299000.0, 100.0, 101.0};
  std::vector<WeightedPoint> points;
  for (int k = 0; k <= 20; ++k) points.push_back({truth.point(100.0 + k / 20.0), 1.0});
  const auto fit = fit_polynomial(points, 3, PolynomialAxis::X1);
  ASSERT_TRUE(fit.has_value());
  for (int k = 0; k <= 20; ++k) EXPECT_NEAR(fit->polynomial.value(100.0 + k / 20.0), truth.value(100.0 + k / 20.0), 1e-6);
}

TEST(PolynomialLandmark, WeightsPullTheFit) {
  // Two parallel clouds, y = 0 and y = 1: the fit follows the weight.
  std::vector<WeightedPoint> points;
  for (int k = 0; k <= 10; ++k) {
    points.push_back({{0.1 * k, 0.0}, 9.0});
    points.push_back({{0.1 * k, 1.0}, 1.0});
  }
  const auto fit = fit_polynomial(points, 1, PolynomialAxis::X1);
  ASSERT_TRUE(fit.has_value());
  EXPECT_NEAR(fit->polynomial.value(0.5), 0.1, 1e-9);
}

TEST(PolynomialLandmark, FitNeedsEnoughDistinctPoints) {
  const std::vector<WeightedPoint> three = {{{0, 0}, 1}, {{1, 1}, 1}, {{2, 0}, 1}};
  EXPECT_FALSE(fit_polynomial(three, 3, PolynomialAxis::X1).has_value());
  EXPECT_TRUE(fit_polynomial(three, 2, PolynomialAxis::X1).has_value());
  const std::vector<WeightedPoint> stacked = {{{1, 0}, 1}, {{1, 1}, 1}, {{1, 2}, 1}, {{1, 3}, 1}, {{1, 4}, 1}};
  EXPECT_FALSE(fit_polynomial(stacked, 1, PolynomialAxis::X1).has_value());  // a vertical line is not x1-variate
  EXPECT_TRUE(fit_polynomial(stacked, 1, PolynomialAxis::X2).has_value());
  EXPECT_EQ(principal_axis(stacked), PolynomialAxis::X2);
  EXPECT_EQ(principal_axis(three), PolynomialAxis::X1);
}

TEST(PolynomialLandmark, StrayBetweenPointsCatchesASwingingFit) {
  // Points of the line x2 = 0 in two bunches, [0, 0.1] and [1.9, 2]: p = 10 x1 (x1 - 2) passes
  // within 0.1 m of all of them (its ends) but swings 10 m away between them.
  std::vector<WeightedPoint> points;
  for (int k = 0; k <= 5; ++k) points.push_back({Eigen::Vector2d(0.02 * k, 0.0), 1.0});
  for (int k = 0; k <= 5; ++k) points.push_back({Eigen::Vector2d(1.9 + 0.02 * k, 0.0), 1.0});
  const Polynomial swing{PolynomialAxis::X1, {0.0, 10.0, -20.0}, 0.0, 0.0, 2.0};
  EXPECT_NEAR(stray_between_points(swing, points), 10.0, 1e-9);
  const auto line = fit_polynomial(points, 3, PolynomialAxis::X1);
  ASSERT_TRUE(line.has_value());
  EXPECT_LT(stray_between_points(line->polynomial, points), 1e-9);
  EXPECT_EQ(stray_between_points(swing, {}), 0.0);
}

TEST(PolynomialLandmark, ApproximationErrorOnAndOffTheDomain) {
  const Polynomial p{PolynomialAxis::X1, {0.0, 0.0, 0.0}, 1.0, 0.0, 2.0};  // x2 = 1 for x1 in [0, 2]
  // Inside the domain: the residual.
  EXPECT_DOUBLE_EQ(approximation_error(p, {0.5, 1.3}), 0.3);
  EXPECT_DOUBLE_EQ(approximation_error(p, {2.0, 0.8}), 0.2);
  // Outside: the distance to the nearer end point (Q_m = (0, 1), Q_M = (2, 1)).
  EXPECT_DOUBLE_EQ(approximation_error(p, {-0.3, 1.4}), 0.5);
  EXPECT_DOUBLE_EQ(approximation_error(p, {2.6, 1.8}), 1.0);
  // The same for an x2-variate polynomial: x1 = 1 for x2 in [0, 2].
  const Polynomial q{PolynomialAxis::X2, {0.0, 0.0, 0.0}, 1.0, 0.0, 2.0};
  EXPECT_DOUBLE_EQ(approximation_error(q, {1.3, 0.5}), 0.3);
  EXPECT_DOUBLE_EQ(approximation_error(q, {1.4, -0.3}), 0.5);
}

TEST(PolynomialLandmark, SegmentationErrorStaysBelowTheTolerance) {
  core::Random rng(5);
  for (int trial = 0; trial < 30; ++trial) {
    Polynomial p{trial % 2 ? PolynomialAxis::X2 : PolynomialAxis::X1,
                 {rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)},
                 rng.uniform(-3.0, 3.0), 0.0, 0.0};
    p.lo = rng.uniform(-2.0, 1.0);
    p.hi = p.lo + rng.uniform(0.2, 2.5);
    for (const double tolerance : {0.001, 0.005, 0.02, 0.1}) {
      const auto vertices = segment_polynomial(p, tolerance);
      ASSERT_GE(vertices.size(), 2u);
      EXPECT_TRUE(vertices.front().isApprox(p.start(), 1e-12));
      EXPECT_TRUE(vertices.back().isApprox(p.end(), 1e-12));
      for (const auto& v : vertices) EXPECT_LT(approximation_error(p, v), 1e-9);  // vertices lie on p
      // The curve, sampled far more finely than the segmentation did, never leaves the tolerance.
      double worst = 0.0;
      for (int k = 0; k <= 20000; ++k) {
        worst = std::max(worst, distance_to_polyline(p.point(p.lo + (p.hi - p.lo) * k / 20000.0), vertices));
      }
      EXPECT_LE(worst, tolerance) << p << " tolerance " << tolerance;
    }
    EXPECT_LE(segment_polynomial(p, 0.1).size(), segment_polynomial(p, 0.001).size());
  }
}

TEST(PolynomialLandmark, ArcLengthSamplesAreEquallySpaced) {
  const Polynomial p = cubic();
  const auto samples = sample_arc_length(p, 0.01);
  EXPECT_NEAR(double(samples.size() - 1), std::ceil(p.length() / 0.01), 1.0);
  for (std::size_t i = 1; i + 1 < samples.size(); ++i) EXPECT_NEAR((samples[i] - samples[i - 1]).norm(), 0.01, 1e-4);
  const auto equal = sample_equally(p, 5);
  ASSERT_EQ(equal.size(), 5u);
  EXPECT_TRUE(equal[2].isApprox(p.point(0.5)));
}

TEST(PolynomialLandmark, RealRootsInAnInterval) {
  // (t - 1)(t - 2)(t - 4) = t^3 - 7 t^2 + 14 t - 8.
  const auto roots = real_roots_in({-8.0, 14.0, -7.0, 1.0}, 0.0, 3.0);
  ASSERT_EQ(roots.size(), 2u);
  EXPECT_NEAR(roots[0], 1.0, 1e-12);
  EXPECT_NEAR(roots[1], 2.0, 1e-12);
  EXPECT_TRUE(real_roots_in({1.0, 0.0, 1.0}, -5.0, 5.0).empty());  // t^2 + 1
}

// The distance along a ray by brute force: the first sign change of the residual.
double brute_distance(const Polynomial& p, const Eigen::Vector2d& o, double angle) {
  const Eigen::Vector2d u(std::cos(angle), std::sin(angle));
  const auto f = [&](double t) {
    const Eigen::Vector2d q = p.local(o + t * u);
    return q.y() - p.value(q.x());
  };
  double prev = f(0.0);
  for (double t = 1e-4; t < 20.0; t += 1e-4) {
    const double v = f(t);
    if ((v < 0) != (prev < 0) && p.in_domain(p.local(o + t * u).x())) return t;
    prev = v;
  }
  return -1.0;
}

TEST(PolynomialLandmark, RayDistanceAndItsDerivativesEq2) {
  core::Random rng(3);
  int checked = 0;
  for (int trial = 0; trial < 200 && checked < 60; ++trial) {
    const Polynomial p{trial % 2 ? PolynomialAxis::X2 : PolynomialAxis::X1,
                       {rng.uniform(-0.2, 0.2), rng.uniform(-0.3, 0.3), rng.uniform(-0.5, 0.5)}, rng.uniform(1.0, 3.0),
                       -2.0, 2.0};
    const Eigen::Vector2d o(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
    const Eigen::Vector2d target = p.point(rng.uniform(-1.5, 1.5));
    const Eigen::Vector2d d = target - o;
    const double angle = std::atan2(d.y(), d.x()) + rng.uniform(-0.05, 0.05);
    const auto hit = intersect_ray(p, o, angle, 20.0);
    if (!hit || hit->cos_incidence < 0.3) continue;
    ++checked;
    EXPECT_NEAR(hit->distance, brute_distance(p, o, angle), 2e-4);
    const double h = 1e-6;
    const auto t_at = [&](const Polynomial& q, const Eigen::Vector2d& oo, double a) {
      const auto r = intersect_ray(q, oo, a, 20.0, 0.5);
      return r ? r->distance : std::nan("");
    };
    EXPECT_NEAR(hit->d_origin.x(), (t_at(p, o + Eigen::Vector2d(h, 0), angle) - t_at(p, o - Eigen::Vector2d(h, 0), angle)) / (2 * h), 1e-4);
    EXPECT_NEAR(hit->d_origin.y(), (t_at(p, o + Eigen::Vector2d(0, h), angle) - t_at(p, o - Eigen::Vector2d(0, h), angle)) / (2 * h), 1e-4);
    EXPECT_NEAR(hit->d_angle, (t_at(p, o, angle + h) - t_at(p, o, angle - h)) / (2 * h), 1e-3);
    Polynomial up = p, down = p;
    up.position += h;
    down.position -= h;
    EXPECT_NEAR(hit->d_position, (t_at(up, o, angle) - t_at(down, o, angle)) / (2 * h), 1e-4);
  }
  EXPECT_GE(checked, 40);
}

TEST(PolynomialLandmark, RayMissesOutsideTheDomainOrBeyondRange) {
  const Polynomial p{PolynomialAxis::X1, {0.0, 0.0, 0.0}, 1.0, 0.0, 2.0};
  EXPECT_NEAR(intersect_ray(p, {1.0, 0.0}, std::numbers::pi / 2, 5.0)->distance, 1.0, 1e-12);
  EXPECT_FALSE(intersect_ray(p, {3.0, 0.0}, std::numbers::pi / 2, 5.0).has_value());
  EXPECT_TRUE(intersect_ray(p, {2.05, 0.0}, std::numbers::pi / 2, 5.0, 0.1).has_value());
  EXPECT_FALSE(intersect_ray(p, {1.0, 0.0}, std::numbers::pi / 2, 0.5).has_value());
  EXPECT_FALSE(intersect_ray(p, {1.0, 0.0}, -std::numbers::pi / 2, 5.0).has_value());
}

TEST(PolynomialLandmark, PositionGradientIsTheOffsetFitsDerivative) {
  // c0 of the offset fit at a fixed shape, recomputed after moving one point, against the gradient.
  const Polynomial shape = cubic();
  core::Random rng(8);
  std::vector<WeightedPoint> points;
  for (int k = 0; k < 12; ++k) {
    const double xi = rng.uniform(-1.0, 2.0);
    points.push_back({{xi, shape.value(xi) + rng.normal(0.0, 0.05)}, rng.uniform(0.5, 2.0)});
  }
  const auto offset = [&](const std::vector<WeightedPoint>& pts) {
    double w = 0.0, s = 0.0;
    for (const auto& p : pts) {
      w += p.weight;
      s += p.weight * (p.position.y() - (shape.value(p.position.x()) - shape.position));
    }
    return s / w;
  };
  const auto grad = position_gradient(shape, points);
  const double h = 1e-6;
  for (std::size_t k = 0; k < points.size(); ++k) {
    for (int c = 0; c < 2; ++c) {
      auto plus = points, minus = points;
      plus[k].position(c) += h;
      minus[k].position(c) -= h;
      EXPECT_NEAR(grad[k](c), (offset(plus) - offset(minus)) / (2 * h), 1e-6);
    }
  }
}

}  // namespace
}  // namespace fleetmap::mapping
