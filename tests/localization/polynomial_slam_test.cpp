#include "localization/polynomial_slam.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <limits>
#include <numbers>

#include "core/angle.h"
#include "core/random.h"
#include "localization/localizer.h"
#include "tests/test_support.h"

namespace fleetmap::localization {
namespace {

Eigen::Matrix3d initial_pose_covariance() { return Eigen::Vector3d(0.05 * 0.05, 0.05 * 0.05, 0.0175 * 0.0175).asDiagonal(); }

// Exact readings inside an axis-aligned rectangle [0, w] x [0, h].
std::optional<double> rectangle_range(const core::Pose2& pose, double angle, double w, double h, double max_range) {
  const double a = pose.theta + angle;
  const double c = std::cos(a), s = std::sin(a);
  double t = std::numeric_limits<double>::infinity();
  if (c > 1e-12) t = std::min(t, (w - pose.x) / c);
  if (c < -1e-12) t = std::min(t, -pose.x / c);
  if (s > 1e-12) t = std::min(t, (h - pose.y) / s);
  if (s < -1e-12) t = std::min(t, -pose.y / s);
  if (!(t <= max_range)) return std::nullopt;
  return t;
}

// Distance from a point to the rectangle's boundary.
double to_rectangle(const Eigen::Vector2d& p, double w, double h) {
  const double dx = std::min(std::abs(p.x()), std::abs(p.x() - w));
  const double dy = std::min(std::abs(p.y()), std::abs(p.y() - h));
  const bool inside_x = p.x() >= 0 && p.x() <= w, inside_y = p.y() >= 0 && p.y() <= h;
  if (inside_x && inside_y) return std::min(dx, dy);
  if (inside_x) return dy;
  if (inside_y) return dx;
  return std::hypot(dx, dy);
}

// The largest distance to the rectangle's walls of the inner 90% of each polynomial's domain, seen
// from the true pose as the filter sees it from its estimate (map and pose share a frame whose
// offset from the room's is only known to P0: the map is judged relative to the pose). The ends
// are left out: a wall's polynomial may run a few millimetres round a corner.
// `room_from_frame` brings map and estimate back into the room's frame after a change of frame.
double map_error_seen_from_pose(const mapping::PolynomialMap& map, const core::Pose2& estimate, const core::Pose2& truth,
                                double w, double h, const core::Transform2& room_from_frame = {}) {
  const core::Transform2 fix = truth.as_transform() * (room_from_frame * estimate.as_transform()).inverse() * room_from_frame;
  double worst = 0.0;
  for (const auto& l : map.landmarks) {
    const auto& p = l.polynomial;
    const double margin = 0.05 * (p.hi - p.lo);
    for (const auto& q : mapping::sample_equally(p, p.lo + margin, p.hi - margin, 50)) worst = std::max(worst, to_rectangle(fix * q, w, h));
  }
  return worst;
}

const std::vector<double> kFiveSensors = {-std::numbers::pi / 2, -std::numbers::pi / 4, 0.0, std::numbers::pi / 4,
                                          std::numbers::pi / 2};

TEST(PolynomialSlam, ThresholdsFollowTheCovarianceUpToKP0) {
  PolynomialSlamOptions o;
  const SlamThresholds at_p0 = slam_thresholds(initial_pose_covariance(), initial_pose_covariance(), o);
  EXPECT_NEAR(at_p0.factor, 1.0 / 150.0, 1e-12);
  EXPECT_NEAR(at_p0.rho, 0.08 + 0.16 / 150.0, 1e-12);
  EXPECT_NEAR(at_p0.sigma, 0.1 + 0.2 / 150.0, 1e-12);
  EXPECT_FALSE(at_p0.diverging);
  const SlamThresholds half = slam_thresholds(75.0 * initial_pose_covariance(), initial_pose_covariance(), o);
  EXPECT_NEAR(half.rho, 0.16, 1e-12);
  EXPECT_NEAR(half.sigma, 0.2, 1e-12);
  const SlamThresholds beyond = slam_thresholds(200.0 * initial_pose_covariance(), initial_pose_covariance(), o);
  EXPECT_TRUE(beyond.diverging);
  EXPECT_DOUBLE_EQ(beyond.rho, 0.24);
  EXPECT_DOUBLE_EQ(beyond.sigma, 0.3);
}

TEST(PolynomialSlam, NoiseFreeRobotMapsARectangleAndStaysWhereItIs) {
  // A robot turning in place in a 4 x 3 m room with exact readings: every wall becomes polynomials
  // lying on it, and the pose estimate does not move away from the truth.
  PolynomialSlamOptions o;
  o.range_noise = 0.005;
  o.cluster_tolerance = 0.001;
  const core::Pose2 start(1.5, 1.2, 0.3);
  PolynomialSlam slam(start, initial_pose_covariance(), Eigen::Matrix3d::Zero(), o);
  core::Pose2 truth = start;
  for (int k = 0; k < 300; ++k) {
    if (k > 0) {
      const Odometry u{0.0, 0.1, 1.0};
      slam.predict(u);
      truth = integrate_motion(truth, u);
    }
    std::vector<std::optional<double>> ranges;
    for (double a : kFiveSensors) ranges.push_back(rectangle_range(truth, a, 4.0, 3.0, 3.0));
    slam.update(kFiveSensors, ranges);
  }
  // The frame itself is anchored only by P0 (sigma 5 cm): a polynomial made of points round a corner
  // can shift pose and map together by a few centimetres, never apart.
  EXPECT_LT((slam.pose().position() - truth.position()).norm(), 3 * 0.05);
  EXPECT_LT(std::abs(core::normalize_angle(slam.pose().theta - truth.theta)), 1e-3);
  ASSERT_GE(slam.map().landmarks.size(), 4u);
  // Exact readings: the map is off only where a corner point bent a polynomial (a few mm).
  EXPECT_LT(map_error_seen_from_pose(slam.map(), slam.pose(), truth, 4.0, 3.0), 5e-3);
  EXPECT_GT(slam.counters().updates, 500);
  EXPECT_EQ(slam.counters().diverged_steps, 0);
}

// A filter at the origin facing +x2 that has mapped the wall x2 = 2 over x1 in [-0.5, 0.5] from
// eleven exact readings (one cluster of epsilon_Z + 1 points).
PolynomialSlam facing_a_wall(const PolynomialSlamOptions& o) {
  PolynomialSlam slam(core::Pose2(0.0, 0.0, std::numbers::pi / 2), initial_pose_covariance(), Eigen::Matrix3d::Zero(), o);
  std::vector<double> angles;
  std::vector<std::optional<double>> ranges;
  for (int i = -5; i <= 5; ++i) {
    const double x = 0.1 * i;
    angles.push_back(std::atan2(2.0, x) - std::numbers::pi / 2);
    ranges.push_back(std::hypot(x, 2.0));
  }
  slam.update(angles, ranges);
  return slam;
}

TEST(PolynomialSlam, BadlyApproximatedPointsRefitTheirPolynomial) {
  PolynomialSlamOptions o;
  o.cluster_tolerance = 0.001;
  PolynomialSlam slam = facing_a_wall(o);
  ASSERT_EQ(slam.map().landmarks.size(), 1u);
  const long first_id = slam.map().landmarks[0].id;
  EXPECT_NEAR(slam.map().landmarks[0].polynomial.value(0.0), 2.0, 1e-9);
  // Readings 9 cm beyond the polynomial: rho_k < eps <= sigma_k, so they go to Q_bad; past
  // epsilon_M of them the polynomial is refitted on Q_bad and R, and replaced.
  std::vector<double> angles;
  std::vector<std::optional<double>> ranges;
  for (int i = -3; i <= 2; ++i) {
    const double x = 0.15 * i;
    angles.push_back(std::atan2(2.09, x) - std::numbers::pi / 2);
    ranges.push_back(std::hypot(x, 2.09));
  }
  slam.update(angles, ranges);
  EXPECT_EQ(slam.counters().bad_points, 6);
  EXPECT_EQ(slam.counters().refits, 1);
  ASSERT_EQ(slam.map().landmarks.size(), 1u);
  const auto& refitted = slam.map().landmarks[0];
  EXPECT_NE(refitted.id, first_id);
  EXPECT_TRUE(refitted.bad_points.empty());
  // Weighted between the old polynomial (R) and the bad points.
  EXPECT_GT(refitted.polynomial.value(0.0), 2.02);
  EXPECT_LT(refitted.polynomial.value(0.0), 2.08);
  EXPECT_EQ(slam.filter().slots(), 1);
}

TEST(PolynomialSlam, FarPointsFormClustersThatBecomePolynomials) {
  PolynomialSlamOptions o;
  PolynomialSlam slam(core::Pose2(), initial_pose_covariance(), Eigen::Matrix3d::Zero(), o);
  // Ten points of a wall: one cluster, no polynomial yet; the eleventh makes one.
  std::vector<double> angles;
  std::vector<std::optional<double>> ranges;
  for (int i = 0; i < 10; ++i) {
    const double y = -0.5 + 0.1 * i;
    angles.push_back(std::atan2(y, 1.5));
    ranges.push_back(std::hypot(1.5, y));
  }
  slam.update(angles, ranges);
  EXPECT_EQ(slam.map().landmarks.size(), 0u);
  ASSERT_EQ(slam.map().clusters.size(), 1u);
  EXPECT_EQ(slam.map().clusters[0].points.size(), 10u);
  slam.update({std::atan2(0.5, 1.5)}, {std::hypot(1.5, 0.5)});
  ASSERT_EQ(slam.map().landmarks.size(), 1u);
  EXPECT_EQ(slam.map().clusters.size(), 0u);
  EXPECT_EQ(slam.map().landmarks[0].polynomial.axis, mapping::PolynomialAxis::X2);  // the wall x1 = 1.5
  EXPECT_NEAR(slam.map().landmarks[0].polynomial.value(0.0), 1.5, 0.02);
  // A point farther than R from the cluster's points starts a new cluster.
  slam.update({std::numbers::pi}, {1.0});
  EXPECT_EQ(slam.map().clusters.size(), 1u);
}

TEST(PolynomialSlam, ReceivedCurvesMergeWithOverlappingPolynomialsFig3) {
  PolynomialSlamOptions o;
  o.cluster_tolerance = 0.001;
  PolynomialSlam slam = facing_a_wall(o);
  ASSERT_EQ(slam.map().landmarks.size(), 1u);
  // The same wall seen by another robot, 2 cm off and reaching farther: merged into one.
  ReceivedCurve same;
  same.polyline = {{-0.2, 2.02}, {0.4, 2.02}, {1.0, 2.02}};
  same.variance = 1e-3;
  same.from_robot = 1;
  EXPECT_EQ(slam.integrate_received({same}), 1);
  EXPECT_EQ(slam.counters().merges, 1);
  ASSERT_EQ(slam.map().landmarks.size(), 1u);
  const auto& merged = slam.map().landmarks[0].polynomial;
  EXPECT_NEAR(merged.lo, -0.5, 1e-6);
  EXPECT_NEAR(merged.hi, 1.0, 1e-6);
  EXPECT_GT(merged.value(0.0), 2.0);
  EXPECT_LT(merged.value(0.0), 2.02);
  EXPECT_EQ(slam.map().landmarks[0].received_from, -1);  // made of both robots' data
  // A wall elsewhere is added as it is.
  ReceivedCurve other;
  other.polyline = {{3.0, -1.0}, {3.0, 1.0}};
  other.variance = 1e-3;
  other.from_robot = 1;
  slam.integrate_received({other});
  ASSERT_EQ(slam.map().landmarks.size(), 2u);
  EXPECT_EQ(slam.map().landmarks[1].received_from, 1);
  EXPECT_EQ(slam.map().landmarks[1].polynomial.axis, mapping::PolynomialAxis::X2);
  EXPECT_EQ(slam.filter().slots(), 2);
}

TEST(PolynomialSlam, AFewCentimetresOfCurveAreNotMergedWithMinMergeLength) {
  // A 6 cm piece of the wall (one spot read again and again gives such a piece) overlaps the wall's
  // polynomial and passes Fig. 3's gamma test; merged, its ill-determined shape pulls the wall's.
  // With min_merge_length 0.1 m it stays a polynomial of its own; without, it is merged.
  ReceivedCurve piece;
  piece.polyline = {{0.10, 2.01}, {0.16, 2.01}};
  piece.variance = 1e-3;
  piece.from_robot = 1;
  for (const double min_length : {0.0, 0.1}) {
    PolynomialSlamOptions o;
    o.cluster_tolerance = 0.001;
    o.min_merge_length = min_length;
    PolynomialSlam slam = facing_a_wall(o);
    ASSERT_EQ(slam.map().landmarks.size(), 1u);
    slam.integrate_received({piece});
    EXPECT_EQ(slam.counters().merges, min_length > 0.0 ? 0 : 1) << "min_merge_length " << min_length;
    EXPECT_EQ(slam.map().landmarks.size(), min_length > 0.0 ? 2u : 1u) << "min_merge_length " << min_length;
  }
}

TEST(PolynomialSlam, GammaTestKeepsParallelWallsApart) {
  PolynomialSlamOptions o;
  o.cluster_tolerance = 0.001;
  PolynomialSlam slam = facing_a_wall(o);
  ReceivedCurve parallel;  // 0.5 m away: gamma = 0.5 > gamma_M
  parallel.polyline = {{-0.5, 2.5}, {0.5, 2.5}};
  parallel.variance = 1e-3;
  slam.integrate_received({parallel});
  EXPECT_EQ(slam.counters().merges, 0);
  EXPECT_EQ(slam.map().landmarks.size(), 2u);
}

TEST(PolynomialSlam, TheLocalizerIsRegisteredAndUsesScans) {
  const auto names = localizer_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "polynomial"), names.end());
  LocalizerContext c;
  c.initial_pose = core::Pose2(2.0, 1.5, 0.0);
  auto loc = make_localizer("polynomial", c);
  EXPECT_EQ(loc->name(), "polynomial");
  core::Random rng(4);
  core::Pose2 truth = c.initial_pose;
  const mapping::OccupancyGrid unused;
  for (int k = 0; k < 120; ++k) {
    if (k > 0) {
      const Odometry u{0.0, 0.2, 1.0};
      loc->predict(u);
      truth = integrate_motion(truth, u);
    }
    RangeScan scan;
    scan.max_range = 4.0;
    for (int b = 0; b < 360; ++b) {
      scan.angles.push_back(core::normalize_angle(b * std::numbers::pi / 180.0));
      const auto r = rectangle_range(truth, scan.angles.back(), 5.0, 3.0, 4.0);
      scan.ranges.push_back(r ? std::optional<double>(*r + rng.normal(0.0, 0.02)) : std::nullopt);
    }
    loc->update_scan(scan, unused);
  }
  // Within 3 sigma of P0, the frame's only anchor.
  EXPECT_LT((loc->pose().position() - truth.position()).norm(), 3 * 0.05);
  double polynomials = 0.0;
  for (const auto& [key, value] : loc->counters()) {
    if (key == "polynomials") polynomials = value;
  }
  EXPECT_GE(polynomials, 4.0);
}

TEST(PolynomialSlam, ChangeFrameMovesPoseMapAndCovarianceTogether) {
  // A robot that has mapped a 4 x 3 m room with noisy readings adopts a frame turned by 40 degrees
  // and moved; its polynomials must lie on the moved walls within the noise they were made with,
  // its pose and covariance move rigidly, and it keeps localizing in the new frame.
  PolynomialSlamOptions o;
  const core::Pose2 start(1.5, 1.2, 0.3);
  PolynomialSlam slam(start, initial_pose_covariance(), Eigen::Matrix3d::Zero(), o);
  core::Random rng(11);
  core::Pose2 truth = start;
  const auto drive = [&](int steps, const core::Transform2& frame) {
    for (int k = 0; k < steps; ++k) {
      const Odometry u{0.0, 0.1, 1.0};
      slam.predict(u);
      truth = integrate_motion(truth, u);
      std::vector<std::optional<double>> ranges;
      for (double a : kFiveSensors) {
        const auto r = rectangle_range(truth, a, 4.0, 3.0, 3.0);
        ranges.push_back(r ? std::optional<double>(*r + rng.normal(0.0, 0.02)) : std::nullopt);
      }
      slam.update(kFiveSensors, ranges);
    }
    return core::Pose2::from_transform(frame * truth.as_transform());
  };
  drive(150, core::Transform2());
  const core::Transform2 t(3.0, -1.0, core::deg2rad(40.0));
  const core::Pose2 before = slam.pose();
  const Eigen::Matrix3d p_before = slam.pose_covariance();
  const auto polynomials = slam.map().landmarks.size();
  const mapping::PolynomialMap map_before = slam.map();
  ASSERT_GE(polynomials, 4u);
  slam.change_frame(t);
  const core::Pose2 expected = core::Pose2::from_transform(t * before.as_transform());
  EXPECT_LT((slam.pose().position() - expected.position()).norm(), 1e-9);
  EXPECT_NEAR(core::normalize_angle(slam.pose().theta - expected.theta), 0.0, 1e-9);
  const Eigen::Matrix2d r = t.rotation_matrix();
  const Eigen::Matrix2d moved = r * p_before.topLeftCorner(2, 2) * r.transpose();
  EXPECT_TRUE(slam.pose_covariance().topLeftCorner(2, 2).isApprox(moved, 1e-9));
  EXPECT_NEAR(slam.pose_covariance()(2, 2), p_before(2, 2), 1e-15);
  ASSERT_EQ(slam.map().landmarks.size(), polynomials);
  // Seen from the pose, the moved map is the old one: the refit adds far less than the map's own
  // error (a few sensor sigmas).
  const double error_before = map_error_seen_from_pose(map_before, before, truth, 4.0, 3.0);
  EXPECT_NEAR(map_error_seen_from_pose(slam.map(), slam.pose(), truth, 4.0, 3.0, t.inverse()), error_before, 2e-3);
  EXPECT_LT(error_before, 0.15);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(slam.filter().covariance());
  EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-12);
  // It keeps localizing against its moved map (within 5 sigma of P0's position).
  const core::Pose2 est_before_driving = slam.pose();
  const core::Pose2 truth_before_driving = core::Pose2::from_transform(t * truth.as_transform());
  const core::Pose2 truth_in_new = drive(60, t);
  // The estimate's error (in the new frame) changes by less than the sensor noise over the turn.
  const Eigen::Vector2d error_then = est_before_driving.position() - truth_before_driving.position();
  const Eigen::Vector2d error_now = slam.pose().position() - truth_in_new.position();
  EXPECT_LT((error_now - error_then).norm(), 0.02);
}

TEST(PolynomialSlam, AShortNoisyPieceOfStraightWallBecomesALine) {
  // Eleven readings 2 cm noisy of the wall x2 = 2 over 1 m: order 3 follows the noise (its ends
  // bend away), the lowest order that fits as well within the noise is a line (b3 = b2 = 0) that
  // stays within the noise of the wall.
  const auto worst_off_the_wall = [](bool lowest_order, mapping::Polynomial* out) {
    PolynomialSlamOptions o;
    o.lowest_order = lowest_order;
    o.cluster_tolerance = 0.1;
    PolynomialSlam slam(core::Pose2(0.0, 0.0, std::numbers::pi / 2), initial_pose_covariance(), Eigen::Matrix3d::Zero(), o);
    core::Random rng(3);
    std::vector<double> angles;
    std::vector<std::optional<double>> ranges;
    for (int i = -5; i <= 5; ++i) {
      const double x = 0.1 * i;
      angles.push_back(std::atan2(2.0, x) - std::numbers::pi / 2);
      ranges.push_back(std::hypot(x, 2.0) + rng.normal(0.0, 0.02));
    }
    slam.update(angles, ranges);
    EXPECT_EQ(slam.map().landmarks.size(), 1u);
    if (slam.map().landmarks.empty()) return 1e9;
    *out = slam.map().landmarks[0].polynomial;
    double worst = 0.0;
    for (const auto& q : mapping::sample_equally(*out, 50)) worst = std::max(worst, std::abs(q.y() - 2.0));
    return worst;
  };
  mapping::Polynomial line, cubic;
  const double line_error = worst_off_the_wall(true, &line);
  const double cubic_error = worst_off_the_wall(false, &cubic);
  EXPECT_EQ(line.shape[0], 0.0);
  EXPECT_EQ(line.shape[1], 0.0);
  EXPECT_NE(cubic.shape[0], 0.0);
  EXPECT_LT(line_error, 2 * 0.02);  // a line through 11 points: well inside 2 sigma
  EXPECT_LT(line_error, cubic_error);
}

// A cubic along x1 on [2, 4], held as a reference plus corrections a_1..a_3 in t = (xi - 3) / 1.
struct HeldCubic {
  mapping::Polynomial reference;
  ShapeBasis basis;
  Eigen::VectorXd entries;
};
HeldCubic held_cubic() {
  HeldCubic h;
  h.reference.axis = mapping::PolynomialAxis::X1;
  h.reference.shape = {0.02, -0.1, 0.3};
  h.reference.position = 1.5;
  h.reference.lo = 2.0;
  h.reference.hi = 4.0;
  h.basis = {3.0, 1.0, 4};
  h.entries = Eigen::Vector4d(1.45, 0.03, -0.02, 0.01);
  return h;
}

TEST(PolynomialSlam, ShapeEntriesAreAUniformShiftPlusCentredPowers) {
  const HeldCubic h = held_cubic();
  const mapping::Polynomial p = polynomial_from_entries(h.reference, h.basis, h.entries);
  for (double xi : {2.0, 2.7, 3.0, 3.9}) {
    const double t = xi - 3.0;
    const double expected = h.reference.value(xi) - h.reference.position + h.entries(0) + h.entries(1) * t +
                            h.entries(2) * t * t + h.entries(3) * t * t * t;
    EXPECT_NEAR(p.value(xi), expected, 1e-12);
  }
}

TEST(PolynomialSlam, ReadingJacobiansMatchNumericalDifferentiation) {
  // dh / d(x, y, theta) and dh / d(c_0, a_1..a_3) of eq. (2)'s distance along a sensor axis, against
  // central differences, for axes meeting the cubic at several places and angles.
  const HeldCubic h = held_cubic();
  const double e = 1e-6;
  int checked = 0;
  for (const core::Pose2& pose : {core::Pose2(2.5, 0.2, 1.2), core::Pose2(3.4, 0.0, 1.7), core::Pose2(3.0, -0.5, 1.0)}) {
    for (double beta : {-0.4, 0.0, 0.3}) {
      const auto r = range_reading(h.reference, h.basis, h.entries, 7, pose, beta, 5.0, 0.0);
      if (!r) continue;
      ++checked;
      const auto h_at = [&](const core::Pose2& x, const Eigen::VectorXd& entries) {
        const auto q = range_reading(h.reference, h.basis, entries, 7, x, beta, 5.0, 0.0);
        EXPECT_TRUE(q.has_value());
        return q ? q->predicted : 0.0;
      };
      for (int i = 0; i < 3; ++i) {
        core::Pose2 plus = pose, minus = pose;
        (i == 0 ? plus.x : i == 1 ? plus.y : plus.theta) += e;
        (i == 0 ? minus.x : i == 1 ? minus.y : minus.theta) -= e;
        EXPECT_NEAR(r->h_pose(i), (h_at(plus, h.entries) - h_at(minus, h.entries)) / (2 * e), 1e-6) << "pose " << i;
      }
      ASSERT_EQ(r->slot, 7);
      ASSERT_EQ(r->h_more.size(), 3u);
      for (int j = 0; j < 4; ++j) {
        Eigen::VectorXd plus = h.entries, minus = h.entries;
        plus(j) += e;
        minus(j) -= e;
        const double analytic = j == 0 ? r->h_slot : r->h_more[std::size_t(j - 1)].second;
        if (j > 0) {
          EXPECT_EQ(r->h_more[std::size_t(j - 1)].first, 7 + j);
        }
        EXPECT_NEAR(analytic, (h_at(pose, plus) - h_at(pose, minus)) / (2 * e), 1e-6) << "entry " << j;
      }
    }
  }
  EXPECT_GE(checked, 5);
}

TEST(PolynomialSlam, FitGradientMatchesNumericalDifferentiation) {
  // eq. (5)'s d (c_0, a_1..a_q) / d pi_k of the weighted LMS fit, against refitting with one
  // point moved, for a fit through points on a cubic (where the Gauss-Newton gradient is exact),
  // along x1 and along x2; with size 1 it is mapping::position_gradient.
  for (const auto axis : {mapping::PolynomialAxis::X1, mapping::PolynomialAxis::X2}) {
    mapping::Polynomial truth;
    truth.axis = axis;
    truth.shape = {0.05, -0.2, 0.4};
    truth.position = 0.8;
    std::vector<mapping::WeightedPoint> points;
    for (int k = 0; k <= 12; ++k) points.push_back({truth.world(Eigen::Vector2d(1.0 + 0.1 * k, truth.value(1.0 + 0.1 * k))), 1.0 + 0.1 * (k % 3)});
    const auto fit = mapping::fit_polynomial(points, 3, axis);
    ASSERT_TRUE(fit);
    const ShapeBasis basis{1.6, 0.6, 4};
    const auto entries_of = [&](const mapping::Polynomial& p) {
      // p = reference shape + c_0 + sum a_j t^j: solve for (c_0, a) at four values of t.
      Eigen::Matrix4d a;
      Eigen::Vector4d b;
      for (int i = 0; i < 4; ++i) {
        const double xi = 1.2 + 0.3 * i;
        a.row(i) = basis.at(xi).transpose();
        b(i) = p.value(xi) - (fit->polynomial.value(xi) - fit->polynomial.position);
      }
      return Eigen::Vector4d(a.lu().solve(b));
    };
    const auto grad = fit_gradient(fit->polynomial, basis, points);
    const ShapeBasis c0_only{1.6, 0.6, 1};
    const auto grad_c0 = fit_gradient(fit->polynomial, c0_only, points);
    const auto fixed_shape = mapping::position_gradient(fit->polynomial, points);
    const double e = 1e-6;
    for (std::size_t k = 0; k < points.size(); ++k) {
      EXPECT_NEAR((grad_c0[k].row(0).transpose() - fixed_shape[k]).norm(), 0.0, 1e-12);
      for (int d = 0; d < 2; ++d) {
        auto plus = points, minus = points;
        plus[k].position(d) += e;
        minus[k].position(d) -= e;
        const auto fp = mapping::fit_polynomial(plus, 3, axis), fm = mapping::fit_polynomial(minus, 3, axis);
        ASSERT_TRUE(fp && fm);
        const Eigen::Vector4d numeric = (entries_of(fp->polynomial) - entries_of(fm->polynomial)) / (2 * e);
        EXPECT_LT((grad[k].col(d) - numeric).norm(), 1e-5) << "point " << k << " coordinate " << d;
      }
    }
  }
}

TEST(PolynomialSlam, OptionsAreValidated) {
  PolynomialSlamOptions o;
  o.rho_max = 0.01;
  fleetmap::testing::expect_input_error([&] { validate(o); }, {"rho_max"});
  o = {};
  o.epsilon_m = 0;
  fleetmap::testing::expect_input_error([&] { validate(o); }, {"epsilon_m"});
  o = {};
  o.cluster_tolerance = -1.0;
  fleetmap::testing::expect_input_error([&] { PolynomialSlam(core::Pose2(), initial_pose_covariance(), initial_pose_covariance(), o); }, {"cluster_tolerance"});
  o = {};
  o.min_merge_length = -0.1;
  fleetmap::testing::expect_input_error([&] { validate(o); }, {"min_merge_length"});
}

}  // namespace
}  // namespace fleetmap::localization

namespace fleetmap::localization {
namespace {

// A robot drives straight at the wall x1 = 2 along a beam 40 degrees off the wall's normal, its
// one sensor reading the same spot ten times (2 cm range noise spreads the points along the beam),
// then turns and reads once 20 cm further along the wall. Eleven points make a cluster, then a
// polynomial: the wall is straight and the range noise explains a line's residuals, so the filter
// holds a line (c0 and a_1), not a curve bent along the beam whose linearised covariance would be
// far too small.
TEST(PolynomialSlam, PointsBunchedAlongABeamMakeALineNotACurveBentAlongIt) {
  PolynomialSlamOptions o;
  o.shape_in_state = true;
  const double beam = 40.0 * std::numbers::pi / 180.0;
  int lines = 0;
  const int seeds = 8;
  for (int seed = 0; seed < seeds; ++seed) {
    core::Random rng = core::Random(17).fork(std::uint64_t(seed));
    const core::Pose2 start(0.0, -1.5, beam);
    PolynomialSlam slam(start, initial_pose_covariance(), Eigen::Matrix3d::Zero(), o);
    core::Pose2 truth = start;
    const auto read = [&](double angle) -> std::optional<double> {
      const double c = std::cos(truth.theta + angle);
      return (2.0 - truth.x) / c + rng.normal(0.0, o.range_noise);
    };
    for (int k = 0; k < 10; ++k) {
      if (k > 0) {
        const Odometry u{0.05, 0.0, 1.0};
        slam.predict(u);
        truth = integrate_motion(truth, u);
      }
      slam.update({0.0}, {read(0.0)});
    }
    // The eleventh point, 20 cm further down the wall.
    const double turn = std::atan2(-1.5 + 2.0 * std::tan(beam) - 0.2 - truth.y, 2.0 - truth.x) - truth.theta;
    slam.update({turn}, {read(turn)});
    ASSERT_EQ(slam.map().landmarks.size(), 1u) << "seed " << seed;
    const int size = slam.basis(0).size;
    EXPECT_LE(size, 3) << "seed " << seed;
    if (size == 2) ++lines;
  }
  EXPECT_EQ(lines, seeds);
}

}  // namespace
}  // namespace fleetmap::localization

namespace fleetmap::localization {
namespace {

// A robot drives 8 m along one straight wall (x1 = 2), its three sensors on the wall's side, with
// exact odometry: nothing it reads tells it where it is along the wall, so a consistent filter
// keeps its variance along the wall at P0's (Huang, Mourikis & Roumeliotis 2008: an EKF linearised
// at estimates that move gains information along such an unobservable direction).
double along_wall_variance_ratio(bool first_estimate_jacobians, std::uint64_t seed) {
  PolynomialSlamOptions o;
  o.shape_in_state = true;
  o.min_incidence_cos = 0.7;
  o.first_estimate_jacobians = first_estimate_jacobians;
  core::Random rng = core::Random(23).fork(seed);
  const core::Pose2 start(0.0, 0.0, std::numbers::pi / 2);
  PolynomialSlam slam(start, initial_pose_covariance(), Eigen::Matrix3d::Zero(), o);
  core::Pose2 truth = start;
  const std::vector<double> angles = {-std::numbers::pi / 2, -std::numbers::pi / 4, -3 * std::numbers::pi / 4};
  double lowest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 80; ++k) {
    if (k > 0) {
      const Odometry u{0.1, 0.0, 1.0};
      slam.predict(u);
      truth = integrate_motion(truth, u);
    }
    std::vector<std::optional<double>> ranges;
    for (double a : angles) ranges.push_back((2.0 - truth.x) / std::cos(truth.theta + a) + rng.normal(0.0, o.range_noise));
    slam.update(angles, ranges);
    lowest = std::min(lowest, slam.pose_covariance()(1, 1));
  }
  return lowest / initial_pose_covariance()(1, 1);
}

TEST(PolynomialSlam, FirstEstimateJacobiansKeepThePositionAlongASingleWallUnobservable) {
  // With Jacobians at first estimates every reading's H is orthogonal to the translation along the
  // wall, so P_yy never falls below P0's (to rounding). Linearised at the current estimate, the
  // readings of a wall whose slope has been corrected since it was made say something about y:
  // P_yy falls 0.7-1% below P0's on these runs, information the wall cannot give (that the setting
  // corrects shapes at all is checked by the second expectation).
  for (std::uint64_t seed = 0; seed < 4; ++seed) {
    EXPECT_GE(along_wall_variance_ratio(true, seed), 1.0 - 1e-9) << "seed " << seed;
    EXPECT_LT(along_wall_variance_ratio(false, seed), 0.999) << "seed " << seed;
  }
}

}  // namespace
}  // namespace fleetmap::localization
